"""The types of the pushing model's effects: its inputs (:class:`PushInputs`), what the effects change before the solve
(:class:`ModelState`) and one effect of the library (:class:`Effect`); see :mod:`pushjax.physics.effects`."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import flax.struct
import jax
import jax.numpy as jnp

__all__ = ["Effect", "ModelState", "Params", "PushInputs", "zeros"]

Params = dict[str, jax.Array]


@flax.struct.dataclass
class PushInputs:
    """Inputs of the augmented pushing model; leading batch axes broadcast against each other.

    Attributes:
      contact: [..., 2] contact point relative to the nominal centre of mass, world axes, m. With
        ``s = 0`` it may be the point the pusher would touch if it went on beyond the window.
      normal: [..., 2] unit surface normal at the contact pointing into the object, world axes;
        zero means that the pusher does not reach the object.
      action: [..., 2] pusher displacement after the first contact, world axes, m.
      pusher_motion: [..., 2] pusher displacement over the whole prediction window, m.
      gap: [...] distance the pusher travels along ``normal`` before it touches, m (negative when it
        starts penetrating the annotated outline, beyond the window's approach when ``s = 0``; 0
        without a normal).
      l: [...] nominal limit-surface ratio, m.
      mu: [...] nominal pusher-object friction coefficient.
      s: [...] contact indicator in [0, 1] (0 when the pusher does not touch within the window).
      object_yaw: [...] orientation of the object (tracked frame) in the world, rad.
      push_speed: [...] pusher speed when it stops in the window, or at the window's end, m/s.
      time_after_stop: [...] time from the pusher's stop to the window's end, s (0: still moving).
      object_position: [..., 2] position of the nominal centre of mass on the table at the window's start,
        world axes, m.
      support_points: [..., K, 2] points of the object's support relative to the nominal centre of mass, object
        axes, m: the footprint's cells (:func:`pushjax.geometry.support_cells`) and the corners of its convex hull
        (:func:`pushjax.geometry.support_feet`); None when unknown (``limit_surface`` needs them).
      support_weights: [..., K] their area weights (>= 0; zero for the hull's corners and padding); None with
        ``support_points``.
      support_feet: [..., K] the loads of the object resting on its hull's corners (>= 0, summing to 1; zero for the
        cells and padding); None: no corners among the points.
      patch_radius: [...] the radius of a support's patch, m (the solve's regularisation length).
    """

    contact: jax.Array
    normal: jax.Array
    action: jax.Array
    pusher_motion: jax.Array
    gap: jax.Array
    l: jax.Array
    mu: jax.Array
    s: jax.Array
    object_yaw: jax.Array
    push_speed: jax.Array
    time_after_stop: jax.Array
    object_position: jax.Array
    support_points: jax.Array | None = None
    support_weights: jax.Array | None = None
    patch_radius: jax.Array | None = None
    support_feet: jax.Array | None = None

    @classmethod
    def create(cls, contact, normal, action, l, mu, s=1.0, *, pusher_motion=None, gap=0.0,
               object_yaw=0.0, push_speed=0.0, time_after_stop=0.0, object_position=(0.0, 0.0),
               support_points=None, support_weights=None, patch_radius=None, support_feet=None) -> PushInputs:
        """Inputs from ``lynch.predict``'s arguments; the others default to a pusher in contact
        (``pusher_motion = action``, ``gap = 0``), object yaw 0 at the table's origin, a pusher that does
        not stop and an unknown support."""
        action = jnp.asarray(action)

        def optional(value):
            return None if value is None else jnp.asarray(value)

        return cls(
            contact=jnp.asarray(contact), normal=jnp.asarray(normal), action=action,
            pusher_motion=action if pusher_motion is None else jnp.asarray(pusher_motion),
            gap=jnp.asarray(gap), l=jnp.asarray(l), mu=jnp.asarray(mu), s=jnp.asarray(s),
            object_yaw=jnp.asarray(object_yaw), push_speed=jnp.asarray(push_speed),
            time_after_stop=jnp.asarray(time_after_stop), object_position=jnp.asarray(object_position),
            support_points=optional(support_points), support_weights=optional(support_weights),
            patch_radius=optional(patch_radius), support_feet=optional(support_feet),
        )


@flax.struct.dataclass
class ModelState:
    """What the effects change before the limit-surface solve (world axes, batch-shaped).

    Attributes:
      contact: [..., 2] contact relative to the centre of friction, m.
      normal, action, l, mu, s: as in :class:`PushInputs`.
      centre: [..., 2] centre of friction relative to the nominal centre of mass, m.
      metric: (A_xx, A_xy, A_yy) force metric of the limit surface, each [...].
      drift_force: [..., 2] constant in-plane force at the centre over the maximal friction force.
    """

    contact: jax.Array
    normal: jax.Array
    action: jax.Array
    l: jax.Array
    mu: jax.Array
    s: jax.Array
    centre: jax.Array
    metric: tuple[jax.Array, jax.Array, jax.Array]
    drift_force: jax.Array


def _identity(params: Params) -> Params:
    return params


@dataclasses.dataclass(frozen=True, kw_only=True)
class Effect:
    """One library effect (see :mod:`pushjax.physics.effects` for the physics of each).

    Attributes:
      name: library name.
      init: the "no effect" parameters, {name: zeros of the parameter's shape}.
      typical: {name: typical magnitude}, for conditioning optimisers.
      modify: (params, state, inputs) -> state, applied before the solve, or None (the default).
      correct: (params, twist, state, inputs) -> twist, applied to the predicted twist of the push, or None (the
        default); with several, their changes add up (each sees the push's twist, not another's correction).
      project: params -> params inside the physically valid set (default: all parameters are valid).
      physical: params -> {readable name with unit: scalar}, the values to report.
      general_solver: whether the effect needs the generalised solver (not plain Lynch).
      solve: (params, state, inputs) -> twist about the centre of friction, replacing the ellipsoidal solve, or
        None (at most one composed effect has one).
      excludes: effects that cannot be composed with this one.
      per_object: whether the parameters describe one object (its support, a marker, a hidden weight) rather than
        the table, the pusher or the dynamics, so that they may differ between objects.
    """

    name: str
    init: Callable[[], Params]
    typical: dict[str, float]
    physical: Callable[[Params], dict[str, jax.Array]]
    modify: Callable[[Params, ModelState, PushInputs], ModelState] | None = None
    correct: Callable[[Params, jax.Array, ModelState, PushInputs], jax.Array] | None = None
    project: Callable[[Params], Params] = _identity
    general_solver: bool = False
    solve: Callable[[Params, ModelState, PushInputs], jax.Array] | None = None
    excludes: tuple[str, ...] = ()
    per_object: bool = False


def zeros(**shapes) -> Callable[[], Params]:
    """An :attr:`Effect.init`: {name: zeros of the shape} for ``name=shape`` items."""
    return lambda: {name: jnp.zeros(shape) for name, shape in shapes.items()}
