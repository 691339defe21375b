"""Planar rigid-body helpers and the units pushjax reports in, shared by every layer.

Datasets and models work in SI units (m, rad); losses and reports use mm and degrees as the paper does.
Arrays broadcast: a yaw of shape [...] turns vectors of shape [..., 2].
"""

from __future__ import annotations

import numpy as np

M_TO_MM = 1000.0
"""Millimetres per metre."""


def rotation_matrix(yaw: np.ndarray | float) -> np.ndarray:
    """[..., 2, 2] matrices turning planar vectors counter-clockwise by `yaw` [...] (rad)."""
    cos, sin = np.cos(yaw), np.sin(yaw)
    return np.stack([np.stack([cos, -sin], axis=-1), np.stack([sin, cos], axis=-1)], axis=-2)


def rotate(vectors: np.ndarray, yaw: np.ndarray | float) -> np.ndarray:
    """[..., 2] `vectors` turned counter-clockwise by `yaw` [...] (rad); a negative yaw maps world axes to a
    frame turned by ``-yaw``."""
    vectors = np.asarray(vectors)
    cos, sin = np.cos(yaw), np.sin(yaw)
    return np.stack([cos * vectors[..., 0] - sin * vectors[..., 1], sin * vectors[..., 0] + cos * vectors[..., 1]],
                    axis=-1)


def centre_of_mass(centroid: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """[..., 2] world position of a body point given in its frame, for [..., 3] poses (x m, y m, yaw rad).

    Args:
      centroid: [2] the point in the body's tracked frame (e.g. `PushObject.centroid`), m.
      poses: [..., 3] poses of the tracked frame, world.
    """
    poses = np.asarray(poses)
    return poses[..., :2] + rotate(np.asarray(centroid), poses[..., 2])
