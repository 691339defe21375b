"""Perception shared by all model variants (Kloss et al., Sec. III-C, Fig. 3).

* Glimpse: a square patch cut around the pusher tip, whose pixel position is known, encoded by three
  conv layers (ReLU, max-pooling, batch norm) into a flat vector.
* Object position: the full image through four conv and three deconv layers to a one-channel map at
  input resolution whose spatial softmax gives the object's pixel position; that pixel is mapped to the
  world by the image scale at the table (top-down camera) or by a bilinear depth lookup and
  unprojection (free viewpoint).

`Perception` runs both on a batch and returns a `Scene`: the glimpse encoding, the object position and
the view (`TopDownView` or `FreeView`, looked up in `VIEW_MAPPINGS`), which also maps the contact point
and normal that the heads predict to the world.

Images are [B, H, W, C] (C = 1 for depth, 3 for point clouds); pixel coordinates (u right, v down,
pixel centres at +0.5) and cameras follow `pushjax.render.camera`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import ClassVar

import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np
from flax import struct

from pushjax.models.config import IMAGE_FIELDS, ModelConfig
from pushjax.render import camera as camera_lib

Batch = Mapping[str, jax.Array]


def standardise_images(images: jax.Array) -> jax.Array:
    """Per-image, per-channel zero mean and unit variance.

    Makes the networks invariant to the camera height and the table's position in the point cloud.

    Args:
      images: [B, H, W, C] depth [m] or point cloud [m].

    Returns:
      [B, H, W, C] dimensionless.
    """
    mean = images.mean(axis=(1, 2), keepdims=True)
    std = images.std(axis=(1, 2), keepdims=True)
    return (images - mean) / (std + 1e-6)


def extract_glimpses(images: jax.Array, centre_pixels: jax.Array, size: int) -> jax.Array:
    """Square patches of `size` x `size` pixels centred on `centre_pixels`, edge-padded at the border.

    Args:
      images: [B, H, W, C].
      centre_pixels: [B, 2] (u, v) [pixels]; rounded to the nearest pixel corner grid, so not
        differentiable with respect to the position.
      size: side length [pixels].

    Returns:
      [B, size, size, C].
    """
    if size <= 0:
        raise ValueError(f"size: expected a positive glimpse size in pixels, got {size}")
    padded = jnp.pad(images, ((0, 0), (size, size), (size, size), (0, 0)), mode="edge")
    # The patch spans [centre - size/2, centre + size/2) in pixel-corner coordinates.
    top_left = jnp.round(centre_pixels - size / 2).astype(jnp.int32) + size
    top_left = jnp.clip(top_left, 0, jnp.array([padded.shape[2] - size, padded.shape[1] - size]))

    def cut(image, corner):
        return jax.lax.dynamic_slice(image, (corner[1], corner[0], 0), (size, size, image.shape[-1]))

    return jax.vmap(cut)(padded, top_left)


class GlimpseEncoder(nn.Module):
    """Three conv layers with ReLU, each followed by 2x2 max-pooling and batch norm, then flattened.

    Attributes:
      features: channels of the three conv layers.
      kernel_size: side of the square conv kernels [pixels].
      batch_norm_momentum: decay of the running batch statistics.
    """

    features: Sequence[int]
    kernel_size: int
    batch_norm_momentum: float = 0.9

    @nn.compact
    def __call__(self, glimpses: jax.Array, train: bool) -> jax.Array:
        """[B, g, g, C] standardised glimpses -> [B, D] encoding."""
        x = glimpses
        for channels in self.features:
            x = nn.Conv(channels, (self.kernel_size, self.kernel_size))(x)
            x = nn.relu(x)
            x = nn.max_pool(x, (2, 2), strides=(2, 2), padding="SAME")
            x = nn.BatchNorm(use_running_average=not train, momentum=self.batch_norm_momentum)(x)
        return x.reshape(x.shape[0], -1)


def _phase_taps(kernel_size: int, stride: int) -> tuple[np.ndarray, int, int]:
    """How a 'SAME' transposed convolution's taps reach each output phase along one axis.

    Output pixel ``stride * m + p`` of ``lax.conv_transpose(..., padding="SAME")`` sums kernel taps ``t`` times
    input pixel ``m + offset`` with ``offset = (p + t - pad) / stride`` whenever that is an integer (``pad`` is
    the low padding of the dilated input that ``lax.conv_transpose`` uses).

    Returns:
      ([stride, high - low + 1, kernel_size] 0/1 array: phase p reads offset low + i through tap t, low, high).
    """
    pad_length = kernel_size + stride - 2
    pad = kernel_size - 1 if stride > kernel_size - 1 else -(-pad_length // 2)
    taps = [(phase, (phase + tap - pad) // stride, tap) for phase in range(stride) for tap in range(kernel_size)
            if (phase + tap - pad) % stride == 0]
    low, high = min(offset for _, offset, _ in taps), max(offset for _, offset, _ in taps)
    select = np.zeros((stride, high - low + 1, kernel_size), np.float32)
    for phase, offset, tap in taps:
        select[phase, offset - low, tap] = 1.0
    return select, low, high


class ConvTranspose(nn.Module):
    """``flax.linen.ConvTranspose(padding="SAME")`` computed as one stride-1 convolution for all output phases.

    Same parameters (``kernel`` [kh, kw, C, F], ``bias`` [F], same initialisers) and the same output, but
    instead of convolving the zero-dilated input it convolves the input itself with the kernel's taps
    regrouped per output phase (sub-pixel convolution), then interleaves the phases. The results agree to
    float rounding; the gradient is 2-4x faster on XLA:CPU, whose gradient of an input-dilated convolution is
    slow (``benchmarks/sweep_breakdown.py``).

    Attributes:
      features: output channels F.
      kernel_size: (kh, kw) [pixels].
      strides: (sh, sw) upsampling factors.
      use_bias: add a learned bias.
    """

    features: int
    kernel_size: Sequence[int]
    strides: Sequence[int]
    use_bias: bool = True

    @nn.compact
    def __call__(self, inputs: jax.Array) -> jax.Array:
        """[B, H, W, C] -> [B, sh * H, sw * W, F]."""
        (kernel_rows, kernel_cols), (stride_rows, stride_cols) = self.kernel_size, self.strides
        kernel = self.param("kernel", nn.initializers.lecun_normal(),
                            (kernel_rows, kernel_cols, inputs.shape[-1], self.features))
        rows, row_low, row_high = _phase_taps(kernel_rows, stride_rows)
        cols, col_low, col_high = _phase_taps(kernel_cols, stride_cols)
        phase_kernel = jnp.einsum("pit,qju,tucf->ijcpqf", rows, cols, kernel)
        phase_kernel = phase_kernel.reshape(*phase_kernel.shape[:3], -1)
        phases = jax.lax.conv_general_dilated(
            inputs, phase_kernel, (1, 1), ((-row_low, row_high), (-col_low, col_high)),
            dimension_numbers=("NHWC", "HWIO", "NHWC"),
        )
        batch, height, width, _ = phases.shape
        outputs = phases.reshape(batch, height, width, stride_rows, stride_cols, self.features)
        outputs = outputs.transpose(0, 1, 3, 2, 4, 5).reshape(
            batch, height * stride_rows, width * stride_cols, self.features)
        if self.use_bias:
            outputs = outputs + self.param("bias", nn.initializers.zeros, (self.features,))
        return outputs


def spatial_softmax(logits: jax.Array) -> jax.Array:
    """Expected pixel position under the softmax of a one-channel map.

    Args:
      logits: [B, H, W].

    Returns:
      [B, 2] (u, v) [pixels], pixel centres at +0.5.
    """
    batch, height, width = logits.shape
    probabilities = jax.nn.softmax(logits.reshape(batch, -1), axis=-1)
    centres = camera_lib.pixel_centres(width, height).reshape(-1, 2)
    return probabilities @ centres


class ObjectLocator(nn.Module):
    """Four conv and three deconv layers to a one-channel map at input resolution; its spatial softmax.

    The first conv keeps the resolution and the other three halve it; the three stride-2 deconvs
    restore it, so H and W must be multiples of 8.

    Attributes:
      conv_features: channels of the four conv layers.
      deconv_features: channels of the first two deconv layers (the last has one).
      kernel_size: side of the square kernels [pixels].
    """

    conv_features: Sequence[int]
    deconv_features: Sequence[int]
    kernel_size: int = 3

    @nn.compact
    def __call__(self, images: jax.Array) -> jax.Array:
        """[B, H, W, C] standardised images -> [B, 2] object pixel (u, v)."""
        height, width = images.shape[1:3]
        if height % 8 or width % 8:
            raise ValueError(f"images: expected height and width divisible by 8, got {height}x{width}")
        kernel = (self.kernel_size, self.kernel_size)
        x = images
        for index, channels in enumerate(self.conv_features):
            stride = 1 if index == 0 else 2
            x = nn.relu(nn.Conv(channels, kernel, strides=(stride, stride))(x))
        for channels in self.deconv_features:
            x = nn.relu(ConvTranspose(channels, kernel, strides=(2, 2))(x))
        # No bias: the spatial softmax ignores a constant offset, so it would get no gradient.
        logits = ConvTranspose(1, kernel, strides=(2, 2), use_bias=False)(x)[..., 0]
        return spatial_softmax(logits)


def cameras_from_batch(intrinsics: jax.Array, extrinsics: jax.Array, width: int, height: int):
    """A batch of cameras (array fields with a leading batch axis) from the dataset fields.

    Args:
      intrinsics: [B, 4] fx, fy, cx, cy [pixels] (`camera_intrinsics`).
      extrinsics: [B, 4, 4] world_from_camera (`camera_extrinsics`) [m].
      width, height: image size [pixels].
    """
    return camera_lib.Camera(
        fx=intrinsics[:, 0], fy=intrinsics[:, 1], cx=intrinsics[:, 2], cy=intrinsics[:, 3],
        world_from_camera=extrinsics, width=width, height=height,
    )


def table_points_top_down(pixels: jax.Array, cameras: camera_lib.Camera) -> jax.Array:
    """World xy [B, 2] [m] of pixels [B, 2] by the image scale at the table (downward cameras).

    Exact on the table plane for a camera looking straight down (`top_down_camera`).
    """

    def one(pixel, camera):
        axis_distance = camera.position[2] / camera.rotation[2, 2]
        return camera_lib.unproject(pixel, axis_distance, camera)[:2]

    return jax.vmap(one)(pixels, cameras)


def depth_from_point_cloud(point_clouds: jax.Array, cameras: camera_lib.Camera) -> jax.Array:
    """Depth images [B, H, W] [m] of organised world-frame point clouds [B, H, W, 3] [m]."""
    return jax.vmap(lambda cloud, camera: -camera_lib.world_to_camera(cloud, camera)[..., 2])(
        point_clouds, cameras
    )


def unproject_with_depth(pixels: jax.Array, depth: jax.Array, cameras: camera_lib.Camera) -> jax.Array:
    """World points [B, N, 3] [m] seen at pixels [B, N, 2], depth bilinearly looked up in [B, H, W] [m]."""

    def one(pixel, image, camera):
        return camera_lib.unproject(pixel, camera_lib.bilinear_lookup(image, pixel), camera)

    return jax.vmap(one)(pixels, depth, cameras)


@struct.dataclass
class TopDownView:
    """The ``top_down`` view: a camera looking straight down at the table, seeing the `depth` image.

    Pixels map to the table by the image scale. The heads predict the contact point as an offset from
    the pusher in units of `length_scale_m` and the normal in world axes.

    Attributes:
      cameras: the batch's cameras (array fields with a leading axis B).
      pusher_pos: [B, 2] pusher position, world xy [m].
      length_scale_m: unit of the predicted contact offset [m].

    Class attributes:
      image_field: the batch field of the image.
      separates_contact_indicator: whether the physics variants predict the motion given contact and
        the contact indicator s as separate outputs (the free view) or s scales the physics' motion.
    """

    image_field: ClassVar[str] = IMAGE_FIELDS["top_down"]
    separates_contact_indicator: ClassVar[bool] = False

    cameras: camera_lib.Camera
    pusher_pos: jax.Array
    length_scale_m: float = struct.field(pytree_node=False)

    @classmethod
    def from_batch(cls, batch: Batch, cameras: camera_lib.Camera, config: ModelConfig) -> TopDownView:
        """The view of `batch` (reads `pusher_pos`) seen by `cameras`."""
        return cls(cameras, batch["pusher_pos"], config.length_scale_m)

    def world_points(self, pixels: jax.Array) -> jax.Array:
        """World xy [B, 2] [m] on the table of pixels [B, 2] (u, v)."""
        return table_points_top_down(pixels, self.cameras)

    def contact_point(self, raw_contact: jax.Array) -> jax.Array:
        """World xy [B, 2] [m] of the contact from its predicted [B, 2] offset from the pusher."""
        return self.pusher_pos + raw_contact * self.length_scale_m

    def contact_and_normal(self, raw_contact: jax.Array, raw_normal: jax.Array) -> tuple[jax.Array, jax.Array]:
        """World contact xy [B, 2] [m] and normal [B, 2] (world axes, unnormalised) from the predictions.

        Args:
          raw_contact: [B, 2] offset from the pusher [length_scale_m].
          raw_normal: [B, 2] normal in world axes.
        """
        return self.contact_point(raw_contact), raw_normal


@struct.dataclass
class FreeView:
    """The ``free`` view: a camera anywhere, seeing the world-frame `point_cloud` image.

    Pixels map to the world by a bilinear lookup in the depth image and unprojection. The heads predict
    the contact point as a pixel offset from the pusher's pixel in units of half the glimpse side, and
    the normal in pixels.

    Attributes:
      cameras: the batch's cameras (array fields with a leading axis B).
      depth: [B, H, W] depth images [m] of the point clouds.
      pusher_pixel: [B, 2] pusher (u, v) [pixels].
      glimpse_size: side of the glimpse around the pusher [pixels].

    Class attributes: as `TopDownView`'s.
    """

    image_field: ClassVar[str] = IMAGE_FIELDS["free"]
    separates_contact_indicator: ClassVar[bool] = True

    cameras: camera_lib.Camera
    depth: jax.Array
    pusher_pixel: jax.Array
    glimpse_size: int = struct.field(pytree_node=False)

    @classmethod
    def from_batch(cls, batch: Batch, cameras: camera_lib.Camera, config: ModelConfig) -> FreeView:
        """The view of `batch` (reads `point_cloud`, `pusher_pixel`) seen by `cameras`."""
        depth = depth_from_point_cloud(batch[cls.image_field], cameras)
        return cls(cameras, depth, batch["pusher_pixel"], config.glimpse_size)

    def world_points(self, pixels: jax.Array) -> jax.Array:
        """World xy [B, 2] [m] of the surface seen at pixels [B, 2] (u, v)."""
        return unproject_with_depth(pixels[:, None], self.depth, self.cameras)[:, 0, :2]

    def contact_point(self, raw_contact: jax.Array) -> jax.Array:
        """World xy [B, 2] [m] of the contact from its predicted [B, 2] offset from the pusher pixel."""

        def to_world(pixel, image, camera):
            return camera_lib.unproject(pixel, camera_lib.bilinear_lookup(image, pixel), camera)[:2]

        return jax.vmap(to_world)(self._contact_pixel(raw_contact), self.depth, self.cameras)

    def contact_and_normal(self, raw_contact: jax.Array, raw_normal: jax.Array) -> tuple[jax.Array, jax.Array]:
        """World contact xy [B, 2] [m] and normal [B, 2] (world axes, unnormalised) from the predictions.

        The normal is the world displacement of the contact pixel moved by `raw_normal`, at the
        contact's depth.

        Args:
          raw_contact: [B, 2] offset from the pusher pixel [half glimpse sides].
          raw_normal: [B, 2] normal [pixels].
        """

        def to_world(pixel, normal_pixel, image, camera):
            contact_depth = camera_lib.bilinear_lookup(image, pixel)
            point = camera_lib.unproject(pixel, contact_depth, camera)
            along_normal = camera_lib.unproject(pixel + normal_pixel, contact_depth, camera)
            return point[:2], (along_normal - point)[:2]

        return jax.vmap(to_world)(self._contact_pixel(raw_contact), raw_normal, self.depth, self.cameras)

    def _contact_pixel(self, raw_contact: jax.Array) -> jax.Array:
        return self.pusher_pixel + raw_contact * (self.glimpse_size / 2)


View = TopDownView | FreeView
VIEW_MAPPINGS: dict[str, type[View]] = {"top_down": TopDownView, "free": FreeView}
"""The view (`config.VIEWS`) -> how its images map to the world."""
PERCEPTION_OUTPUTS = ("object_pixel", "object_pos")
"""The `PushModel` outputs that come from the perception."""


@struct.dataclass
class Scene:
    """What `Perception` sees in a batch.

    Attributes:
      glimpse: [B, D] encoding of the glimpse around the pusher.
      object_pixel: [B, 2] predicted object position (u, v) [pixels].
      object_pos: [B, 2] its world xy [m].
      view: the batch's view, which maps predicted contacts to the world.
    """

    glimpse: jax.Array
    object_pixel: jax.Array
    object_pos: jax.Array
    view: View

    def outputs(self) -> dict[str, jax.Array]:
        """The `PERCEPTION_OUTPUTS` of a `PushModel`."""
        return {name: getattr(self, name) for name in PERCEPTION_OUTPUTS}


class Perception(nn.Module):
    """The glimpse encoder (submodule ``glimpse``) and object locator (``locator``) on a batch's image.

    Attributes:
      config: the architecture; `config.view` picks the image and its mapping (`VIEW_MAPPINGS`).
    """

    config: ModelConfig

    @nn.compact
    def __call__(self, batch: Batch, train: bool) -> Scene:
        """Perceives a batch.

        Args:
          batch: dict with a leading batch axis B; reads `depth` [B, H, W, 1] [m] (top-down view) or
            `point_cloud` [B, H, W, 3] [m] (free view), `pusher_pixel` [B, 2] [pixels], `pusher_pos`
            [B, 2] [m], `camera_intrinsics` [B, 4] and `camera_extrinsics` [B, 4, 4].
          train: normalise the glimpses by the batch's statistics (True) or the running ones (False).
        """
        config = self.config
        view_mapping = VIEW_MAPPINGS[config.view]
        raw_images = batch[view_mapping.image_field]
        if raw_images.ndim != 4:
            raise ValueError(
                f"batch[{view_mapping.image_field!r}]: expected [B, H, W, C], got {raw_images.shape}"
            )
        images = standardise_images(raw_images)
        height, width = images.shape[1:3]
        cameras = cameras_from_batch(batch["camera_intrinsics"], batch["camera_extrinsics"], width, height)
        glimpses = extract_glimpses(images, batch["pusher_pixel"], config.glimpse_size)
        glimpse = GlimpseEncoder(
            config.glimpse_features, config.glimpse_kernel, config.batch_norm_momentum, name="glimpse"
        )(glimpses, train)
        object_pixel = ObjectLocator(
            config.locator_conv_features, config.locator_deconv_features, config.locator_kernel,
            name="locator",
        )(images)
        view = view_mapping.from_batch(batch, cameras, config)
        return Scene(glimpse, object_pixel, view.world_points(object_pixel), view)
