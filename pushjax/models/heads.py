"""One prediction head per model variant (Kloss et al., Sec. III-C, Figs. 3-4, Sec. V-B), and their registry.

A head maps the `perception.Scene` of a batch (or, for ``neural_dyn``, the batch's ground-truth
physical state) and the push to the predicted object motion. `HEADS` maps each variant name
(`ModelConfig.variant`) to its head; adding a variant is one `Head` subclass, one entry there and its
name in `config.VARIANTS`.
`PHYSICS_VARIANTS` and `ERROR_OPTIONS` are read off the registry, which implements `config.VARIANTS`.

* ``neural``: [glimpse encoding, object position, action, l] -> FC stack -> object motion v_o.
* ``neural_dyn``: the ``neural`` FC stack fed the ground-truth physical state (contact, normal,
  contact flag, action, l, mu) instead of perception.
* ``hybrid``: FC stack from [glimpse encoding, action] -> contact point, normal and contact
  indicator s (sigmoid); v_o = ``physics(contact, normal, action, l, mu, s)`` (Lynch's model), whose
  derivative gets `lynch.with_push_gate_gradient`'s straight-through push gate (values unchanged).
* ``simple``: FC stack from [glimpse encoding, action] -> effective push velocity v_p and contact
  point; v_o = ``lynch.object_velocity(contact, v_p, l)`` (stage 2 only).
* ``error``: ``hybrid`` plus an additive error term from [glimpse encoding, action, object position,
  l] through its own FC stack, with ``stop_gradient`` on those inputs; ``error_grad`` without the
  stop; ``error_norm`` with the action normalised to unit length before it enters the error term.
  The three share one parameter structure, so a sweep can vmap over them (``error_options``).

In the free view (`perception.FreeView`) the contact point and normal are predicted in pixel space
and transformed to world coordinates for the physics, and s is a separate output that multiplies the
predicted motion.

Each head declares what it predicts: `Head.needs_perception`, `Head.predictions` (its output names),
`Head.output_names` (all of a `PushModel`'s outputs in a view) and `Head.default_error_options`.

`PushModel` runs the heads in its own scope, so their FC stacks are the top-level modules ``head``
and ``error`` of the parameter tree.

Internal scaling: network inputs and outputs of lengths are in units of `ModelConfig.length_scale_m`
and rotations in units of `ModelConfig.rotation_scale_rad`, so that they are O(1); every returned
quantity is SI. The contact point predicted from the glimpse is relative to the pusher, so the contact
relative to the centre of mass, ``pusher_pos + offset - object_pos``, also depends on the predicted
object position.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import ClassVar

import flax.linen as nn
import jax
import jax.numpy as jnp

from pushjax.models.config import ModelConfig
from pushjax.models.perception import PERCEPTION_OUTPUTS, VIEW_MAPPINGS, Scene
from pushjax.physics import lynch

Batch = Mapping[str, jax.Array]
Physics = Callable[..., jax.Array]


class MLP(nn.Module):
    """Dense layers with ReLU between them; the last layer is linear.

    Attributes:
      features: widths of all layers, the output layer last.
    """

    features: Sequence[int]

    @nn.compact
    def __call__(self, inputs: jax.Array) -> jax.Array:
        x = inputs
        for index, width in enumerate(self.features):
            x = nn.Dense(width)(x)
            if index < len(self.features) - 1:
                x = nn.relu(x)
        return x


class Head(nn.Module):
    """Base of the variant heads.

    Attributes:
      config: the architecture.
      physics: the analytical model of the hybrid and error heads, called as
        ``physics(contact, normal, action, l, mu, s)`` on [B, 2], [B, 2], [B, 2], [B], [B], [B]
        arrays and returning the [B, 3] twist; `lynch.predict` by default.

    Class attributes:
      needs_perception: whether the head reads the batch's `Scene` (else it gets None).
      predictions: names of the outputs the head returns.
      default_error_options: (stop_gradient, normalise_action) flags of an error term, each 0 or 1;
        None for a head without one.
    """

    config: ModelConfig
    physics: Physics = lynch.predict

    needs_perception: ClassVar[bool] = True
    predictions: ClassVar[frozenset[str]] = frozenset({"motion"})
    default_error_options: ClassVar[tuple[float, float] | None] = None

    @classmethod
    def output_names(cls, view: str) -> frozenset[str]:
        """Names of the outputs of a `PushModel` with this head in `view` (a key of `VIEW_MAPPINGS`)."""
        return cls.predictions | frozenset(PERCEPTION_OUTPUTS if cls.needs_perception else ())

    def __call__(
        self, batch: Batch, scene: Scene | None, error_options: jax.Array | None = None
    ) -> dict[str, jax.Array]:
        """Predicts the object motion.

        Args:
          batch: dict with a leading batch axis B; reads `action` [B, 2] [m], `l` [B] [m], `mu` [B]
            (and `contact` [B, 2] [m], `normal` [B, 2], `contact_flag` [B] for ``neural_dyn``;
            `pusher_pos` [B, 2] [m] for heads that need perception).
          scene: what the perception sees in the batch; None if not `needs_perception`.
          error_options: optional [2] (stop_gradient, normalise_action) flags, each 0 or 1, overriding
            `default_error_options`; ignored by heads without an error term.

        Returns:
          dict with the `predictions`, among them `motion` [B, 3] (dx, dy [m], dyaw [rad]).
        """
        raise NotImplementedError


def _column(values: jax.Array) -> jax.Array:
    return values[:, None]


def _motion(raw: jax.Array, config: ModelConfig) -> jax.Array:
    """[B, 3] network output -> (dx, dy [m], dyaw [rad])."""
    return jnp.concatenate([raw[:, :2] * config.length_scale_m, raw[:, 2:3] * config.rotation_scale_rad], -1)


def _object_from_pusher(batch: Batch, scene: Scene, config: ModelConfig) -> jax.Array:
    """[B, 2] predicted object position relative to the pusher [length_scale_m]."""
    return (scene.object_pos - batch["pusher_pos"]) / config.length_scale_m


def _glimpse_and_action(batch: Batch, scene: Scene, config: ModelConfig) -> jax.Array:
    """[B, D + 2] inputs of the physics heads' FC stack: glimpse encoding, action [length_scale_m]."""
    return jnp.concatenate([scene.glimpse, batch["action"] / config.length_scale_m], axis=-1)


class NeuralHead(Head):
    """``neural``: [glimpse encoding, object position, action, l] -> FC stack -> object motion v_o."""

    @nn.compact
    def __call__(self, batch, scene, error_options=None):
        config = self.config
        scale = config.length_scale_m
        inputs = jnp.concatenate(
            [
                scene.glimpse, _object_from_pusher(batch, scene, config), batch["action"] / scale,
                _column(batch["l"]) / scale,
            ],
            -1,
        )
        return {"motion": _motion(MLP((*config.head_features, 3), name="head")(inputs), config)}


class NeuralDynHead(Head):
    """``neural_dyn``: the ``neural`` FC stack fed the ground-truth physical state instead of perception.

    The state is (contact, normal, contact flag, action, l, mu).
    """

    needs_perception = False

    @nn.compact
    def __call__(self, batch, scene, error_options=None):
        config = self.config
        scale = config.length_scale_m
        state = jnp.concatenate(
            [
                batch["contact"] / scale, batch["normal"], _column(batch["contact_flag"]),
                batch["action"] / scale, _column(batch["l"]) / scale, _column(batch["mu"]),
            ],
            axis=-1,
        )
        return {"motion": _motion(MLP((*config.head_features, 3), name="head")(state), config)}


class SimpleHead(Head):
    """``simple``: FC stack from [glimpse encoding, action] -> effective push velocity v_p and contact point.

    v_o = ``lynch.object_velocity(contact, v_p, l)`` (stage 2 of Lynch's model only). Outputs `contact`
    [B, 2] relative to the predicted centre of mass [m] and `push_velocity` [B, 2] [m].
    """

    predictions = frozenset({"motion", "contact", "push_velocity"})

    @nn.compact
    def __call__(self, batch, scene, error_options=None):
        config = self.config
        raw = MLP((*config.head_features, 4), name="head")(_glimpse_and_action(batch, scene, config))
        contact = scene.view.contact_point(raw[:, :2]) - scene.object_pos
        push_velocity = raw[:, 2:4] * config.length_scale_m
        return {
            "contact": contact, "push_velocity": push_velocity,
            "motion": lynch.object_velocity(contact, push_velocity, batch["l"]),
        }


class HybridHead(Head):
    """``hybrid``: FC stack from [glimpse encoding, action] -> contact point, normal and contact indicator s.

    v_o = ``physics(contact, normal, action, l, mu, s)`` (Lynch's model). Outputs `contact` [B, 2]
    relative to the predicted centre of mass [m], `normal` [B, 2] (unnormalised, world axes), `s` [B]
    and its logit `s_logit` [B]. In a view that `separates_contact_indicator` (the free view) the
    physics gets s = 1, giving `motion_given_contact` [B, 3], and `motion` is s times that.
    """

    predictions = frozenset({"motion", "contact", "normal", "s", "s_logit"})

    @classmethod
    def output_names(cls, view: str) -> frozenset[str]:
        names = super().output_names(view)
        if VIEW_MAPPINGS[view].separates_contact_indicator:
            return names | {"motion_given_contact"}
        return names

    @nn.compact
    def __call__(self, batch, scene, error_options=None):
        return self.physics_outputs(batch, scene)

    def physics_outputs(self, batch: Batch, scene: Scene) -> dict[str, jax.Array]:
        """The outputs of ``hybrid`` (see the class docstring); call it from a compact method."""
        config = self.config
        action, l, mu = batch["action"], batch["l"], batch["mu"]
        raw = MLP((*config.head_features, 5), name="head")(_glimpse_and_action(batch, scene, config))
        contact, normal = scene.view.contact_and_normal(raw[:, :2], raw[:, 2:4])
        contact = contact - scene.object_pos
        s_logit = raw[:, 4]
        s = nn.sigmoid(s_logit)
        outputs = {"contact": contact, "normal": normal, "s": s, "s_logit": s_logit}
        if scene.view.separates_contact_indicator:
            motion_given_contact = self._physics_motion(contact, normal, action, l, mu, jnp.ones_like(s))
            outputs.update(motion=_column(s) * motion_given_contact, motion_given_contact=motion_given_contact)
        else:
            outputs["motion"] = self._physics_motion(contact, normal, action, l, mu, s)
        return outputs

    def _physics_motion(self, contact, normal, action, l, mu, s) -> jax.Array:
        """[B, 3] `physics` twist (dx, dy [m], dyaw [rad]) with `lynch.with_push_gate_gradient`'s derivative.

        The values are `physics`'s, bit for bit; the straight-through push gate lets a normal predicted facing
        away from the push still learn from the motion loss. Arguments as `physics` takes them: contact [B, 2]
        relative to the centre of mass [m], normal [B, 2] (any length), action [B, 2] [m], l [B] [m], mu [B],
        s [B] in [0, 1].
        """
        motion = self.physics(contact, normal, action, l, mu, s)
        return lynch.with_push_gate_gradient(motion, contact, normal, action, l, mu, s)


class ErrorHead(HybridHead):
    """``error``: ``hybrid`` plus an additive error term on its motion, with ``stop_gradient`` on its inputs.

    The error term is an FC stack (``error``) from [glimpse encoding, action, object position, l];
    the error variants share one parameter structure, so a sweep can vmap over them
    (``error_options``). Also outputs `error` [B, 3] (dx, dy [m], dyaw [rad]), added to `motion` and
    `motion_given_contact`.
    """

    predictions = HybridHead.predictions | {"error"}
    default_error_options = (1.0, 0.0)

    @nn.compact
    def __call__(self, batch, scene, error_options=None):
        config = self.config
        action = batch["action"]
        object_from_pusher = _object_from_pusher(batch, scene, config)
        outputs = self.physics_outputs(batch, scene)
        if error_options is None:
            error_options = jnp.asarray(self.default_error_options)
        stop_gradient, normalise_action = error_options[0] > 0.5, error_options[1] > 0.5
        action_norm = jnp.sqrt(jnp.sum(action**2, axis=-1, keepdims=True) + 1e-12)
        error_action = jnp.where(normalise_action, action / action_norm, action / config.length_scale_m)
        inputs = jnp.concatenate(
            [
                scene.glimpse, error_action, object_from_pusher, _column(batch["l"]) / config.length_scale_m,
            ],
            -1,
        )
        inputs = jnp.where(stop_gradient, jax.lax.stop_gradient(inputs), inputs)
        error = _motion(MLP((*config.error_features, 3), name="error")(inputs), config)
        outputs["error"] = error
        for name in ("motion", "motion_given_contact"):
            if name in outputs:
                outputs[name] = outputs[name] + error
        return outputs


class ErrorGradHead(ErrorHead):
    """``error_grad``: ``error`` without the ``stop_gradient``, so the error term trains the perception."""

    default_error_options = (0.0, 0.0)


class ErrorNormHead(ErrorHead):
    """``error_norm``: ``error`` with the action normalised to unit length before it enters the error term."""

    default_error_options = (1.0, 1.0)


HEADS: dict[str, type[Head]] = {
    "neural": NeuralHead,
    "neural_dyn": NeuralDynHead,
    "hybrid": HybridHead,
    "simple": SimpleHead,
    "error": ErrorHead,
    "error_grad": ErrorGradHead,
    "error_norm": ErrorNormHead,
}
"""The variant (`config.VARIANTS`) -> its head."""
PHYSICS_VARIANTS = tuple(variant for variant, head in HEADS.items() if "contact" in head.predictions)
"""The variants that predict a contact point and compute the motion with Lynch's model."""
ERROR_OPTIONS: dict[str, tuple[float, float]] = {
    variant: head.default_error_options for variant, head in HEADS.items()
    if head.default_error_options is not None
}
"""(stop_gradient, normalise_action) of the error-term variants."""
