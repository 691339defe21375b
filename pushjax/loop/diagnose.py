"""Where does the residual come from? Its dependence on candidate explanatory variables.

The strength of a variable is a cross-validated correction gain: the variable is binned (categories,
or up to :data:`MAX_BINS` quantile bins of the fit split), the per-bin medians of the fit split's
residual (measured minus predicted: translation in world, push or object axes, and rotation) are
shrunk towards zero by ``count / (count + SHRINKAGE)``, and the strength is the fraction of the
translation + rotation error (each in % of the ``zero`` baseline, as in effect selection)
that subtracting these medians removes. It is a ratio, so it does not depend on the residual's scale;
medians keep it robust to outliers; being cross-fitted over push sequences (every window is corrected
by medians learnt without its push), it is about zero or negative for a variable the residual does not
depend on, whatever the number of bins. The translation is binned in the axes (world, along/across
the push, object) with the largest gain. Its noise comes from a bootstrap over push sequences: a
variable is beyond noise when its strength is at least ``min_strength`` (relevant) and the lower
one-sided bootstrap bound (Bonferroni over the variables) is above zero (significant).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

from pushjax import planar
from pushjax.loop import metrics
from pushjax.loop.windows import CATEGORICAL, VARIABLES, Examples

MAX_BINS = 8
SHRINKAGE = 10.0
"""Bin medians are shrunk towards zero by count / (count + SHRINKAGE)."""
MIN_STRENGTH = 0.1
"""Default share of the error that a variable's correction must remove to count as structure."""
FRAMES = ("world", "push", "object")


@dataclasses.dataclass(frozen=True)
class Dependence:
    """How strongly the residual depends on one variable.

    Attributes:
      variable: the variable's name (see :data:`pushjax.loop.windows.VARIABLES`).
      strength: share of the translation + rotation error removed by correcting for the variable
        (see the module docstring).
      lower: the lower bootstrap bound of ``strength``.
      frame: the translation axes of the correction (``world``, ``push`` or ``object``).
      beyond_noise: relevant and significant (see :func:`diagnose`).
    """

    variable: str
    strength: float
    lower: float
    frame: str
    beyond_noise: bool


def _frame_angles(examples: Examples) -> dict[str, np.ndarray]:
    motion = np.asarray(examples.inputs.pusher_motion, np.float64)
    return {"world": np.zeros(len(examples)), "push": np.arctan2(motion[:, 1], motion[:, 0]),
            "object": np.asarray(examples.inputs.object_yaw, np.float64)}


def assign_bins(values: np.ndarray, kind: str) -> tuple[np.ndarray, Callable[[np.ndarray], np.ndarray]]:
    """Bins learnt from ``values`` of a variable of ``kind``: (the categories, or the edges between
    numeric bins; a function giving any values' bin indices, -1 for an unseen category)."""
    if kind == CATEGORICAL:
        categories = np.unique(values)
        lookup = {value: k for k, value in enumerate(categories)}
        return categories, lambda other: np.array([lookup.get(value, -1) for value in other])
    numbers = np.asarray(values, np.float64)
    distinct = np.unique(numbers)
    if len(distinct) <= MAX_BINS:
        edges = (distinct[1:] + distinct[:-1]) / 2
    else:
        edges = np.unique(np.quantile(numbers, np.linspace(0, 1, MAX_BINS + 1)[1:-1]))
    return edges, lambda other: np.searchsorted(edges, np.asarray(other, np.float64))


def diagnose(
    examples: Examples,
    prediction: np.ndarray,
    variables: Sequence[str] = tuple(VARIABLES),
    min_strength: float = MIN_STRENGTH,
    folds: int = 5,
    n_bootstrap: int = 500,
    alpha: float = 0.05,
    seed: int = 0,
) -> list[Dependence]:
    """Ranks the variables by how much of the error a cross-fitted correction for them removes.

    The push sequences are split into ``folds`` groups; each group's corrections are learnt on the
    other groups, so every window is corrected by medians that did not see its push.

    Args:
      examples: the windows.
      prediction: the model's [N, 3] predictions on them (dx m, dy m, dtheta rad).
      variables: names of the variables to test (keys of ``examples.variables``).
      min_strength: share of the error a correction must remove to count as structure.
      folds: number of sequence groups for cross-fitting (>= 2).
      n_bootstrap: bootstrap resamplings of the push sequences.
      alpha: family-wise error level of the "beyond noise" decisions.
      seed: seed of the fold assignment and the bootstrap.

    Returns:
      One :class:`Dependence` per variable, strongest first. ``beyond_noise`` holds when the strength is
      at least ``min_strength`` and its lower one-sided bootstrap bound is above zero.
    """
    if folds < 2:
        raise ValueError(f"folds: expected at least 2, got {folds}")
    prediction = np.asarray(prediction, np.float64)
    residual = examples.target - prediction
    angles = _frame_angles(examples)
    ids, sequence_index = np.unique(examples.sequence, return_inverse=True)
    fold = np.random.default_rng(seed).permutation(len(ids))[sequence_index] % min(folds, len(ids))
    base = metrics.window_errors(prediction, examples.target, examples.sequence)
    base_score = metrics.combined(metrics.summarize(base))
    quantile = alpha / max(len(variables), 1)
    results = []
    for name in variables:
        values = examples.variables[name]
        best = None
        for frame in FRAMES:
            local = np.column_stack([planar.rotate(residual[:, :2], -angles[frame]), residual[:, 2]])
            shift = np.zeros((len(examples), 3))
            for k in np.unique(fold):
                train, test = fold != k, fold == k
                shift[test] = _bin_medians(values[train], local[train], values[test], VARIABLES[name])
            corrected = prediction + np.column_stack([planar.rotate(shift[:, :2], angles[frame]), shift[:, 2]])
            errors = metrics.window_errors(corrected, examples.target, examples.sequence)
            strength = 1 - metrics.combined(metrics.summarize(errors)) / base_score
            if best is None or strength > best[0]:
                best = (strength, frame, errors)
        strength, frame, errors = best
        boot = metrics.bootstrap_combined([base, errors], n_bootstrap, seed)
        lower = float(np.quantile(1 - boot[:, 1] / boot[:, 0], quantile))
        results.append(Dependence(variable=name, strength=float(strength), lower=lower, frame=frame,
                                  beyond_noise=bool(strength >= min_strength and lower > 0)))
    return sorted(results, key=lambda dependence: -dependence.strength)


def _bin_medians(train_values, train_residual, test_values, kind) -> np.ndarray:
    """[M, 3] shrunken medians of the residual in the training windows' bins, for the test windows."""
    labels, assign = assign_bins(train_values, kind)
    n_bins = len(labels) if kind == CATEGORICAL else len(labels) + 1
    train_bin, test_bin = assign(train_values), assign(test_values)
    medians = np.zeros((n_bins + 1, 3))  # the last row: bins unseen in training
    for b in range(n_bins):
        members = train_bin == b
        count = members.sum()
        if count:
            medians[b] = np.median(train_residual[members], axis=0) * count / (count + SHRINKAGE)
    return medians[np.where(test_bin >= 0, test_bin, n_bins)]
