"""Integrate the quasi-static Lynch model along a whole pusher path.

The model predicts the object's motion for a small pusher displacement from the current contact
state; a push of several centimetres is the sum of many such steps, each re-annotating the contact
as the object moves and turns.
"""

from __future__ import annotations

import numpy as np

from pushjax import planar
from pushjax.geometry import contact as contact_lib
from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, limit_surface_ratio
from pushjax.physics import lynch


def rollout(
    obj: PushObject,
    object_pose: np.ndarray,
    pusher_start: np.ndarray,
    action: np.ndarray,
    mu: float,
    steps: int = 100,
    l: float | None = None,
    pusher_radius: float = PUSHER_RADIUS,
) -> np.ndarray:
    """Object poses along a straight push predicted by the Lynch model.

    Args:
      obj: the pushed object.
      object_pose: [3] start pose of the tracked frame (x m, y m, yaw rad).
      pusher_start: [2] pusher centre at the start, m (world).
      action: [2] total pusher displacement, m (world).
      mu: pusher-object friction coefficient.
      steps: number of equal pusher increments.
      l: limit-surface ratio in m (uniform pressure when omitted).
      pusher_radius: m.

    Returns:
      [steps + 1, 3] tracked-frame poses (x m, y m, yaw rad), the first being ``object_pose``.
    """
    if steps < 1:
        raise ValueError(f"steps: expected a positive integer, got {steps}")
    l = limit_surface_ratio(obj) if l is None else l
    pose = np.asarray(object_pose, dtype=np.float64).copy()
    increment = np.asarray(action, dtype=np.float64) / steps
    pusher = np.asarray(pusher_start, dtype=np.float64).copy()
    poses = [pose.copy()]
    for _ in range(steps):
        state = contact_lib.annotate(obj, pose, pusher, increment, radius=pusher_radius)
        motion = np.asarray(lynch.predict(
            state.contact_rel_com, state.normal, state.action_from_contact, l, mu))
        pose = _move_about_com(obj, pose, motion)
        pusher = pusher + increment
        poses.append(pose.copy())
    return np.stack(poses)


def _move_about_com(obj: PushObject, pose: np.ndarray, motion: np.ndarray) -> np.ndarray:
    """Apply a COM translation (dx, dy) and a rotation dtheta about the COM to a tracked-frame pose."""
    com_offset = planar.rotate(obj.centroid, pose[2])
    rotated_offset = planar.rotate(com_offset, motion[2])
    com = pose[:2] + com_offset + motion[:2]
    return np.array([*(com - rotated_offset), pose[2] + motion[2]])
