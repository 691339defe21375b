"""The MIT Push Dataset's push protocol: the grid of pushes and the pusher's path and motion (NumPy only).

Protocol (Yu et al., IROS 2016; the collection script ``collect_push_dataset_with_acceleration.py`` in
``github.com/mcubelab/push-est-public``): the pusher touches side ``i`` of the object at the fraction ``s`` of
its length (the pusher centre one pusher radius out along the side's normal) and moves in the direction of the
side's inward normal turned by the angle ``t`` (counter-clockwise positive), either at constant velocity ``v``
(``a = 0``) or accelerating from rest at ``a``, until it has travelled 5 cm past the contact point. Here the
pusher starts 3 mm before that contact point (along the push direction), at velocity ``v`` for constant-velocity
pushes (the robot reaches it within 0.2 mm at the dataset's 100 m/s²) and at rest for accelerating ones, which
accelerate up to ``v`` (the MIT robot capped them at 1 m/s).

The grid: velocities :data:`MIT_VELOCITIES`, accelerations :data:`MIT_ACCELERATIONS`, angles :data:`MIT_ANGLES`
and contact points :func:`side_points` on every side; :func:`sample_push` draws from it. The MuJoCo testbed
(:mod:`pushjax.sim.push`) drives its pusher along :func:`pusher_line` with :func:`pusher_motion`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object
from pushjax.mit.files import PushParams

PUSH_DISTANCE = 0.05
"""Pusher travel past the nominal contact point in m."""
APPROACH_DISTANCE = 0.003
"""Pusher travel before the nominal contact point in m."""

MIT_VELOCITIES = (10.0, 20.0, 50.0, 75.0, 100.0, 150.0, 200.0, 300.0, 400.0, 500.0)
"""Constant pusher velocities of the MIT grid, mm/s."""
MIT_ACCELERATIONS = (100.0, 200.0, 500.0, 750.0, 1000.0, 1500.0, 2000.0, 2500.0)
"""Pusher accelerations of the MIT grid, mm/s² (0 = constant velocity is the other option)."""
MIT_ANGLES = tuple(np.radians(np.linspace(-80.0, 80.0, 9)))
"""Push angles of the MIT grid to the side's inward normal, rad (-80° to 80° in 20° steps)."""


def side_points(obj: PushObject | str) -> np.ndarray:
    """Contact fractions ``s`` of the MIT grid on each side of ``obj``.

    The collection script pushes polygon sides at ``s`` = 0, 0.1, ..., 1 (it meant to use 0, 0.2, ..., 1 for
    hex, but its test compares the vertex list with the string "hex", so hex gets the 11 points too) and curved
    outlines at 40 points evenly spaced around the whole outline; with the outline cut into four quarter sides
    (see :class:`pushjax.geometry.PushObject`) that is ``s`` = 0, 0.1, ..., 0.9 on each quarter.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    if any(len(side) > 2 for side in obj.sides):
        return np.arange(10) / 10
    return np.linspace(0.0, 1.0, 11)


def sample_push(
    obj: PushObject | str,
    surface: str,
    rng: np.random.Generator,
    velocities: Sequence[float] = MIT_VELOCITIES,
    accelerations: Sequence[float] = (0.0,),
) -> PushParams:
    """A push drawn uniformly from the MIT grid: side, contact point, angle, velocity and acceleration.

    Args:
      obj: the object or its name.
      surface: surface name, stored in the returned parameters.
      rng: the random generator to draw from.
      velocities: allowed pusher velocities, mm/s (> 0; for accelerating pushes the top speed).
      accelerations: allowed pusher accelerations, mm/s² (0 = constant velocity).

    Returns:
      The push, with ``point`` and ``angle`` rounded to the 3 decimals that the file name keeps, so that the
      simulated push is exactly the one its file name describes.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    if not velocities or not accelerations:
        raise ValueError("velocities and accelerations: expected at least one value each")
    return PushParams(
        surface=surface,
        shape=obj.name,
        acceleration=float(rng.choice(np.asarray(accelerations, dtype=np.float64))),
        velocity=float(rng.choice(np.asarray(velocities, dtype=np.float64))),
        side=int(rng.integers(len(obj.sides))),
        point=round(float(rng.choice(side_points(obj))), 3),
        angle=round(float(rng.choice(MIT_ANGLES)), 3),
    )


def pusher_line(obj: PushObject | str, params: PushParams) -> tuple[np.ndarray, np.ndarray]:
    """Start point [2] (m, object frame) and unit direction [2] of the pusher centre's straight path."""
    if isinstance(obj, str):
        obj = get_object(obj)
    point, inward = obj.side_point(params.side, params.point)
    cos, sin = math.cos(params.angle), math.sin(params.angle)
    direction = np.array([cos * inward[0] - sin * inward[1], sin * inward[0] + cos * inward[1]])
    contact_centre = point - PUSHER_RADIUS * inward
    return contact_centre - APPROACH_DISTANCE * direction, direction


def pusher_motion(params: PushParams, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance travelled (m) and speed (m/s) of the pusher at ``times`` [T] (s) since it started."""
    travel = APPROACH_DISTANCE + PUSH_DISTANCE
    speed, acceleration = params.velocity_si, params.acceleration_si
    times = np.asarray(times, dtype=np.float64)
    if acceleration <= 0:
        distance = speed * times
        velocity = np.full_like(times, speed)
    else:
        ramp = speed / acceleration
        distance = np.where(times < ramp, 0.5 * acceleration * times ** 2, 0.5 * acceleration * ramp ** 2
                            + speed * (times - ramp))
        velocity = np.minimum(acceleration * times, speed)
    moving = distance < travel
    return np.where(moving, distance, travel), np.where(moving, velocity, 0.0)


def push_duration(params: PushParams) -> float:
    """Time in s from the start of the pusher's motion to its stop."""
    travel = APPROACH_DISTANCE + PUSH_DISTANCE
    speed, acceleration = params.velocity_si, params.acceleration_si
    if acceleration <= 0:
        return travel / speed
    ramp = speed / acceleration
    if 0.5 * acceleration * ramp ** 2 >= travel:
        return math.sqrt(2 * travel / acceleration)
    return ramp + (travel - 0.5 * acceleration * ramp ** 2) / speed
