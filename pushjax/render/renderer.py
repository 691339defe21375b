"""Offscreen MuJoCo rendering of the pushing scene: depth images, point clouds and colour images.

Scene naming convention (shared with `pushjax.sim`):

* geom `table`: the table, its top surface at z = 0;
* body `object` with the free joint `object_joint`: the pushed object, body frame z-up;
* mocap body `pusher`: the pusher (a vertical cylinder);
* camera `camera`: a fixed camera attached to the world body.

The OpenGL backend is chosen where rendering starts, when the first `DepthRenderer` is made
(`choose_gl_backend`): ``MUJOCO_GL`` when it is set, else the first of `GL_BACKENDS` that works (headless EGL
first); importing pushjax sets nothing.
"""

from __future__ import annotations

import copy
import functools
import importlib
import inspect
import os
import weakref
from typing import Literal

import jax
import jax.numpy as jnp
import mujoco
import numpy as np

from pushjax.render.camera import Camera, point_cloud_from_depth

TABLE_GEOM = "table"
OBJECT_BODY = "object"
OBJECT_JOINT = "object_joint"
PUSHER_BODY = "pusher"
CAMERA = "camera"

PUSHER_CLEARANCE_M = 1e-3
"""Gap between the table top and the lowest point of the pusher [m], so the two never z-fight."""

_INTRINSICS_TOLERANCE_PX = 1e-3

GL_BACKENDS = ("egl", "osmesa", "glfw")
"""The OpenGL backends (values of ``MUJOCO_GL``) tried in turn when the variable is unset."""


@functools.cache
def choose_gl_backend() -> str:
    """The OpenGL backend of MuJoCo's offscreen rendering in this process, chosen on first use.

    ``MUJOCO_GL`` when set, else the first of `GL_BACKENDS` that renders; ``MUJOCO_GL`` is then set to it,
    so that processes started later (dataset build workers) inherit it. MuJoCo reads the variable when its
    OpenGL-context module loads (at ``import mujoco``), so that module is reloaded when the choice differs.

    Raises:
      RuntimeError: one line naming every backend tried and why it failed.
    """
    requested = os.environ.get("MUJOCO_GL")
    # The module whose `GLContext` mujoco.Renderer instantiates (its path differs between MuJoCo versions).
    gl_context = inspect.getmodule(mujoco.Renderer).gl_context
    failures = []
    for backend in (requested,) if requested else GL_BACKENDS:
        os.environ["MUJOCO_GL"] = backend
        try:
            if getattr(gl_context, "_MUJOCO_GL", backend) != backend.lower():
                gl_context = importlib.reload(gl_context)
            mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), height=1, width=1).close()
            return backend
        except Exception as error:  # each backend fails in its own way (ImportError, RuntimeError, GLError, ...)
            failures.append(f"MUJOCO_GL={backend}: {' '.join(str(error).split()) or type(error).__name__}")
    if not requested:
        del os.environ["MUJOCO_GL"]
    raise RuntimeError(f"no OpenGL backend for MuJoCo's offscreen rendering works ({'; '.join(failures)}); "
                       "headless machines need EGL (BUILD.md: libegl1 libegl-mesa0 libgl1-mesa-dri)")


def _object_id(model: mujoco.MjModel, object_type: mujoco.mjtObj, name: str, what: str) -> int:
    object_id = mujoco.mj_name2id(model, object_type, name)
    if object_id < 0:
        raise ValueError(f"model has no {what} named {name!r} (see the pushjax.render.renderer naming convention).")
    return object_id


def set_camera(model: mujoco.MjModel, camera: Camera, camera_name: str = CAMERA) -> None:
    """Writes `camera`'s pose and field of view into the fixed world camera `camera_name` of `model`.

    MuJoCo cameras have square pixels and a centred principal point, so `camera` must have fx == fy,
    cx == width / 2 and cy == height / 2. The camera is made a fixed perspective camera parametrised by
    `cam_fovy` (any sensor-size/intrinsics parametrisation of the model camera is cleared).

    Args:
      model: modified in place.
      camera: a single (unbatched) camera.
      camera_name: name of a camera attached to the world body.

    Raises:
      ValueError: the camera does not exist, is attached to a moving body, or `camera` is not
        representable by MuJoCo.
    """
    camera_id = _object_id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera_name, "camera")
    if model.cam_bodyid[camera_id] != 0:
        raise ValueError(f"camera {camera_name!r} must be attached to the world body.")
    fx, fy, cx, cy = (float(v) for v in (camera.fx, camera.fy, camera.cx, camera.cy))
    if abs(fx - fy) > _INTRINSICS_TOLERANCE_PX:
        raise ValueError(f"camera must have square pixels (fx == fy) for MuJoCo, got fx={fx}, fy={fy}.")
    if abs(cx - camera.width / 2) > _INTRINSICS_TOLERANCE_PX or abs(cy - camera.height / 2) > _INTRINSICS_TOLERANCE_PX:
        raise ValueError(
            f"camera must have a centred principal point (cx, cy) = {(camera.width / 2, camera.height / 2)} "
            f"for MuJoCo, got {(cx, cy)}."
        )
    world_from_camera = np.asarray(camera.world_from_camera, dtype=np.float64)
    if world_from_camera.shape != (4, 4):
        raise ValueError(f"camera.world_from_camera must have shape (4, 4), got {world_from_camera.shape}.")
    rotation = world_from_camera[:3, :3]
    if not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-5) or np.linalg.det(rotation) < 0:
        raise ValueError("camera.world_from_camera must be a rigid transform (proper rotation).")
    quaternion = np.empty(4)
    mujoco.mju_mat2Quat(quaternion, rotation.flatten())
    model.cam_pos[camera_id] = world_from_camera[:3, 3]
    model.cam_quat[camera_id] = quaternion
    model.cam_fovy[camera_id] = np.degrees(2 * np.arctan(0.5 * camera.height / fy))
    model.cam_mode[camera_id] = mujoco.mjtCamLight.mjCAMLIGHT_FIXED
    model.cam_projection[camera_id] = mujoco.mjtProjection.mjPROJ_PERSPECTIVE
    model.cam_sensorsize[camera_id] = 0.0


def _lowest_point_in_body_frame(model: mujoco.MjModel, body_id: int, what: str) -> float:
    """Lowest z [m] of the body's geoms (their bounding boxes) in the body frame."""
    geom_ids = np.flatnonzero(model.geom_bodyid == body_id)
    if geom_ids.size == 0:
        raise ValueError(f"{what} body has no geoms.")
    corner_signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1], indexing="ij")).reshape(3, -1).T
    lowest = np.inf
    for geom_id in geom_ids:
        centre, half_size = model.geom_aabb[geom_id, :3], model.geom_aabb[geom_id, 3:]
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, model.geom_quat[geom_id])
        corners = (centre + corner_signs * half_size) @ rotation.reshape(3, 3).T + model.geom_pos[geom_id]
        lowest = min(lowest, corners[:, 2].min())
    return float(lowest)


class DepthRenderer:
    """Renders the pushing scene from one camera at given object poses and pusher positions.

    The object is placed resting on the table: its body height is chosen so that the lowest point of
    its geoms' bounding boxes touches z = 0 (exact for prisms with a z-up body frame, such as all MIT
    push objects). The pusher is placed with its lowest point `PUSHER_CLEARANCE_M` above the table.

    The renderer works on its own copy of `model` (with the camera set from `camera`), so several
    renderers with different cameras can share one model. Use it as a context manager or call `close()`.

    Depth pixels that see nothing hold the far clipping distance `model.vis.map.zfar * model.stat.extent`.
    """

    def __init__(self, model: mujoco.MjModel, camera: Camera, camera_name: str = CAMERA):
        """Creates the renderer and its OpenGL context.

        Args:
          model: scene following the module's naming convention (not modified).
          camera: the camera to render from; sets the image size.
          camera_name: the model camera to drive.
        """
        self.model = copy.deepcopy(model)
        set_camera(self.model, camera, camera_name)
        self.camera = camera
        self._camera_id = _object_id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, camera_name, "camera")
        _object_id(self.model, mujoco.mjtObj.mjOBJ_GEOM, TABLE_GEOM, "geom")

        object_body = _object_id(self.model, mujoco.mjtObj.mjOBJ_BODY, OBJECT_BODY, "body")
        object_joint = _object_id(self.model, mujoco.mjtObj.mjOBJ_JOINT, OBJECT_JOINT, "joint")
        if self.model.jnt_type[object_joint] != mujoco.mjtJoint.mjJNT_FREE:
            raise ValueError(f"joint {OBJECT_JOINT!r} must be a free joint.")
        self._object_qpos_address = int(self.model.jnt_qposadr[object_joint])
        self.object_rest_z = -_lowest_point_in_body_frame(self.model, object_body, OBJECT_BODY)

        pusher_body = _object_id(self.model, mujoco.mjtObj.mjOBJ_BODY, PUSHER_BODY, "body")
        self._pusher_mocap_id = int(self.model.body_mocapid[pusher_body])
        if self._pusher_mocap_id < 0:
            raise ValueError(f"body {PUSHER_BODY!r} must be a mocap body.")
        self.pusher_z = PUSHER_CLEARANCE_M - _lowest_point_in_body_frame(self.model, pusher_body, PUSHER_BODY)

        global_visual = self.model.vis.global_
        global_visual.offwidth = max(global_visual.offwidth, camera.width)
        global_visual.offheight = max(global_visual.offheight, camera.height)
        self._data = mujoco.MjData(self.model)
        backend = choose_gl_backend()
        try:
            self._renderer = mujoco.Renderer(self.model, height=camera.height, width=camera.width)
        except mujoco.FatalError as error:
            raise RuntimeError(f"could not create an OpenGL context with MUJOCO_GL={backend}: {error}") from error
        # Frees the OpenGL context when the renderer is collected, and at the latest at interpreter exit
        # (atexit), while the modules that freeing needs still exist: mujoco.Renderer's own __del__ would run
        # during module teardown and print a traceback there.
        self._close = weakref.finalize(self, self._renderer.close)
        self._point_cloud = jax.jit(point_cloud_from_depth, static_argnames="frame")

    def set_state(self, object_pose: np.ndarray, pusher_xy: np.ndarray) -> None:
        """Poses the object and the pusher and updates the kinematics.

        Args:
          object_pose: [3] planar pose (x [m], y [m], yaw [rad]) resting on the table, or [7] free joint
            qpos (position [m], unit quaternion w-x-y-z), or [model.nq] full qpos.
          pusher_xy: [2] pusher position on the table [m].
        """
        object_pose = np.asarray(object_pose, dtype=np.float64)
        pusher_xy = np.asarray(pusher_xy, dtype=np.float64)
        if pusher_xy.shape != (2,):
            raise ValueError(f"pusher_xy must have shape (2,), got {pusher_xy.shape}.")
        qpos = self._data.qpos
        address = self._object_qpos_address
        if object_pose.shape == (self.model.nq,):
            qpos[:] = object_pose
        elif object_pose.shape in ((3,), (7,)):
            qpos[:] = self.model.qpos0
            if object_pose.shape == (3,):
                x, y, yaw = object_pose
                object_pose = np.array([x, y, self.object_rest_z, np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])
            qpos[address : address + 7] = object_pose
        else:
            raise ValueError(
                f"object_pose must have shape (3,) (x, y, yaw), (7,) (free joint qpos) or ({self.model.nq},) "
                f"(full qpos), got {object_pose.shape}."
            )
        self._data.mocap_pos[self._pusher_mocap_id] = (pusher_xy[0], pusher_xy[1], self.pusher_z)
        mujoco.mj_kinematics(self.model, self._data)
        mujoco.mj_comPos(self.model, self._data)  # centres of mass for tracking lights
        mujoco.mj_camlight(self.model, self._data)

    def _render(self, object_pose, pusher_xy, depth: bool) -> np.ndarray:
        self.set_state(object_pose, pusher_xy)
        if depth:
            self._renderer.enable_depth_rendering()
        else:
            self._renderer.disable_depth_rendering()
        self._renderer.update_scene(self._data, camera=self._camera_id)
        return self._renderer.render()

    def depth(self, object_pose: np.ndarray, pusher_xy: np.ndarray) -> np.ndarray:
        """[height, width] float32 depth image [m] (distance along the optical axis); arguments as in `set_state`."""
        return self._render(object_pose, pusher_xy, depth=True)

    def point_cloud(
        self, object_pose: np.ndarray, pusher_xy: np.ndarray, frame: Literal["camera", "world"] = "camera"
    ) -> np.ndarray:
        """[height, width, 3] float32 organised point cloud [m] in the camera or world frame; see `depth`."""
        depth = self.depth(object_pose, pusher_xy)
        return np.asarray(self._point_cloud(depth, self.camera, frame=frame))

    def rgb(self, object_pose: np.ndarray, pusher_xy: np.ndarray) -> np.ndarray:
        """[height, width, 3] uint8 colour image; arguments as in `set_state`."""
        return self._render(object_pose, pusher_xy, depth=False)

    def close(self) -> None:
        """Frees the OpenGL resources; the renderer is unusable afterwards. Closing twice does nothing."""
        self._close()

    def __enter__(self) -> DepthRenderer:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def planar_transform(translation_xy: jax.typing.ArrayLike, rotation_rad: jax.typing.ArrayLike) -> jax.Array:
    """[3, 3] homogeneous planar rigid transform: rotate by `rotation_rad` about the origin, then translate
    by `translation_xy` [2] [m]."""
    translation_xy = jnp.asarray(translation_xy, dtype=jnp.float32)
    if translation_xy.shape != (2,):
        raise ValueError(f"translation_xy must have shape (2,), got {translation_xy.shape}.")
    cos, sin = jnp.cos(rotation_rad), jnp.sin(rotation_rad)
    return jnp.array(
        [[cos, -sin, translation_xy[0]], [sin, cos, translation_xy[1]], [0.0, 0.0, 1.0]], dtype=jnp.float32
    )


def random_scene_transform(
    rng: np.random.Generator | jax.Array, max_translation_m: float, max_rotation_rad: float
) -> np.ndarray | jax.Array:
    """Random planar rigid transform of the whole scene (object and pusher, camera fixed) for visual variety.

    The rotation angle is uniform in [-max_rotation_rad, max_rotation_rad] (about the table origin) and
    each translation component is uniform in [-max_translation_m, max_translation_m].

    Args:
      rng: a `np.random.Generator` (returns a numpy array) or a JAX PRNG key (returns a JAX array).
      max_translation_m: largest shift per axis [m], >= 0.
      max_rotation_rad: largest rotation [rad], >= 0.

    Returns:
      [3, 3] homogeneous transform (see `planar_transform`); store it with the sample and apply it with
      `apply_scene_transform`.
    """
    for name, value in (("max_translation_m", max_translation_m), ("max_rotation_rad", max_rotation_rad)):
        if not float(value) >= 0:
            raise ValueError(f"{name} must be >= 0, got {value}.")
    if isinstance(rng, np.random.Generator):
        tx, ty = rng.uniform(-max_translation_m, max_translation_m, size=2)
        rotation = rng.uniform(-max_rotation_rad, max_rotation_rad)
        cos, sin = np.cos(rotation), np.sin(rotation)
        return np.array([[cos, -sin, tx], [sin, cos, ty], [0.0, 0.0, 1.0]])
    translation_key, rotation_key = jax.random.split(rng)
    translation = jax.random.uniform(translation_key, (2,), minval=-max_translation_m, maxval=max_translation_m)
    rotation = jax.random.uniform(rotation_key, (), minval=-max_rotation_rad, maxval=max_rotation_rad)
    return planar_transform(translation, rotation)


def _check_transform(transform: jax.Array) -> None:
    if transform.shape != (3, 3):
        raise ValueError(f"transform must have shape (3, 3), got {transform.shape}.")


def transform_planar_points(transform: jax.typing.ArrayLike, points_xy: jax.typing.ArrayLike) -> jax.Array:
    """Applies a [3, 3] planar transform to points [..., 2] [m]. Directions: use `transform[:2, :2]` only."""
    transform, points_xy = jnp.asarray(transform), jnp.asarray(points_xy)
    _check_transform(transform)
    if points_xy.ndim < 1 or points_xy.shape[-1] != 2:
        raise ValueError(f"points_xy must have shape [..., 2], got {points_xy.shape}.")
    return points_xy @ transform[:2, :2].T + transform[:2, 2]


def transform_planar_poses(transform: jax.typing.ArrayLike, poses: jax.typing.ArrayLike) -> jax.Array:
    """Applies a [3, 3] planar transform to poses [..., 3] (x [m], y [m], yaw [rad]); yaw is not wrapped."""
    transform, poses = jnp.asarray(transform), jnp.asarray(poses)
    _check_transform(transform)
    if poses.ndim < 1 or poses.shape[-1] != 3:
        raise ValueError(f"poses must have shape [..., 3], got {poses.shape}.")
    xy = transform_planar_points(transform, poses[..., :2])
    yaw = poses[..., 2] + jnp.arctan2(transform[1, 0], transform[0, 0])
    return jnp.concatenate([xy, yaw[..., None]], axis=-1)


def apply_scene_transform(
    transform: jax.typing.ArrayLike, object_pose: jax.typing.ArrayLike, pusher_xy: jax.typing.ArrayLike
) -> tuple[jax.Array, jax.Array]:
    """Moves a scene by `transform` [3, 3]: returns (object_pose [..., 3], pusher_xy [..., 2]) transformed."""
    return transform_planar_poses(transform, object_pose), transform_planar_points(transform, pusher_xy)


__all__ = [
    "TABLE_GEOM",
    "OBJECT_BODY",
    "OBJECT_JOINT",
    "PUSHER_BODY",
    "CAMERA",
    "PUSHER_CLEARANCE_M",
    "set_camera",
    "DepthRenderer",
    "planar_transform",
    "random_scene_transform",
    "transform_planar_points",
    "transform_planar_poses",
    "apply_scene_transform",
]
