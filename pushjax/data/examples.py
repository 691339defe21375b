"""Push sequences -> examples: the data points of the paper (Sec. III-B), with the fields of `pushjax.data.schema`.

From one recorded push sequence (a cleaned MIT-layout file, :class:`pushjax.mit.files.Push`):

1. Windows: ``windows_per_sequence`` start times drawn uniformly from the samples at which the pusher still
   moves for at least a quarter of the horizon, so windows that begin late hold shorter pushes (the pusher
   stops inside them). The window spans ``horizon`` seconds (0.5 s); the action ``u`` is the pusher's
   displacement over it and the target the object's motion.
2. Scene transforms: each window is seen ``transforms_per_window`` times, each time under a random planar rigid
   transform of the whole scene (object and pusher; the camera stays): a rotation uniform in
   [-max_rotation, max_rotation] and a translation that puts the object's centre of mass uniformly in the
   square of half width ``max_translation`` about the table origin, which both cameras look at; transforms
   that would put the pusher's start or end out of view are redrawn.
3. No-contact examples: a ``no_contact_fraction`` of the examples of every sequence do not touch the object.
   Windows in which the pusher misses the object by itself (grazing pushes at large angles, about 12 % at
   20 mm/s) count towards that share: windows are drawn from ``4 x windows_per_sequence`` candidates, keeping
   missing ones only while they fit in the share (unless too few touching windows exist). For the rest of the
   share, the pusher of randomly chosen touching examples is moved to a random spot within 5 cm of the object
   (and in view) from which its straight motion ``u`` does not touch the object (checked with
   :func:`pushjax.geometry.annotate`); the object then stays where it is, so their motion target is zero.
4. Ground-truth state from :func:`pushjax.geometry.annotate` at the window start (contact point relative to the
   centre of mass, inward normal, contact indicator, action from first contact), the uniform-pressure
   limit-surface ratio ``l`` of the object, the pusher-object friction ``mu`` (the file's
   ``pushjax_pusher_friction`` attribute, else the testbed's value) and the stage-1 effective push velocity of
   :func:`pushjax.physics.lynch.effective_push_velocity`.
5. Rendering: the depth image before the push (object at its window-start pose, pusher at ``p``), and for the
   free camera the organised point cloud in world coordinates.

Pixel coordinates (``object_pixel``, ``pusher_pixel``, ``motion_pixel``) project points on the plane of the
objects' top faces, ``z = THICKNESS`` (12.7 mm), which is what the depth image sees of the object there.
``motion_pixel`` is the difference of the projected centres of mass after and before the window.
"""

from __future__ import annotations

import functools
import math

import jax
import numpy as np

from pushjax import planar
from pushjax.data.configs import DatasetConfig, contact_point_id
from pushjax.data.schema import FIELDS, Field
from pushjax.geometry import OBJECT_NAMES, PUSHER_RADIUS, THICKNESS, annotate, get_object, limit_surface_ratio
from pushjax.mit.files import Push
from pushjax.physics import lynch
from pushjax.render.camera import Camera, free_camera, point_cloud_from_depth, top_down_camera
from pushjax.render.renderer import DepthRenderer
from pushjax.sim import scene
from pushjax.sim.surfaces import SURFACE_NAMES

EXTRA_FIELDS: dict[str, Field] = {
    "object_pose": Field((3,), np.float32,
                         "pose (x m, y m, yaw rad) of the object's tracked frame at the window start, world; "
                         "what DepthRenderer and annotate take"),
    "pusher_moved": Field((), np.int32, "1 if the pusher was moved away from the object (no-contact example)"),
    "first_contact_fraction": Field((), np.float32,
                                    "share of the action made before the first touch (1 if none)"),
}
"""Fields added to the schema's: every example carries ``FIELDS`` and these."""

ALL_FIELDS = {**FIELDS, **EXTRA_FIELDS}

MOVED_PUSHER_REACH = 0.05
"""A moved pusher starts within this distance (m) of the object's outline."""
_VIEW_MARGIN = 0.05
"""Pushers (start and end) stay this share of the image size away from the image border."""
_MOVE_CANDIDATES = 16
_MOVE_ROUNDS = 20
_WINDOW_CANDIDATES = 4
"""Candidate windows drawn per kept window."""
_TRANSFORM_ROUNDS = 10
"""Scene transforms drawn per example before falling back to a centred one."""
_MIN_WINDOW_PUSH = 0.25
"""The pusher moves during at least this share of every window's horizon."""


def make_camera(config: DatasetConfig) -> Camera:
    """The camera of a dataset: ``top_down_camera`` or ``free_camera`` at ``image_size`` pixels."""
    if config.camera == "free":
        return free_camera(config.image_size, config.image_size)
    return top_down_camera(config.image_size, config.image_size)


def make_renderer(config: DatasetConfig, obj: str, surface: str) -> DepthRenderer:
    """A depth renderer of the testbed scene of ``obj`` on ``surface`` seen by the dataset's camera."""
    model = scene.build_model(obj, surface)
    # Offscreen buffers of the image size, not the scene's 640 x 480 (one GL context per object and worker).
    model.vis.global_.offwidth = model.vis.global_.offheight = config.image_size
    return DepthRenderer(model, make_camera(config))


@functools.cache
def _limit_surface_ratio(obj: str) -> float:
    return limit_surface_ratio(get_object(obj))


@functools.cache
def _outline_radius(obj: str) -> float:
    shape = get_object(obj)
    return float(np.max(np.linalg.norm(shape.outline - shape.centroid, axis=1)))


def _com(obj: str, poses: np.ndarray) -> np.ndarray:
    """[E, 2] world centre of mass of [E, 3] tracked-frame poses."""
    return planar.centre_of_mass(get_object(obj).centroid, poses)


def _pixels(points_xy: np.ndarray, camera: Camera) -> np.ndarray:
    """[..., 2] pixel coordinates of table-plane points [..., 2] lifted to the top-face height.

    NumPy twin of :func:`pushjax.render.camera.project` (whose eager JAX calls would compile once per batch shape).
    """
    points = np.concatenate([points_xy, np.full(points_xy.shape[:-1] + (1,), THICKNESS)], axis=-1)
    world_from_camera = np.asarray(camera.world_from_camera, np.float64)
    in_camera = (points - world_from_camera[:3, 3]) @ world_from_camera[:3, :3]
    depth = -in_camera[..., 2]
    u = float(camera.cx) + float(camera.fx) * in_camera[..., 0] / depth
    v = float(camera.cy) - float(camera.fy) * in_camera[..., 1] / depth
    return np.stack([u, v], axis=-1)


def window_starts(tip_xy: np.ndarray, velocity: float, frequency: float, horizon_samples: int, count: int,
                  rng: np.random.Generator) -> np.ndarray:
    """[count] random window start indices (see the module docstring).

    Args:
      tip_xy: [T, 2] pusher positions on the sequence's clock, m.
      velocity: nominal pusher speed, m/s (a sample counts as moving above 5 % of it).
      frequency: rate of the clock, Hz.
      horizon_samples: window length in samples.
      count: number of starts to draw.
      rng: the generator.
    """
    step = np.linalg.norm(np.diff(tip_xy, axis=0), axis=1)
    moving = np.flatnonzero(step > 0.05 * velocity / frequency)
    if len(tip_xy) <= horizon_samples or len(moving) == 0:
        raise ValueError(f"tip_xy: a sequence of {len(tip_xy)} samples with the pusher moving in "
                         f"{len(moving)} of them has no window of {horizon_samples} samples")
    stop = int(moving[-1]) + 1
    latest = min(stop - math.ceil(_MIN_WINDOW_PUSH * horizon_samples), len(tip_xy) - 1 - horizon_samples)
    return rng.integers(0, max(latest, 0) + 1, size=count)


def _moved_pushers(obj: str, pose: np.ndarray, action: np.ndarray, camera: Camera,
                   rng: np.random.Generator) -> np.ndarray:
    """[M, 2] pusher starts near the object (pose [M, 3]) from which ``action`` [M, 2] misses it, in view."""
    count = len(pose)
    result = np.zeros((count, 2))
    todo = np.arange(count)
    com = _com(obj, pose)
    reach = _outline_radius(obj) + PUSHER_RADIUS + MOVED_PUSHER_REACH
    low, high = _VIEW_MARGIN * camera.width, (1 - _VIEW_MARGIN) * camera.width
    for _ in range(_MOVE_ROUNDS):
        angle = rng.uniform(0, 2 * np.pi, (len(todo), _MOVE_CANDIDATES))
        distance = reach * np.sqrt(rng.uniform(0, 1, (len(todo), _MOVE_CANDIDATES)))
        start = com[todo, None] + distance[..., None] * np.stack([np.cos(angle), np.sin(angle)], axis=-1)
        touches = annotate(obj, pose[todo, None], start, action[todo, None]).touches
        pixels = _pixels(np.stack([start, start + action[todo, None]], axis=-2), camera)
        visible = np.all((pixels >= low) & (pixels <= high), axis=(-1, -2))
        valid = ~touches & visible
        found = np.any(valid, axis=1)
        first = np.argmax(valid, axis=1)
        result[todo[found]] = start[found, first[found]]
        todo = todo[~found]
        if len(todo) == 0:
            return result
    raise RuntimeError(f"could not place a non-touching pusher in view for {len(todo)} examples of {obj}")


def _scene_transforms(com: np.ndarray, pusher_path: np.ndarray, config: DatasetConfig, camera: Camera,
                      rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Random scene rotations [E] (rad) and translations [E, 2] (m) that keep the pusher in view.

    Args:
      com: [E, 2] centres of mass before the transform, m.
      pusher_path: [E, 2, 2] pusher start and end before the transform, m.

    A draw that moves the pusher's start or end out of view (closer than 5 % of the image size to its border) is
    redrawn; after ``_TRANSFORM_ROUNDS`` failed draws the centre of mass is put at the table origin instead,
    where every MIT object and its pusher are in view.
    """
    count = len(com)
    rotation = rng.uniform(-config.max_rotation, config.max_rotation, count)
    target = np.zeros((count, 2))
    todo = np.arange(count)
    low, high = _VIEW_MARGIN * camera.width, (1 - _VIEW_MARGIN) * camera.width
    for _ in range(_TRANSFORM_ROUNDS):
        target[todo] = rng.uniform(-config.max_translation, config.max_translation, (len(todo), 2))
        translation = target[todo] - planar.rotate(com[todo], rotation[todo])
        ends = np.stack([planar.rotate(pusher_path[todo, k], rotation[todo]) + translation for k in range(2)], axis=1)
        pixels = _pixels(ends, camera)
        todo = todo[~np.all((pixels >= low) & (pixels <= high), axis=(1, 2))]
        if len(todo) == 0:
            break
    target[todo] = 0.0
    return rotation, target - planar.rotate(com, rotation)


def _choose_windows(push: Push, obj: str, horizon_samples: int, config: DatasetConfig,
                    rng: np.random.Generator) -> np.ndarray:
    """[windows_per_sequence] window starts, drawn at random, keeping windows whose pusher misses the object
    only while their examples stay within the no-contact share (when enough touching windows exist)."""
    frequency = 1.0 / float(push.time[1] - push.time[0])
    candidates = window_starts(push.tip[:, :2], push.params.velocity_si, frequency, horizon_samples,
                               _WINDOW_CANDIDATES * config.windows_per_sequence, rng)
    touches = annotate(obj, push.object[candidates], push.tip[candidates, :2],
                       push.tip[candidates + horizon_samples, :2] - push.tip[candidates, :2]).touches
    allowed_misses = math.floor(round(config.examples_per_sequence * config.no_contact_fraction)
                                / config.transforms_per_window)
    keep = touches | (np.cumsum(~touches) <= allowed_misses)
    chosen = np.concatenate([np.flatnonzero(keep), np.flatnonzero(~keep)])[:config.windows_per_sequence]
    return candidates[np.sort(chosen)]


def pusher_friction(push: Push) -> float:
    """The pusher-object friction of a recorded push: the file's ``pushjax_pusher_friction``, else the testbed's."""
    if "pushjax_pusher_friction" in push.attributes:
        return float(push.attributes["pushjax_pusher_friction"])
    return scene.pusher_friction()


def sequence_examples(push: Push, config: DatasetConfig, renderer: DepthRenderer, sequence_id: int,
                      rng: np.random.Generator) -> dict[str, np.ndarray]:
    """All examples of one push sequence, stacked.

    Args:
      push: the cleaned sequence (its file name must parse: the parameters become metadata).
      config: the dataset (window, transform and no-contact numbers, horizon, camera).
      renderer: a renderer of ``push``'s object with ``config``'s camera (:func:`make_renderer`).
      sequence_id: stored with every example.
      rng: the generator of windows, transforms and pusher moves.

    Returns:
      field name -> [E, ...] array with the dtypes of :data:`ALL_FIELDS`, E = ``config.examples_per_sequence``.
    """
    params = push.params
    if params is None:
        raise ValueError(f"push: {push.path} has no MIT file name, so no push parameters")
    obj = params.shape
    camera = renderer.camera
    frequency = 1.0 / float(push.time[1] - push.time[0])
    horizon_samples = round(config.horizon * frequency)
    starts = _window_starts(push, obj, frequency, horizon_samples, config, rng)
    count = len(starts)

    pose0, pose1 = push.object[starts], push.object[starts + horizon_samples]
    pusher = push.tip[starts, :2]
    action = push.tip[starts + horizon_samples, :2] - pusher
    rotation, translation = _scene_transforms(_com(obj, pose0), np.stack([pusher, pusher + action], axis=1),
                                              config, camera, rng)

    def moved_scene(poses):
        return np.concatenate([planar.rotate(poses[:, :2], rotation) + translation, (poses[:, 2] + rotation)[:, None]],
                              axis=1)

    pose0, pose1 = moved_scene(pose0), moved_scene(pose1)
    pusher = planar.rotate(pusher, rotation) + translation
    action = planar.rotate(action, rotation)
    contact, moved = _contact_with_misses(obj, pose0, pusher, action, config, camera, rng)
    com0, com1 = _com(obj, pose0), _com(obj, pose1)
    motion = np.concatenate([com1 - com0, (pose1[:, 2] - pose0[:, 2])[:, None]], axis=1)
    motion[moved] = 0.0
    com1 = com0 + motion[:, :2]

    l = _limit_surface_ratio(obj)
    mu = pusher_friction(push)
    push_velocity, _ = lynch.effective_push_velocity(
        contact.contact_rel_com, contact.normal, contact.action_from_contact, l, mu)

    pixels = _pixels(np.stack([com0, com1, pusher]), camera)
    depth = np.stack([renderer.depth(pose, position) for pose, position in zip(pose0, pusher)])
    if config.has_point_cloud:
        point_cloud = np.asarray(_world_point_clouds(depth, camera))
    else:
        point_cloud = np.zeros(depth.shape + (3,), np.float32)

    examples = {
        **_sequence_fields(params, camera, l, mu, sequence_id, count),
        "depth": depth[..., None],
        "point_cloud": point_cloud,
        "pusher_pos": pusher,
        "pusher_pixel": pixels[2],
        "action": action,
        "object_pos": com0,
        "object_pixel": pixels[0],
        "motion": motion,
        "motion_pixel": pixels[1] - pixels[0],
        "contact": contact.contact_rel_com,
        "normal": contact.normal,
        "contact_flag": contact.touches,
        "action_from_contact": contact.action_from_contact,
        "push_velocity": np.asarray(push_velocity),
        "start_time": push.time[starts],
        "scene_transform": _transform_matrices(rotation, translation),
        "object_pose": pose0,
        "pusher_moved": moved,
        "first_contact_fraction": contact.first_contact_fraction,
    }
    return {name: np.ascontiguousarray(examples[name], dtype=field.dtype) for name, field in ALL_FIELDS.items()}


def _sequence_fields(params, camera, l: float, mu: float, sequence_id: int, count: int) -> dict[str, np.ndarray]:
    """The fields every example of a sequence shares (its push's parameters `params`, the `camera`, the limit-surface
    ratio `l` m, the pusher friction `mu`), each repeated `count` times."""

    def repeated(value):
        return np.broadcast_to(np.asarray(value), (count,) + np.shape(value))

    return {"l": repeated(l), "mu": repeated(mu), "object_id": repeated(OBJECT_NAMES.index(params.shape)),
            "surface_id": repeated(_surface_id(params.surface)), "velocity": repeated(params.velocity),
            "push_angle": repeated(params.angle), "contact_point_id": repeated(contact_point_id(params)),
            "sequence_id": repeated(sequence_id),
            "camera_intrinsics": repeated(np.array([camera.fx, camera.fy, camera.cx, camera.cy])),
            "camera_extrinsics": repeated(np.asarray(camera.world_from_camera))}


def _window_starts(push: Push, obj: str, frequency: float, horizon_samples: int, config: DatasetConfig,
                   rng: np.random.Generator) -> np.ndarray:
    """[E] the first sample of each example's window (`frequency` Hz, windows of `horizon_samples`): chosen windows
    (the ``repeated`` experiment: its one start), each `config.transforms_per_window` times."""
    if config.experiment == "repeated":
        starts = np.full(config.windows_per_sequence, round(config.repeated_start_time * frequency))
        if starts[0] + horizon_samples >= len(push.time):
            raise ValueError(f"config: repeated_start_time {config.repeated_start_time} s leaves no window")
    else:
        starts = _choose_windows(push, obj, horizon_samples, config, rng)
    return np.repeat(starts, config.transforms_per_window)


def _contact_with_misses(obj: str, pose0: np.ndarray, pusher: np.ndarray, action: np.ndarray, config: DatasetConfig,
                         camera, rng: np.random.Generator):
    """The windows' contact annotation after moving enough pushers off the object for `config.no_contact_fraction`
    (windows in which the pusher naturally misses count towards it); `pusher` [E, 2] is moved in place. Returns the
    annotation and the [E] bool mask of moved pushers."""
    contact = annotate(obj, pose0, pusher, action)
    missing = round(len(pusher) * config.no_contact_fraction) - int(np.sum(~contact.touches))
    moved = np.zeros(len(pusher), bool)
    if missing > 0:
        moved[rng.permutation(np.flatnonzero(contact.touches))[:missing]] = True
        pusher[moved] = _moved_pushers(obj, pose0[moved], action[moved], camera, rng)
        contact = annotate(obj, pose0, pusher, action)
    return contact, moved


def _transform_matrices(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """[E, 3, 3] homogeneous planar transforms of the scene: rotation [E] rad, then translation [E, 2] m."""
    transform = np.zeros((len(rotation), 3, 3))
    transform[:, :2, :2] = np.stack([np.stack([np.cos(rotation), -np.sin(rotation)], -1),
                                     np.stack([np.sin(rotation), np.cos(rotation)], -1)], axis=1)
    transform[:, :2, 2] = translation
    transform[:, 2, 2] = 1.0
    return transform


def _surface_id(surface: str) -> int:
    if surface not in SURFACE_NAMES:
        raise ValueError(f"push: unknown surface {surface!r}, expected one of {', '.join(SURFACE_NAMES)}")
    return SURFACE_NAMES.index(surface)


@jax.jit
def _world_point_clouds(depth: jax.Array, camera: Camera) -> jax.Array:
    """[E, H, W, 3] world point clouds of [E, H, W] depth images of ``camera``."""
    return jax.vmap(lambda image: point_cloud_from_depth(image, camera, frame="world"))(depth)
