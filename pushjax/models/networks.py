"""The paper's model (Kloss et al., Sec. III-C, Figs. 3-4, Sec. V-B) as one Flax module.

`PushModel` is the perception (`perception.Perception`: glimpse encoder, object locator and the view's
pixel-to-world mapping, picked by `ModelConfig.view` from `perception.VIEW_MAPPINGS`) followed by the
head of its variant (`ModelConfig.variant`), looked up in `heads.HEADS`, which describes the variants.

The parameter tree has the top-level modules ``glimpse`` and ``locator`` (perception), ``head`` (the
variant's FC stack) and, for the error variants, ``error``.
"""

from __future__ import annotations

from collections.abc import Mapping

import flax.linen as nn
import jax
import numpy as np

from pushjax.models import heads, perception
from pushjax.models.config import ModelConfig
from pushjax.models.heads import Physics
from pushjax.physics import lynch

Batch = Mapping[str, jax.Array]


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

    def setup(self):
        self.variant_head = heads.HEADS[self.config.variant](self.config, self.physics)
        nn.share_scope(self, self.variant_head)
        if self.variant_head.needs_perception:
            self.perception = perception.Perception(self.config)
            nn.share_scope(self, self.perception)

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
          dict with the outputs named by ``heads.HEADS[variant].output_names(view)``: `motion` [B, 3]
          (dx, dy [m], dyaw [rad]); except for ``neural_dyn`` also `object_pixel` [B, 2] [pixels] and
          `object_pos` [B, 2] world [m]; for physics variants `contact` [B, 2] relative to the
          predicted centre of mass [m]; for hybrid and error variants `normal` [B, 2] (unnormalised,
          world axes), `s` [B] and `s_logit` [B]; for ``simple`` `push_velocity` [B, 2] [m]; for error
          variants `error` [B, 3]; for hybrid and error variants in the free view
          `motion_given_contact` [B, 3], the motion before multiplying by s.
        """
        if not self.variant_head.needs_perception:
            return self.variant_head(batch, None, error_options)
        scene = self.perception(batch, train)
        return {**scene.outputs(), **self.variant_head(batch, scene, error_options)}


def count_parameters(params: Mapping) -> dict[str, int]:
    """Number of parameters per top-level module (e.g. glimpse, locator, head, error) and in total."""
    counts = {
        name: int(sum(np.prod(leaf.shape) for leaf in jax.tree.leaves(subtree)))
        for name, subtree in params.items()
    }
    counts["total"] = sum(counts.values())
    return counts
