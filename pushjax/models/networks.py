"""The paper's model variants (Kloss et al., Sec. III-C, Figs. 3-4, Sec. V-B) as one Flax module.

Variants (`ModelConfig.variant`):

* ``neural``: [glimpse encoding, object position, action, l] -> FC stack -> object motion v_o.
* ``neural_dyn``: the ``neural`` FC stack fed the ground-truth physical state (contact, normal,
  contact flag, action, l, mu) instead of perception.
* ``hybrid``: FC stack from [glimpse encoding, action] -> contact point, normal and contact
  indicator s (sigmoid); v_o = ``physics(contact, normal, action, l, mu, s)`` (Lynch's model).
* ``simple``: FC stack from [glimpse encoding, action] -> effective push velocity v_p and contact
  point; v_o = ``lynch.object_velocity(contact, v_p, l)`` (stage 2 only).
* ``error``: ``hybrid`` plus an additive error term from [glimpse encoding, action, object position,
  l] through its own FC stack, with ``stop_gradient`` on those inputs; ``error_grad`` without the
  stop; ``error_norm`` with the action normalised to unit length before it enters the error term.
  The three share one parameter structure, so a sweep can vmap over them (``error_options``).

Views (`ModelConfig.view`): ``top_down`` reads the ``depth`` image and maps pixels to the table by
the image scale; ``free`` reads the ``point_cloud`` image, maps pixels to the world by bilinear depth
lookup and unprojection, predicts the physics variants' contact point and normal in pixel space
(transformed to world coordinates for the physics) and s as a separate output that multiplies the
predicted motion.

Internal scaling: network inputs and outputs of lengths are in units of ``length_scale_m`` and
rotations in units of ``rotation_scale_rad``, so that they are O(1); every returned quantity is SI.
The contact point predicted from the glimpse is relative to the pusher, so the contact relative to
the centre of mass, ``pusher_pos + offset - object_pos``, also depends on the predicted object
position.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence

import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np

from pushjax.models import perception
from pushjax.physics import lynch
from pushjax.render import camera as camera_lib

VARIANTS = ("neural", "neural_dyn", "hybrid", "simple", "error", "error_grad", "error_norm")
VIEWS = ("top_down", "free")
ERROR_OPTIONS: dict[str, tuple[float, float]] = {
    "error": (1.0, 0.0),
    "error_grad": (0.0, 0.0),
    "error_norm": (1.0, 1.0),
}
"""(stop_gradient, normalise_action) of the error-term variants."""
PHYSICS_VARIANTS = ("hybrid", "simple", *ERROR_OPTIONS)

Batch = Mapping[str, jax.Array]
Physics = Callable[..., jax.Array]


@dataclasses.dataclass(frozen=True)
class ModelConfig:
    """Architecture of a :class:`PushModel`. Defaults are the paper-scale sizes.

    Attributes:
      variant: one of `VARIANTS`.
      view: one of `VIEWS`.
      glimpse_size: side of the glimpse around the pusher [pixels].
      glimpse_features: channels of the three glimpse conv layers.
      glimpse_kernel: glimpse conv kernel side [pixels].
      locator_conv_features: channels of the four object-locator conv layers.
      locator_deconv_features: channels of the first two locator deconv layers.
      locator_kernel: locator kernel side [pixels].
      head_features: hidden widths of the prediction FC stack (an output layer follows).
      error_features: hidden widths of the error-term FC stack (an output layer follows).
      batch_norm_momentum: decay of the glimpse batch-norm running statistics.
      length_scale_m: unit of lengths inside the networks [m].
      rotation_scale_rad: unit of predicted rotations inside the networks [rad].
    """

    variant: str = "hybrid"
    view: str = "top_down"
    glimpse_size: int = 80
    glimpse_features: tuple[int, ...] = (32, 32, 16)
    glimpse_kernel: int = 5
    locator_conv_features: tuple[int, ...] = (16, 32, 32, 32)
    locator_deconv_features: tuple[int, ...] = (32, 16)
    locator_kernel: int = 3
    head_features: tuple[int, ...] = (1024, 128)
    error_features: tuple[int, ...] = (512, 128)
    batch_norm_momentum: float = 0.9
    length_scale_m: float = 0.01
    rotation_scale_rad: float = 0.1

    def __post_init__(self):
        if self.variant not in VARIANTS:
            raise ValueError(f"variant: expected one of {VARIANTS}, got {self.variant!r}")
        if self.view not in VIEWS:
            raise ValueError(f"view: expected one of {VIEWS}, got {self.view!r}")
        if len(self.glimpse_features) != 3:
            raise ValueError(f"glimpse_features: expected 3 conv layers, got {self.glimpse_features}")
        if len(self.locator_conv_features) != 4:
            raise ValueError(
                f"locator_conv_features: expected 4 conv layers, got {self.locator_conv_features}"
            )
        if len(self.locator_deconv_features) != 2:
            raise ValueError(
                "locator_deconv_features: expected 2 (the third deconv has one channel), got "
                f"{self.locator_deconv_features}"
            )
        if self.glimpse_size <= 0:
            raise ValueError(f"glimpse_size: expected a positive size in pixels, got {self.glimpse_size}")
        if self.length_scale_m <= 0 or self.rotation_scale_rad <= 0:
            raise ValueError("length_scale_m, rotation_scale_rad: expected positive scales")

    @property
    def image_field(self) -> str:
        """The batch field the perception reads."""
        return "depth" if self.view == "top_down" else "point_cloud"


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


def _column(values: jax.Array) -> jax.Array:
    return values[:, None]


class PushModel(nn.Module):
    """Predicts the object motion caused by a push from a batch (see `pushjax.data.schema`).

    Attributes:
      config: the architecture.
      physics: the analytical model of the hybrid and error variants, called as
        ``physics(contact, normal, action, l, mu, s)`` on [B, 2], [B, 2], [B, 2], [B], [B], [B]
        arrays and returning the [B, 3] twist; `lynch.predict` by default.
    """

    config: ModelConfig
    physics: Physics = lynch.predict

    @nn.compact
    def __call__(
        self, batch: Batch, train: bool, error_options: jax.Array | None = None
    ) -> dict[str, jax.Array]:
        """Forward pass.

        Args:
          batch: dict with a leading batch axis B; reads `depth` or `point_cloud`, `pusher_pixel`,
            `pusher_pos`, `action`, `l`, `mu`, `camera_intrinsics`, `camera_extrinsics` (and the
            ground-truth state for ``neural_dyn``).
          train: batch statistics of the batch (True) or running ones (False).
          error_options: optional [2] (stop_gradient, normalise_action) flags of the error term,
            each 0 or 1, overriding the variant's (`ERROR_OPTIONS`); lets a vmapped sweep mix the
            error variants.

        Returns:
          dict with `motion` [B, 3] (dx, dy [m], dyaw [rad]); except for ``neural_dyn`` also
          `object_pixel` [B, 2] [pixels] and `object_pos` [B, 2] world [m]; for physics variants
          `contact` [B, 2] relative to the predicted centre of mass [m]; for hybrid and error
          variants `normal` [B, 2] (unnormalised, world axes), `s` [B] and `s_logit` [B]; for
          ``simple`` `push_velocity` [B, 2] [m]; for error variants `error` [B, 3]; in the free
          view `motion_given_contact` [B, 3], the motion before multiplying by s.
        """
        config = self.config
        scale = config.length_scale_m
        action, l, mu = batch["action"], batch["l"], batch["mu"]
        if config.variant == "neural_dyn":
            state = jnp.concatenate(
                [
                    batch["contact"] / scale, batch["normal"], _column(batch["contact_flag"]),
                    action / scale, _column(l) / scale, _column(mu),
                ],
                axis=-1,
            )
            return {"motion": self._motion(MLP((*config.head_features, 3), name="head")(state))}

        raw_images = batch[config.image_field]
        if raw_images.ndim != 4:
            raise ValueError(
                f"batch[{config.image_field!r}]: expected [B, H, W, C], got {raw_images.shape}"
            )
        images = perception.standardise_images(raw_images)
        height, width = images.shape[1:3]
        cameras = perception.cameras_from_batch(
            batch["camera_intrinsics"], batch["camera_extrinsics"], width, height
        )
        glimpses = perception.extract_glimpses(images, batch["pusher_pixel"], config.glimpse_size)
        glimpse = perception.GlimpseEncoder(
            config.glimpse_features, config.glimpse_kernel, config.batch_norm_momentum, name="glimpse"
        )(glimpses, train)
        object_pixel = perception.ObjectLocator(
            config.locator_conv_features, config.locator_deconv_features, config.locator_kernel,
            name="locator",
        )(images)
        if config.view == "top_down":
            depth = None
            object_pos = perception.table_points_top_down(object_pixel, cameras)
        else:
            depth = perception.depth_from_point_cloud(raw_images, cameras)
            object_pos = perception.unproject_with_depth(object_pixel[:, None], depth, cameras)[:, 0, :2]
        relative_object = (object_pos - batch["pusher_pos"]) / scale
        outputs = {"object_pixel": object_pixel, "object_pos": object_pos}

        if config.variant == "neural":
            inputs = jnp.concatenate([glimpse, relative_object, action / scale, _column(l) / scale], -1)
            outputs["motion"] = self._motion(MLP((*config.head_features, 3), name="head")(inputs))
            return outputs

        head_inputs = jnp.concatenate([glimpse, action / scale], axis=-1)
        if config.variant == "simple":
            raw = MLP((*config.head_features, 4), name="head")(head_inputs)
            contact, _ = self._contact_and_normal(raw[:, :2], raw[:, :2], batch, object_pos, depth, cameras)
            push_velocity = raw[:, 2:4] * scale
            outputs.update(
                contact=contact, push_velocity=push_velocity,
                motion=lynch.object_velocity(contact, push_velocity, l),
            )
            return outputs

        raw = MLP((*config.head_features, 5), name="head")(head_inputs)
        contact, normal = self._contact_and_normal(raw[:, :2], raw[:, 2:4], batch, object_pos, depth, cameras)
        s_logit = raw[:, 4]
        s = nn.sigmoid(s_logit)
        outputs.update(contact=contact, normal=normal, s=s, s_logit=s_logit)
        if config.view == "top_down":
            motion = self.physics(contact, normal, action, l, mu, s)
        else:
            motion_given_contact = self.physics(contact, normal, action, l, mu, jnp.ones_like(s))
            motion = _column(s) * motion_given_contact

        if config.variant in ERROR_OPTIONS:
            if error_options is None:
                error_options = jnp.asarray(ERROR_OPTIONS[config.variant])
            stop_gradient, normalise_action = error_options[0] > 0.5, error_options[1] > 0.5
            action_norm = jnp.sqrt(jnp.sum(action**2, axis=-1, keepdims=True) + 1e-12)
            error_action = jnp.where(normalise_action, action / action_norm, action / scale)
            inputs = jnp.concatenate([glimpse, error_action, relative_object, _column(l) / scale], -1)
            inputs = jnp.where(stop_gradient, jax.lax.stop_gradient(inputs), inputs)
            error = self._motion(MLP((*config.error_features, 3), name="error")(inputs))
            outputs["error"] = error
            motion = motion + error
            if config.view == "free":
                motion_given_contact = motion_given_contact + error
        outputs["motion"] = motion
        if config.view == "free":
            outputs["motion_given_contact"] = motion_given_contact
        return outputs

    def _motion(self, raw: jax.Array) -> jax.Array:
        """[B, 3] network output -> (dx, dy [m], dyaw [rad])."""
        return jnp.concatenate(
            [raw[:, :2] * self.config.length_scale_m, raw[:, 2:3] * self.config.rotation_scale_rad], -1
        )

    def _contact_and_normal(self, raw_contact, raw_normal, batch, object_pos, depth, cameras):
        """Contact [B, 2] relative to `object_pos` [m] and normal [B, 2] in world axes.

        Top-down: `raw_contact` is the offset from the pusher in `length_scale_m`, `raw_normal` the
        world-frame normal. Free view: both are in pixels (the offset in units of half the glimpse),
        and are unprojected with the depth looked up at the contact pixel.
        """
        config = self.config
        if config.view == "top_down":
            contact = batch["pusher_pos"] + raw_contact * config.length_scale_m - object_pos
            return contact, raw_normal
        contact_pixel = batch["pusher_pixel"] + raw_contact * (config.glimpse_size / 2)

        def to_world(pixel, normal_pixel, image, camera):
            contact_depth = camera_lib.bilinear_lookup(image, pixel)
            point = camera_lib.unproject(pixel, contact_depth, camera)
            along_normal = camera_lib.unproject(pixel + normal_pixel, contact_depth, camera)
            return point[:2], (along_normal - point)[:2]

        contact_world, normal = jax.vmap(to_world)(contact_pixel, raw_normal, depth, cameras)
        return contact_world - object_pos, normal


def count_parameters(params: Mapping) -> dict[str, int]:
    """Number of parameters per top-level module (e.g. glimpse, locator, head, error) and in total."""
    counts = {
        name: int(sum(np.prod(leaf.shape) for leaf in jax.tree.leaves(subtree)))
        for name, subtree in params.items()
    }
    counts["total"] = sum(counts.values())
    return counts
