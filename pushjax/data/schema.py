"""Field names, shapes and units of one example (one data point of the paper, Sec. III-B).

This is the contract between the dataset builders (`pushjax.data`) and the models and trainers
(`pushjax.models`, `pushjax.train`): a batch is a dict of NumPy arrays with these keys and a leading
batch axis. Lengths are in metres, angles in radians, time in seconds, pixel coordinates (u right,
v down, origin at the image's top-left corner, pixel centres at +0.5) as in `pushjax.render.camera`.

H, W are the image height and width of the dataset config.
"""

from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class Field:
    shape: tuple[int | str, ...]
    dtype: type
    doc: str


FIELDS: dict[str, Field] = {
    # Inputs.
    "depth": Field(("H", "W", 1), np.float32, "metric depth before the push (top-down camera), m"),
    "point_cloud": Field(("H", "W", 3), np.float32,
                         "organised point cloud before the push in world coordinates, m "
                         "(free-viewpoint experiment; zeros elsewhere)"),
    "pusher_pos": Field((2,), np.float32, "pusher centre p at the window start, world, m"),
    "pusher_pixel": Field((2,), np.float32, "pusher centre p in pixel coordinates"),
    "action": Field((2,), np.float32, "pusher displacement u over the horizon, world, m"),
    # Targets.
    "object_pos": Field((2,), np.float32, "object centre of mass o at the window start, world, m"),
    "object_pixel": Field((2,), np.float32, "o in pixel coordinates"),
    "motion": Field((3,), np.float32,
                    "object motion over the horizon: centre-of-mass translation (m, world) and yaw "
                    "change (rad)"),
    "motion_pixel": Field((2,), np.float32, "centre-of-mass translation in pixels"),
    # Ground-truth physical state (baselines, state-error table).
    "contact": Field((2,), np.float32, "contact point relative to the centre of mass, world axes, m"),
    "normal": Field((2,), np.float32, "inward unit surface normal at the contact, world; 0 if none"),
    "contact_flag": Field((), np.float32, "contact indicator s: 1 if the pusher touches the object"),
    "action_from_contact": Field((2,), np.float32,
                                 "action shortened to start at first contact, m (0 if none)"),
    "l": Field((), np.float32, "limit-surface ratio of the object, m"),
    "mu": Field((), np.float32, "pusher-object friction coefficient"),
    "push_velocity": Field((2,), np.float32,
                           "effective push velocity v_p of Lynch stage 1 for action_from_contact, m"),
    # Metadata.
    "object_id": Field((), np.int32, "index into pushjax.geometry.OBJECT_NAMES"),
    "surface_id": Field((), np.int32, "index into pushjax.sim surfaces (abs, delrin, plywood, pu)"),
    "velocity": Field((), np.float32, "pusher speed of the recorded push, mm/s (MIT file-name unit)"),
    "push_angle": Field((), np.float32, "push angle to the side's normal, rad"),
    "contact_point_id": Field((), np.int32, "id of the (side, point) pair of the push"),
    "sequence_id": Field((), np.int32, "id of the recorded push sequence the window comes from"),
    "start_time": Field((), np.float32, "window start within the push sequence, s"),
    "camera_intrinsics": Field((4,), np.float32, "fx, fy, cx, cy in pixels"),
    "camera_extrinsics": Field((4, 4), np.float32, "world_from_camera transform"),
    "scene_transform": Field((3, 3), np.float32,
                             "planar transform applied to the recorded scene for visual variety"),
}
