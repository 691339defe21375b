"""Pinhole camera models in JAX: projection, unprojection and sub-pixel image lookup.

Conventions (identical to MuJoCo's and OpenGL's, so that images rendered by `mujoco.Renderer` line up
with `project`):

* Camera frame: x to the right, y up, the camera looks along -z.
* Pixels: (u, v) with u to the right and v down, origin at the top-left corner of the top-left pixel,
  so the centre of pixel (row i, column j) is (u, v) = (j + 0.5, i + 0.5). Row 0 of an image is the top.
* Depth: metric distance along the optical axis, i.e. -z in the camera frame; positive in front of the
  camera. This is what MuJoCo's depth rendering returns.

Every function here is pure, differentiable and works under `jax.jit` / `jax.vmap` (a batch of cameras
is a `Camera` whose array fields carry a leading batch axis, mapped with `jax.vmap`).
"""

from __future__ import annotations

from typing import Literal, Sequence

import jax
import jax.numpy as jnp
import numpy as np
from flax import struct

ArrayLike = jax.typing.ArrayLike


@struct.dataclass
class Camera:
    """A pinhole camera.

    Attributes:
      fx, fy: focal lengths [pixels], scalars.
      cx, cy: principal point [pixels], scalars, measured from the top-left image corner.
      world_from_camera: [4, 4] homogeneous rigid transform taking camera-frame points to world points [m].
      width, height: image size [pixels] (static, not traced).
    """

    fx: jax.Array
    fy: jax.Array
    cx: jax.Array
    cy: jax.Array
    world_from_camera: jax.Array
    width: int = struct.field(pytree_node=False)
    height: int = struct.field(pytree_node=False)

    @classmethod
    def create(
        cls,
        *,
        fx: ArrayLike,
        fy: ArrayLike,
        cx: ArrayLike,
        cy: ArrayLike,
        width: int,
        height: int,
        world_from_camera: ArrayLike,
    ) -> Camera:
        """Validating constructor; arguments as in the class docstring.

        Raises:
          ValueError: an argument has the wrong shape or an impossible value.
        """
        _check_image_size(width, height)
        intrinsics = {}
        for name, value in (("fx", fx), ("fy", fy), ("cx", cx), ("cy", cy)):
            value = jnp.asarray(value, dtype=jnp.float32)
            if value.shape != ():
                raise ValueError(f"{name} must be a scalar, got shape {value.shape}.")
            intrinsics[name] = value
        for name in ("fx", "fy"):
            if _is_concrete(intrinsics[name]) and not float(intrinsics[name]) > 0:
                raise ValueError(f"{name} must be a positive focal length in pixels, got {intrinsics[name]}.")
        world_from_camera = jnp.asarray(world_from_camera, dtype=jnp.float32)
        if world_from_camera.shape != (4, 4):
            raise ValueError(f"world_from_camera must have shape (4, 4), got {world_from_camera.shape}.")
        return cls(**intrinsics, world_from_camera=world_from_camera, width=int(width), height=int(height))

    @property
    def rotation(self) -> jax.Array:
        """[3, 3] world_from_camera rotation; its columns are the camera axes in world coordinates."""
        return self.world_from_camera[:3, :3]

    @property
    def position(self) -> jax.Array:
        """[3] camera centre in world coordinates [m]."""
        return self.world_from_camera[:3, 3]


def _is_concrete(x) -> bool:
    return not isinstance(x, jax.core.Tracer)


def _check_image_size(width, height) -> None:
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value <= 0:
            raise ValueError(f"{name} must be a positive integer number of pixels, got {value!r}.")


def _as_vector3(value: ArrayLike, name: str) -> jax.Array:
    value = jnp.asarray(value, dtype=jnp.float32)
    if value.shape != (3,):
        raise ValueError(f"{name} must have shape (3,), got {value.shape}.")
    return value


def _check_last_axis(value: jax.Array, size: int, name: str) -> None:
    if value.ndim < 1 or value.shape[-1] != size:
        raise ValueError(f"{name} must have shape [..., {size}], got {value.shape}.")


def intrinsics_from_fov(
    fovy_deg: ArrayLike, width: int, height: int
) -> tuple[jax.Array, jax.Array, jax.Array, jax.Array]:
    """Intrinsics of a camera with square pixels and a centred principal point (MuJoCo's camera model).

    Args:
      fovy_deg: vertical field of view [degrees], in (0, 180); MuJoCo's `fovy`.
      width, height: image size [pixels].

    Returns:
      (fx, fy, cx, cy) [pixels].
    """
    _check_image_size(width, height)
    fovy_deg = jnp.asarray(fovy_deg, dtype=jnp.float32)
    if fovy_deg.shape != ():
        raise ValueError(f"fovy_deg must be a scalar, got shape {fovy_deg.shape}.")
    if _is_concrete(fovy_deg) and not 0.0 < float(fovy_deg) < 180.0:
        raise ValueError(f"fovy_deg must lie in (0, 180) degrees, got {float(fovy_deg)}.")
    fy = 0.5 * height / jnp.tan(jnp.deg2rad(fovy_deg) / 2)
    return fy, fy, jnp.float32(width / 2), jnp.float32(height / 2)


def look_at(eye: ArrayLike, target: ArrayLike, up: ArrayLike = (0.0, 0.0, 1.0)) -> jax.Array:
    """world_from_camera [4, 4] of a camera at `eye` [m] looking at `target` [m].

    The camera's y axis (image up) is the projection of `up` onto the image plane.

    Raises:
      ValueError: an argument is not a 3-vector, or (for concrete inputs) `eye == target` or the viewing
        direction is parallel to `up`.
    """
    eye = _as_vector3(eye, "eye")
    target = _as_vector3(target, "target")
    up = _as_vector3(up, "up")
    forward = target - eye
    right = jnp.cross(forward, up)
    if _is_concrete(forward) and _is_concrete(right):
        if float(jnp.linalg.norm(forward)) < 1e-9:
            raise ValueError("eye and target must differ.")
        if float(jnp.linalg.norm(right)) < 1e-6 * float(jnp.linalg.norm(forward) * jnp.linalg.norm(up)):
            raise ValueError("up must not be parallel to the viewing direction target - eye.")
    forward = forward / jnp.linalg.norm(forward)
    right = right / jnp.linalg.norm(right)
    camera_up = jnp.cross(right, forward)
    rotation = jnp.stack([right, camera_up, -forward], axis=1)
    return _rigid_transform(rotation, eye)


def _rigid_transform(rotation: jax.Array, translation: jax.Array) -> jax.Array:
    top = jnp.concatenate([rotation, translation[:, None]], axis=1)
    return jnp.concatenate([top, jnp.array([[0.0, 0.0, 0.0, 1.0]], dtype=top.dtype)], axis=0)


def top_down_camera(
    width: int = 64,
    height: int = 64,
    *,
    height_m: float = 0.4,
    fovy_deg: float = 45.0,
    center_xy: Sequence[float] = (0.0, 0.0),
) -> Camera:
    """Camera `height_m` above the table point `center_xy`, looking straight down.

    Image right is world +x and image up is world +y. The defaults see a 0.33 m x 0.33 m patch of the table
    (5.2 mm per pixel at 64 x 64): room for the largest MIT objects (~18 cm) plus a 5 cm push and the pusher.

    Args:
      width, height: image size [pixels].
      height_m: camera height above the table top (z = 0) [m].
      fovy_deg: vertical field of view [degrees].
      center_xy: [2] table point under the camera [m].
    """
    center_xy = jnp.asarray(center_xy, dtype=jnp.float32)
    if center_xy.shape != (2,):
        raise ValueError(f"center_xy must have shape (2,), got {center_xy.shape}.")
    if _is_concrete(height_m) and not float(height_m) > 0:
        raise ValueError(f"height_m must be positive, got {height_m}.")
    fx, fy, cx, cy = intrinsics_from_fov(fovy_deg, width, height)
    position = jnp.concatenate([center_xy, jnp.asarray(height_m, jnp.float32)[None]])
    world_from_camera = _rigid_transform(jnp.eye(3, dtype=jnp.float32), position)
    return Camera(fx=fx, fy=fy, cx=cx, cy=cy, world_from_camera=world_from_camera, width=width, height=height)


def free_camera(
    width: int = 64,
    height: int = 64,
    *,
    eye: Sequence[float] = (0.0, -0.25, 0.4),
    target: Sequence[float] = (0.0, 0.0, 0.0),
    fovy_deg: float = 45.0,
) -> Camera:
    """Oblique camera of the paper's second setup: at `eye` [m] looking at `target` [m], world +z up.

    With the defaults (0.47 m from the table centre, 58 degrees below the horizon) the table patch in view
    spans about 0.39 m left to right at the table centre.
    """
    fx, fy, cx, cy = intrinsics_from_fov(fovy_deg, width, height)
    return Camera(
        fx=fx, fy=fy, cx=cx, cy=cy, world_from_camera=look_at(eye, target), width=width, height=height
    )


def world_to_camera(world_points: ArrayLike, camera: Camera) -> jax.Array:
    """Camera-frame coordinates [..., 3] [m] of world points [..., 3] [m]."""
    world_points = jnp.asarray(world_points)
    _check_last_axis(world_points, 3, "world_points")
    return (world_points - camera.position) @ camera.rotation


def camera_to_world(camera_points: ArrayLike, camera: Camera) -> jax.Array:
    """World coordinates [..., 3] [m] of camera-frame points [..., 3] [m]."""
    camera_points = jnp.asarray(camera_points)
    _check_last_axis(camera_points, 3, "camera_points")
    return camera_points @ camera.rotation.T + camera.position


def project(world_points: ArrayLike, camera: Camera) -> tuple[jax.Array, jax.Array]:
    """Projects world points onto the image.

    Args:
      world_points: [..., 3] world coordinates [m].
      camera: the camera.

    Returns:
      pixels: [..., 2] (u, v) [pixels] (u right, v down, pixel centres at +0.5).
      depth: [...] distance along the optical axis [m]; pixels of points with depth <= 0 (behind the
        camera) are meaningless.
    """
    points = world_to_camera(world_points, camera)
    depth = -points[..., 2]
    u = camera.cx + camera.fx * points[..., 0] / depth
    v = camera.cy - camera.fy * points[..., 1] / depth
    return jnp.stack([u, v], axis=-1), depth


def unproject_to_camera(pixels: ArrayLike, depth: ArrayLike, camera: Camera) -> jax.Array:
    """Camera-frame points [..., 3] [m] seen at `pixels` [..., 2] [pixels] with `depth` [...] [m]."""
    pixels = jnp.asarray(pixels)
    depth = jnp.asarray(depth)
    _check_last_axis(pixels, 2, "pixels")
    x = (pixels[..., 0] - camera.cx) / camera.fx * depth
    y = -(pixels[..., 1] - camera.cy) / camera.fy * depth
    return jnp.stack(jnp.broadcast_arrays(x, y, -depth), axis=-1)


def unproject(pixels: ArrayLike, depth: ArrayLike, camera: Camera) -> jax.Array:
    """World points [..., 3] [m] seen at `pixels` [..., 2] [pixels] with `depth` [...] [m]; inverse of `project`."""
    return camera_to_world(unproject_to_camera(pixels, depth, camera), camera)


def pixel_centres(width: int, height: int) -> jax.Array:
    """[height, width, 2] (u, v) coordinates [pixels] of every pixel centre, row 0 = top."""
    _check_image_size(width, height)
    u, v = jnp.meshgrid(jnp.arange(width) + 0.5, jnp.arange(height) + 0.5, indexing="xy")
    return jnp.stack([u, v], axis=-1).astype(jnp.float32)


def point_cloud_from_depth(
    depth: ArrayLike, camera: Camera, frame: Literal["camera", "world"] = "camera"
) -> jax.Array:
    """Organised point cloud of a depth image.

    Args:
      depth: [height, width] depth image [m] of `camera`.
      camera: the camera that took it.
      frame: "camera" or "world": the frame of the returned coordinates.

    Returns:
      [height, width, 3] coordinates [m] of the surface point seen at each pixel centre.
    """
    depth = jnp.asarray(depth)
    if depth.shape != (camera.height, camera.width):
        raise ValueError(
            f"depth must have the camera's image shape {(camera.height, camera.width)}, got {depth.shape}."
        )
    if frame not in ("camera", "world"):
        raise ValueError(f'frame must be "camera" or "world", got {frame!r}.')
    points = unproject_to_camera(pixel_centres(camera.width, camera.height), depth, camera)
    return camera_to_world(points, camera) if frame == "world" else points


def bilinear_lookup(image: ArrayLike, pixels: ArrayLike) -> jax.Array:
    """Bilinearly interpolated image values at sub-pixel positions.

    Differentiable w.r.t. `image` and `pixels`. Positions beyond the outermost pixel centres are clamped
    to the border (zero gradient w.r.t. `pixels` there).

    Args:
      image: [H, W] or [H, W, C].
      pixels: [..., 2] (u, v) [pixels], pixel centres at +0.5.

    Returns:
      [...] or [..., C] values.
    """
    image = jnp.asarray(image)
    pixels = jnp.asarray(pixels)
    if image.ndim not in (2, 3):
        raise ValueError(f"image must have shape [H, W] or [H, W, C], got {image.shape}.")
    _check_last_axis(pixels, 2, "pixels")
    height, width = image.shape[:2]
    x = jnp.clip(pixels[..., 0] - 0.5, 0, width - 1)
    y = jnp.clip(pixels[..., 1] - 0.5, 0, height - 1)
    x0 = jnp.clip(jnp.floor(x), 0, max(width - 2, 0))
    y0 = jnp.clip(jnp.floor(y), 0, max(height - 2, 0))
    wx, wy = x - x0, y - y0
    x0i, y0i = x0.astype(jnp.int32), y0.astype(jnp.int32)
    x1i, y1i = jnp.minimum(x0i + 1, width - 1), jnp.minimum(y0i + 1, height - 1)
    if image.ndim == 3:
        wx, wy = wx[..., None], wy[..., None]
    top = (1 - wx) * image[y0i, x0i] + wx * image[y0i, x1i]
    bottom = (1 - wx) * image[y1i, x0i] + wx * image[y1i, x1i]
    return (1 - wy) * top + wy * bottom


def pixels_per_metre_at_table(camera: Camera) -> jax.Array:
    """Image scale [pixels / m] on the table plane z = 0 where the optical axis meets it.

    Exact everywhere on the table for a camera looking straight down (`top_down_camera`); for a tilted
    camera it holds only near the principal point (and there only along the image x axis).
    """
    axis_distance = camera.position[2] / camera.rotation[2, 2]
    return camera.fx / axis_distance


def field_of_view_deg(camera: Camera) -> jax.Array:
    """Vertical field of view [degrees] of a camera with a centred principal point."""
    return jnp.rad2deg(2 * jnp.arctan(0.5 * camera.height / camera.fy))


__all__ = [
    "Camera",
    "intrinsics_from_fov",
    "look_at",
    "top_down_camera",
    "free_camera",
    "world_to_camera",
    "camera_to_world",
    "project",
    "unproject",
    "unproject_to_camera",
    "pixel_centres",
    "point_cloud_from_depth",
    "bilinear_lookup",
    "pixels_per_metre_at_table",
    "field_of_view_deg",
]
