"""The pushing model a controller plans with: an object's outline and Lynch's model with any composed effects.

:class:`PlanningModel` is a pytree (``effects`` static), so a controller jit-compiled once per set of effect names
takes any object, ``l``, ``mu`` and effect parameters without compiling again. :func:`predict` is the rollout of
:mod:`pushjax.physics.rollout` along a pusher path.
"""

from __future__ import annotations

from collections.abc import Sequence

import flax.struct
import jax
import jax.numpy as jnp

from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object, limit_surface_ratio
from pushjax.physics import effects as effects_lib
from pushjax.physics import model_file
from pushjax.physics import rollout

__all__ = ["PlanningModel", "make_model", "predict"]


@flax.struct.dataclass
class PlanningModel:
    """One object and the pushing model the controller believes in.

    Attributes:
      shape: the object's outline (:func:`pushjax.geometry.outline_jax.outline`).
      l: [] limit-surface ratio, m.
      mu: [] pusher-object friction coefficient.
      radius: [] pusher radius, m.
      params: {effect: {name: array}} of the composed effects ({} for plain Lynch).
      support: the object's support (:func:`pushjax.physics.rollout.object_support`), which the exact limit
        surface (``limit_surface``) needs; None for the other models.
      effects: names of the composed effects (static; () is plain Lynch).
      search: the rollout's contact search (static; :func:`pushjax.physics.rollout.rollout`): "local" (around the
        tracked contact) or "full" (every outline feature every step, the former search, for comparison).
    """

    shape: outline_jax.Outline
    l: jax.Array
    mu: jax.Array
    radius: jax.Array
    params: dict
    support: rollout.Support | None = None
    effects: tuple[str, ...] = flax.struct.field(pytree_node=False, default=())
    search: str = flax.struct.field(pytree_node=False, default="local")


def make_model(obj: PushObject | str, mu: float = 0.25, l: float | None = None, *, effects: Sequence[str] = (),
               params: dict | None = None, dtype=jnp.float32) -> PlanningModel:
    """The :class:`PlanningModel` of `obj` (or its name).

    Args:
      obj: the object.
      mu: pusher-object friction coefficient (> 0).
      l: limit-surface ratio, m (default: uniform pressure, :func:`pushjax.geometry.objects.limit_surface_ratio`).
      effects: effect names of :data:`pushjax.physics.effects.EFFECTS` composed with Lynch's model.
      params: their parameters, {effect: {name: value}}; missing effects take their "no effect" values.
      dtype: float dtype of the arrays.
    """
    obj = get_object(obj) if isinstance(obj, str) else obj
    l = limit_surface_ratio(obj) if l is None else l
    if not (jnp.isfinite(mu) and mu > 0 and jnp.isfinite(l) and l > 0):
        raise ValueError(f"mu, l: expected positive finite values, got {mu}, {l}")
    effects = tuple(effects)
    full = model_file.AugmentedModel.create(effects, params, mu).params  # filled up and checked
    full = jax.tree_util.tree_map(lambda value: jnp.asarray(value, dtype), full)
    return PlanningModel(shape=outline_jax.outline(obj, dtype), l=jnp.asarray(l, dtype), mu=jnp.asarray(mu, dtype),
                     radius=jnp.asarray(PUSHER_RADIUS, dtype), params=full,
                     support=rollout.object_support(obj, dtype) if effects_lib.needs_support(effects) else None,
                     effects=effects)


def predict(model: PlanningModel, pose, pusher_path) -> rollout.Rollout:
    """The model's rollout from `pose` [3] (x m, y m, yaw rad) along `pusher_path` [T + 1, 2] (world, m)."""
    return rollout.rollout(model.shape, pose, pusher_path, model.l, model.mu, model.params, effects=model.effects,
                           radius=model.radius, support=model.support, search=model.search)
