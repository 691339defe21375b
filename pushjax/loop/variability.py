"""Push-to-push variability: a parameter that differs from push to push, its spread over the pushes with an interval.

A parameter read on each push (the pusher–object friction that the force sensor reads where the push slides,
:func:`pushjax.loop.force.sliding_friction`) scatters for two reasons: the readings' measurement error and a true spread
of the parameter between pushes. The random-effects model that pools the per-object and per-surface values
(:mod:`pushjax.loop.hierarchy`, :func:`pushjax.loop.metrics.random_effects`), with the pushes as its groups, tells them
apart: each reading's standard error is its measurement noise, ``tau`` the true spread (Paule-Mandel's estimate, which
lies within its Q-profile interval: the readings' errors differ by orders of magnitude between pushes, where
DerSimonian-Laird's estimate falls short of a large spread; :data:`pushjax.loop.metrics.TAU_ESTIMATORS`), with its
Q-profile interval.
The spread is reported relative to the population's mean (``relative_sd = tau / mean``), so that it compares with a
log-normal spread ``sigma`` of the parameter (relative standard deviation ``sqrt(exp(sigma^2) - 1)``, e.g. the testbed's
``pusher_friction_sigma``).

A model told the population's mean predicts a push with another value of the parameter wrongly, however good its
physics: :func:`window_spread` is how much each window's motion varies with the parameter's spread, which the loop adds
to its predictive noise and to the noise floor that ``explained`` is judged against.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from pushjax import planar
from pushjax.loop import fit as fit_lib
from pushjax.loop import metrics
from pushjax.loop.windows import Examples

MIN_PUSHES = 8
"""Fewest pushes with a reading (and its standard error) for a spread to be estimated."""
PUSHER_FRICTION_SOURCE = "force sensor: per-push sliding readings, pooled with pushes as random-effects groups"
"""The ``source`` of the pusher friction's variability."""


@dataclasses.dataclass(frozen=True)
class Variability:
    """The spread of one parameter over the pushes.

    Attributes:
      relative_sd: the true spread between pushes (random-effects ``tau``, Paule-Mandel) over the population's mean.
      interval: [low, high] its 95 % Q-profile interval, relative to the mean (low is 0 where the readings' measurement
        errors alone explain their scatter).
      mean: the population's mean (random-effects pooled value).
      mean_std: its standard error.
      measurement_relative_sd: the readings' root-mean-square standard error over the mean: the measurement noise.
      n_pushes: pushes with a reading.
      source: where the readings come from.
    """

    relative_sd: float
    interval: list[float]
    mean: float
    mean_std: float
    measurement_relative_sd: float
    n_pushes: int
    source: str

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def spread(value: np.ndarray, std: np.ndarray, source: str, estimator: str = "paule_mandel") -> Variability | None:
    """The spread of [P] per-push readings with [P] standard errors (NaN: no reading); None with fewer than
    :data:`MIN_PUSHES` readings (``estimator``: of ``tau``, :data:`pushjax.loop.metrics.TAU_ESTIMATORS`)."""
    value, std = np.asarray(value, np.float64), np.asarray(std, np.float64)
    known = np.isfinite(value) & np.isfinite(std) & (std > 0)
    if np.count_nonzero(known) < MIN_PUSHES:
        return None
    value, std = value[known], std[known]
    pooled = metrics.random_effects(value, std, estimator=estimator)
    return Variability(relative_sd=pooled.tau / pooled.mean, interval=[bound / pooled.mean for bound in pooled.tau_interval],
                       mean=pooled.mean, mean_std=pooled.mean_std,
                       measurement_relative_sd=float(np.sqrt(np.mean(std ** 2)) / pooled.mean),
                       n_pushes=int(len(value)), source=source)


def pusher_friction_readings(examples: Examples) -> tuple[np.ndarray, np.ndarray]:
    """[P] the force sensor's pusher-friction reading of each push of ``examples`` and [P] its standard error (NaN:
    the push slid too briefly for one), in the order of the pushes' indices."""
    _, first = np.unique(examples.push, return_index=True)
    return examples.push_friction[first], examples.push_friction_std[first]


def measure(examples: Examples) -> dict[str, Variability]:
    """{parameter: its spread over the pushes of ``examples``}, keyed by the loop's parameter names
    (``pusher_friction``); a parameter with too few readings is left out."""
    found = {"pusher_friction": spread(*pusher_friction_readings(examples), PUSHER_FRICTION_SOURCE)}
    return {name: values for name, values in found.items() if values is not None}


def window_spread(model: fit_lib.FitResult | None, examples: Examples,
                  variability: dict[str, Variability]) -> np.ndarray:
    """[N, 3] standard deviation of each window's predicted motion over the pushes' spread of the parameters.

    The model (None: Lynch's) predicts every window with the pusher–object friction ``exp(+-relative_sd)`` times the
    one it is given (one standard deviation either way, and never negative); half the difference is the motion's
    standard deviation (first order in the spread), along the object's axes and of the rotation (m, m, rad), as the
    predictive noise is.

    Args:
      model: the fitted model.
      examples: the windows.
      variability: :func:`measure`'s result; zeros without ``pusher_friction``.
    """
    if "pusher_friction" not in variability:
        return np.zeros((len(examples), 3))
    relative_sd = variability["pusher_friction"].relative_sd
    mu = np.asarray(examples.inputs.mu, np.float64)
    above, below = (fit_lib.predict([model], dataclasses.replace(
        examples, inputs=examples.inputs.replace(mu=mu * factor)))[0] for factor in np.exp([relative_sd, -relative_sd]))
    half = (above - below) / 2
    local = planar.rotate(half[:, :2], -np.asarray(examples.inputs.object_yaw, np.float64))
    return np.abs(np.column_stack([local, half[:, 2]]))
