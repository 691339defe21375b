"""Architecture of a `networks.PushModel`: which variant, which view, and the layer sizes.

`VARIANTS` and `VIEWS` are the names a config accepts; `heads.HEADS` and `perception.VIEW_MAPPINGS`
implement exactly these (tests/models/test_heads.py holds them to it). The config lives below the
heads and the perception, which read it, so that neither has to import `networks`.
"""

from __future__ import annotations

import dataclasses

VARIANTS = ("neural", "neural_dyn", "hybrid", "simple", "error", "error_grad", "error_norm")
"""The model variants (Kloss et al., Sec. III-C and V-B); `heads.HEADS` has one head per name."""
IMAGE_FIELDS = {"top_down": "depth", "free": "point_cloud"}
"""The view -> the batch field its perception reads (`pushjax.data.schema`)."""
VIEWS = tuple(IMAGE_FIELDS)
"""The camera views; `perception.VIEW_MAPPINGS` maps each one's pixels to the world."""


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
        for name in ("glimpse_kernel", "locator_kernel"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name}: expected a positive kernel side in pixels, got {getattr(self, name)}")
        for name in ("glimpse_features", "locator_conv_features", "locator_deconv_features", "head_features",
                     "error_features"):
            if any(width <= 0 for width in getattr(self, name)):
                raise ValueError(f"{name}: expected positive layer widths, got {getattr(self, name)}")
        if not 0 <= self.batch_norm_momentum <= 1:
            raise ValueError(f"batch_norm_momentum: expected a decay in [0, 1], got {self.batch_norm_momentum}")
        if self.length_scale_m <= 0 or self.rotation_scale_rad <= 0:
            raise ValueError("length_scale_m, rotation_scale_rad: expected positive scales")

    @property
    def image_field(self) -> str:
        """The batch field the perception reads."""
        return IMAGE_FIELDS[self.view]
