"""A stopping rule that does not follow evaluation noise: the trend of the validation score, with its uncertainty.

The convergence criterion of the ``data_efficiency_full`` run (`pushjax.train.convergence.CRITERION`) ends training
when the best of the last five scores is not 1 % better than the best before them. Between two evaluations the score
moves by 0.3-0.8 points from noise alone, as much as that 1 % (about 0.36 points at 190 080 examples), so the stop
largely follows the noise, and models that were still improving were stopped.

`TrendRule` (fixed before the long-trained models it judges were read) stops only when the data say, with 95 %
confidence, that further training gains little: a straight line fitted by least squares to the scores of the last
`TrendRule.window_steps` steps, whose one-sided upper confidence bound on the improvement per `TrendRule.per_steps`
steps is below `TrendRule.max_gain` points. Why 20 000 steps and 0.5 points per 10 000: with scores every 1 000 steps
and a noise of 0.5 points, a 10-evaluation window bounds the slope only to ±0.55 points per 10 000 steps (its
bound at a true slope of zero is about 1.0, so a rule strict enough to matter would never stop), a 20-evaluation window
to ±0.19 (bound about 0.36 at zero slope): a model that the rule stops gains, with 95 % confidence, less than 0.5
points in its next 10 000 steps; at a noise of 0.8 points it stops only once the fitted trend is flat or rising.

The score is the findings' (`pushjax.paper.statistics.SCORE`): the mean of the translation and rotation errors in %
of the ``zero`` baseline; lower is better, so an improvement is a falling score.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from scipy import stats


@dataclasses.dataclass(frozen=True)
class Trend:
    """The least-squares trend of a window of validation scores.

    Attributes:
      step: the last evaluation's step.
      evaluations: scores in the window.
      gain: the fitted improvement per `TrendRule.per_steps` steps, score points (positive: falling scores).
      gain_se: its standard error.
      gain_upper: its one-sided upper confidence bound.
      gain_lower: its one-sided lower confidence bound (> 0: still improving at that confidence).
    """

    step: int
    evaluations: int
    gain: float
    gain_se: float
    gain_upper: float
    gain_lower: float


@dataclasses.dataclass(frozen=True)
class TrendRule:
    """Stop when the one-sided upper bound on the improvement per `per_steps` steps, fitted over the last
    `window_steps` steps, is below `max_gain` score points.

    Attributes:
      window_steps: the span of the fitted window, steps (evaluations at steps in ``[last - window_steps, last]``).
      per_steps: the improvement is stated per this many steps.
      max_gain: the improvement per `per_steps` below which training may stop, score points.
      confidence: one-sided confidence of the bounds.
      min_evaluations: fewest evaluations in the window for a fit.
    """

    window_steps: int = 20_000
    per_steps: int = 10_000
    max_gain: float = 0.5
    confidence: float = 0.95
    min_evaluations: int = 10

    def __post_init__(self):
        for name in ("window_steps", "per_steps", "min_evaluations"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name}: expected a positive integer, got {getattr(self, name)}")
        if self.min_evaluations < 3:
            raise ValueError(f"min_evaluations: a trend's uncertainty needs at least 3, got {self.min_evaluations}")
        if self.max_gain <= 0:
            raise ValueError(f"max_gain: expected > 0, got {self.max_gain}")
        if not 0.5 < self.confidence < 1.0:
            raise ValueError(f"confidence: expected in (0.5, 1), got {self.confidence}")

    def trend(self, steps: Sequence[int], scores: Sequence[float], require_span: bool = True) -> Trend | None:
        """The trend of the evaluations (`steps`, `scores`: [n], in order) in the window that ends at the last one;
        None when the evaluations do not yet span the window (with `require_span`) or are fewer than
        `min_evaluations`."""
        steps, scores = np.asarray(steps, np.float64), np.asarray(scores, np.float64)
        if steps.shape != scores.shape or steps.ndim != 1:
            raise ValueError(f"steps and scores: expected two [n] arrays, got {steps.shape} and {scores.shape}")
        if len(steps) == 0 or (require_span and steps[-1] - steps[0] < self.window_steps):
            return None
        inside = steps >= steps[-1] - self.window_steps
        x, y = steps[inside], scores[inside]
        n = len(x)
        if n < self.min_evaluations:
            return None
        centred = x - x.mean()
        sxx = float(centred @ centred)
        slope = float(centred @ (y - y.mean())) / sxx
        residuals = y - y.mean() - slope * centred
        slope_se = float(np.sqrt(residuals @ residuals / (n - 2) / sxx))
        t = float(stats.t.ppf(self.confidence, n - 2))
        gain, gain_se = -slope * self.per_steps, slope_se * self.per_steps
        return Trend(int(steps[-1]), n, gain, gain_se, gain + t * gain_se, gain - t * gain_se)

    def stops(self, steps: Sequence[int], scores: Sequence[float]) -> bool:
        """Whether training may stop after the last of these evaluations."""
        trend = self.trend(steps, scores)
        return trend is not None and trend.gain_upper < self.max_gain

    def first_stop(self, steps: Sequence[int], scores: Sequence[float]) -> int | None:
        """The step of the first evaluation after which the rule stops (None: it never does in these)."""
        for end in range(1, len(steps) + 1):
            if self.stops(steps[:end], scores[:end]):
                return int(steps[end - 1])
        return None


IMPROVING = TrendRule(window_steps=10_000, min_evaluations=5)
"""Whether a curve still falls at its end: the trend of its last 10 000 steps (at least 5 evaluations; the window need
not be spanned), improving when its one-sided 95 % lower bound on the gain is above 0 (`Trend.gain_lower`)."""

RULE = TrendRule()
"""The rule, fixed before the long-trained models of Table 1 were read: `long_run_continues` applies it at 75 000
steps, and the audit of the ``data_efficiency_full`` models (`pushjax.paper.stopping_audit`) applies it to their
curves."""


def long_run_continues(curves: Sequence[tuple[Sequence[int], Sequence[float]]], rule: TrendRule = RULE) -> bool:
    """Whether a variant's fixed-budget models are continued to twice their steps: when the rule does not stop any
    seed's curve (`curves`: [(steps, scores)] per seed) at its last evaluation, i.e. a curve is still falling by more
    than the rule tolerates."""
    return any(not rule.stops(steps, scores) for steps, scores in curves)
