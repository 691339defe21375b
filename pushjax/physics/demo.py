"""A 5 cm push of every MIT object predicted by the analytical model, as a markdown table."""

from __future__ import annotations

import numpy as np

from pushjax import planar
from pushjax.geometry.objects import PUSHER_RADIUS, all_objects, limit_surface_ratio
from pushjax.physics.rollout import straight_push

PUSH_DISTANCE = 0.05


def analytical_push_table(mu: float = 0.25, angle_deg: float = 20.0, point: float = 0.3,
                          steps: int = 100) -> str:
    """Markdown table of the final object motion for a push on side 0 of every object.

    Args:
      mu: pusher-object friction coefficient.
      angle_deg: push direction relative to the side's inward normal, degrees.
      point: contact point along side 0 as a fraction in [0, 1].
      steps: integration steps over the 5 cm push.
    """
    if not np.isfinite(mu) or mu < 0:
        raise ValueError(f"mu: expected a finite non-negative friction coefficient, got {mu}")
    if not -90.0 < angle_deg < 90.0:
        raise ValueError(f"angle_deg: expected a push into the side, in (-90, 90), got {angle_deg}")
    rows = ["| object | l (mm) | dx (mm) | dy (mm) | dtheta (deg) |", "|---|---:|---:|---:|---:|"]
    angle = np.deg2rad(angle_deg)
    for obj in all_objects():
        surface_point, normal = obj.side_point(0, point)
        direction = planar.rotation_matrix(angle) @ normal
        pusher_start = surface_point - direction * (PUSHER_RADIUS / max(direction @ normal, 1e-6) + 1e-3)
        poses = straight_push(obj, np.zeros(3), pusher_start, PUSH_DISTANCE * direction, mu, steps=steps)
        dx, dy, dtheta = poses[-1] - poses[0]
        l = limit_surface_ratio(obj)
        rows.append(f"| {obj.name} | {l * 1e3:.1f} | {dx * 1e3:.1f} | {dy * 1e3:.1f} | {np.rad2deg(dtheta):.1f} |")
    return "\n".join(rows)
