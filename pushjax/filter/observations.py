"""What the filters are given about a push: :class:`TrackedPush` (the pusher's path and the tracked poses on the
filter clock, with the truth they are scored against) and :class:`PositionStream` (a second sensor's readings of
the object's centre of mass, the filters' :class:`~pushjax.filter.models.PositionSensor` observation).

Made from simulated testbed pushes by ``pushjax.studies.tracking`` and read by a trained perception by
``pushjax.sensing.perception``; plain arrays, no MuJoCo.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["PositionStream", "TrackedPush"]


@dataclasses.dataclass(frozen=True)
class TrackedPush:
    """One simulated push as the filters see it, plus its truth, on the filter clock [T + 1].

    Attributes:
      name: the file name the push would have.
      obj: object name.
      pusher: [T + 1, 2] pusher centre, m.
      measurements: [T + 1, 3] tracked poses (x m, y m, yaw rad wrapped), NaN rows where dropped.
      truth: [T + 1, 3] true poses (yaw unwrapped).
      mu_nominal: the coefficient the file declares.
      mu_true: the coefficient the push was simulated with.
    """

    name: str
    obj: str
    pusher: np.ndarray
    measurements: np.ndarray
    truth: np.ndarray
    mu_nominal: float
    mu_true: float


@dataclasses.dataclass(frozen=True)
class PositionStream:
    """A second sensor's readings of the pushed objects' centres of mass on the filter clock, and its noise.

    Attributes:
      positions: {push name: [T + 1, 2] readings (world x m, y m) on that push's filter clock, NaN rows where the
        sensor has none (it runs slower than the filter)}; every evaluated push needs one.
      std: [2] standard deviation of a reading (world x m, y m), estimated on other pushes than the evaluated ones.
      details: what ``results.json`` records about the sensor (``perception``): its model, rate and how its noise was
        estimated.
    """

    positions: dict[str, np.ndarray]
    std: tuple[float, float]
    details: dict
