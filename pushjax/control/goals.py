"""The push-to-goal task: goals drawn per object, and what counts as success (fixed before any run).

A goal moves the object from its start pose, the origin at yaw 0, by a translation of uniform length in
:data:`TRANSLATION_RANGE` in a uniform direction and a rotation uniform within ±:data:`MAX_ROTATION_DEG`, drawn
from ``default_rng([seed, crc32(object)])``: the same seed gives every object the same goals whatever else is run.
Success is a final TRUE pose within :data:`SUCCESS_POSITION` and :data:`SUCCESS_YAW_DEG` of the goal; success rates
come with Wilson score intervals (:func:`wilson_interval`). When one model pushes better than another is decided by
the project's one rule (:func:`pushjax.stats.decide`, in :func:`pushjax.studies.push_to_goal.compare`): over the
goals both were given (same object, goal and planner; the goals are the unit), the mean paired difference of the time
to success, a failed goal counting as the episode's time limit, below zero by more than 2 standard errors of that mean
(Pocock's larger bound when the same comparison is looked at again with more goals); above zero by as much: worse;
in between: not decided with that many goals.
"""

from __future__ import annotations

import dataclasses
import math
import zlib
from collections.abc import Sequence

import numpy as np

__all__ = ["Goal", "MAX_ROTATION_DEG", "SUCCESS_POSITION", "SUCCESS_YAW_DEG", "TRANSLATION_RANGE", "draw_goals",
           "succeeded", "wilson_interval"]

SUCCESS_POSITION = 0.005
"""Largest final position error of a success, m (5 mm)."""
SUCCESS_YAW_DEG = 5.0
"""Largest final orientation error of a success, degrees."""
TRANSLATION_RANGE = (0.05, 0.20)
"""Range of the goals' translations, m."""
MAX_ROTATION_DEG = 90.0
"""Largest goal rotation, degrees (either sense)."""


@dataclasses.dataclass(frozen=True)
class Goal:
    """One task: push `obj` from `start` to `goal` (x m, y m, yaw rad); `index` numbers the object's goals."""

    obj: str
    index: int
    start: tuple[float, float, float]
    goal: tuple[float, float, float]


def draw_goals(objects: Sequence[str], per_object: int, seed: int) -> list[Goal]:
    """`per_object` goals for each object (see the module docstring), objects in the given order."""
    if per_object < 1:
        raise ValueError(f"per_object: expected a positive number of goals, got {per_object}")
    goals = []
    for obj in objects:
        rng = np.random.default_rng([seed, zlib.crc32(obj.encode("utf-8"))])
        for index in range(per_object):
            distance = rng.uniform(*TRANSLATION_RANGE)
            direction = rng.uniform(-math.pi, math.pi)
            rotation = math.radians(rng.uniform(-MAX_ROTATION_DEG, MAX_ROTATION_DEG))
            goals.append(Goal(obj=obj, index=index, start=(0.0, 0.0, 0.0),
                              goal=(distance * math.cos(direction), distance * math.sin(direction), rotation)))
    return goals


def succeeded(position_error: float, yaw_error: float) -> bool:
    """Whether a final error (position m, orientation rad) is a success."""
    return position_error < SUCCESS_POSITION and abs(math.degrees(yaw_error)) < SUCCESS_YAW_DEG


def wilson_interval(successes: int, trials: int, z: float = 1.959964) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion (95 % for the default `z`); (0, 1) without trials."""
    if trials == 0:
        return 0.0, 1.0
    rate = successes / trials
    denominator = 1 + z * z / trials
    centre = (rate + z * z / (2 * trials)) / denominator
    half = z * math.sqrt(rate * (1 - rate) / trials + z * z / (4 * trials * trials)) / denominator
    return max(0.0, centre - half), min(1.0, centre + half)
