"""Prediction errors as in Kloss et al.: translation (mm) and rotation (deg), absolute and as % of the
``zero`` baseline (predicting no motion); their noise over push sequences (bootstrap intervals, a paired
sign-flip test) and the scores of a predicted distribution (negative log density, interval coverage).
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Sequence

import numpy as np
from scipy import optimize, stats

from pushjax import planar
from pushjax.stats import resample_sequences

METRIC_KEYS = ("trans_percent", "rot_percent", "trans_mm", "rot_deg")
EXACT_FLIPS_UP_TO = 13
"""Sign-flip tests over at most this many sequences enumerate every sign pattern (2^13 = 8192)."""


@dataclasses.dataclass(frozen=True)
class WindowErrors:
    """Per-window errors of one model, all [N].

    Attributes:
      translation_mm: |predicted - measured| displacement of the nominal centre of mass, mm.
      rotation_deg: |predicted - measured| yaw change, deg.
      zero_translation_mm: the ``zero`` baseline's translation error (the measured displacement), mm.
      zero_rotation_deg: the ``zero`` baseline's rotation error, deg.
      sequence: push sequence index of each window.
    """

    translation_mm: np.ndarray
    rotation_deg: np.ndarray
    zero_translation_mm: np.ndarray
    zero_rotation_deg: np.ndarray
    sequence: np.ndarray


def window_errors(prediction: np.ndarray, target: np.ndarray, sequence: np.ndarray) -> WindowErrors:
    """Errors of [N, 3] predictions (dx m, dy m, dtheta rad) against [N, 3] targets."""
    prediction, target = np.asarray(prediction, np.float64), np.asarray(target, np.float64)
    return WindowErrors(
        translation_mm=1e3 * np.linalg.norm(prediction[:, :2] - target[:, :2], axis=1),
        rotation_deg=np.abs(np.degrees(prediction[:, 2] - target[:, 2])),
        zero_translation_mm=1e3 * np.linalg.norm(target[:, :2], axis=1),
        zero_rotation_deg=np.abs(np.degrees(target[:, 2])),
        sequence=np.asarray(sequence),
    )


def concatenate(parts: list[WindowErrors]) -> WindowErrors:
    """The windows of several :class:`WindowErrors` (e.g. of cross-fitting folds) in order."""
    return WindowErrors(**{field.name: np.concatenate([getattr(part, field.name) for part in parts])
                           for field in dataclasses.fields(WindowErrors)})


def summarize(errors: WindowErrors) -> dict[str, float]:
    """{trans_percent, rot_percent, trans_mm, rot_deg}: mean errors, and their ratio to the zero baseline's in %."""
    return {
        "trans_percent": float(100 * errors.translation_mm.sum() / max(errors.zero_translation_mm.sum(), 1e-12)),
        "rot_percent": float(100 * errors.rotation_deg.sum() / max(errors.zero_rotation_deg.sum(), 1e-12)),
        "trans_mm": float(errors.translation_mm.mean()),
        "rot_deg": float(errors.rotation_deg.mean()),
    }


def combined(summary: dict[str, float]) -> float:
    """The selection score: translation + rotation error, each in % of the zero baseline."""
    return summary["trans_percent"] + summary["rot_percent"]


def _resampling_counts(sequence: np.ndarray, n_bootstrap: int, seed: int):
    """([B, S] multinomial counts of the S sequences, the per-sequence sum of any [N] values)."""
    ids, index = np.unique(sequence, return_inverse=True)

    def per_sequence(values):
        return np.bincount(index, weights=values, minlength=len(ids))

    return resample_sequences(len(ids), n_bootstrap, seed), per_sequence


def bootstrap_combined(errors: list[WindowErrors], n_bootstrap: int = 1000, seed: int = 0) -> np.ndarray:
    """[B, M] combined scores of M models (same windows) on B resamplings of the push sequences.

    Sequences are drawn with replacement (counts from a multinomial), the same draws for every model,
    so differences between models are paired.
    """
    counts, per_sequence = _resampling_counts(errors[0].sequence, n_bootstrap, seed)
    zero_t = counts @ per_sequence(errors[0].zero_translation_mm)
    zero_r = counts @ per_sequence(errors[0].zero_rotation_deg)
    scores = [100 * (counts @ per_sequence(e.translation_mm)) / np.maximum(zero_t, 1e-12)
              + 100 * (counts @ per_sequence(e.rotation_deg)) / np.maximum(zero_r, 1e-12) for e in errors]
    return np.stack(scores, axis=1)


def bootstrap_interval(errors: WindowErrors, n_bootstrap: int = 1000, seed: int = 0,
                       level: float = 0.95) -> dict[str, list[float]]:
    """{metric: [low, high]}: percentile bootstrap interval (push sequences resampled) of each of
    :data:`METRIC_KEYS` at the two-sided ``level``."""
    counts, per_sequence = _resampling_counts(errors.sequence, n_bootstrap, seed)
    windows = counts @ per_sequence(np.ones(len(errors.sequence)))
    resampled = {
        "trans_percent": 100 * (counts @ per_sequence(errors.translation_mm))
        / np.maximum(counts @ per_sequence(errors.zero_translation_mm), 1e-12),
        "rot_percent": 100 * (counts @ per_sequence(errors.rotation_deg))
        / np.maximum(counts @ per_sequence(errors.zero_rotation_deg), 1e-12),
        "trans_mm": (counts @ per_sequence(errors.translation_mm)) / windows,
        "rot_deg": (counts @ per_sequence(errors.rotation_deg)) / windows,
    }
    tail = (1 - level) / 2
    return {key: [float(np.quantile(resampled[key], tail)), float(np.quantile(resampled[key], 1 - tail))]
            for key in METRIC_KEYS}


def sequence_gains(reference: WindowErrors, others: list[WindowErrors]) -> np.ndarray:
    """[M, S] how much each push sequence lowers the combined score (points of %) from ``reference`` to
    each of M other models on the same windows; row sums are the score differences."""
    ids, index = np.unique(reference.sequence, return_inverse=True)
    zero_t = max(reference.zero_translation_mm.sum(), 1e-12)
    zero_r = max(reference.zero_rotation_deg.sum(), 1e-12)

    def contributions(errors):
        return (100 * np.bincount(index, errors.translation_mm, len(ids)) / zero_t
                + 100 * np.bincount(index, errors.rotation_deg, len(ids)) / zero_r)

    base = contributions(reference)
    return np.stack([base - contributions(other) for other in others]) if others else np.zeros((0, len(ids)))


def sign_flip_pvalues(gains: np.ndarray, n_flips: int = 10000, seed: int = 0) -> np.ndarray:
    """[M] one-sided p-values that the [M, S] per-sequence ``gains`` sum to more than chance would give.

    The paired randomization test over push sequences: under the null hypothesis each sequence's gain is
    as likely negative as positive, so the sum is compared with its value under every sign pattern
    (all 2^S when S <= :data:`EXACT_FLIPS_UP_TO`, else ``n_flips`` random ones plus the observed one).
    The smallest p-value S sequences can give is 2^-S.
    """
    gains = np.atleast_2d(np.asarray(gains, np.float64))
    count = gains.shape[1]
    if count <= EXACT_FLIPS_UP_TO:
        signs = np.array(list(itertools.product((1.0, -1.0), repeat=count))).reshape(-1, count)
        flipped = signs @ gains.T
        return np.mean(flipped >= gains.sum(axis=1) - 1e-12, axis=0)
    signs = np.random.default_rng(seed).choice((1.0, -1.0), size=(n_flips, count))
    flipped = signs @ gains.T
    return (1 + np.sum(flipped >= gains.sum(axis=1) - 1e-12, axis=0)) / (1 + n_flips)


def smallest_pvalue(n_sequences: int, n_flips: int = 10000) -> float:
    """The smallest p-value :func:`sign_flip_pvalues` can give over ``n_sequences`` sequences."""
    return 2.0 ** -n_sequences if n_sequences <= EXACT_FLIPS_UP_TO else 1 / (1 + n_flips)


def holm(p_values: np.ndarray, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Holm's step-down test of M hypotheses at the family-wise level ``alpha``.

    Returns:
      ([M] bool, whether each is rejected; [M] the level each p-value was compared with, ``alpha / (M - rank)``,
      the rank counted from the smallest p-value; a hypothesis after the first non-rejection keeps its level but
      is not rejected).
    """
    p_values = np.asarray(p_values, np.float64)
    order = np.argsort(p_values, kind="stable")
    levels = np.empty(len(p_values))
    levels[order] = alpha / (len(p_values) - np.arange(len(p_values)))
    passed = np.cumprod(p_values[order] <= levels[order]).astype(bool)
    rejected = np.empty(len(p_values), bool)
    rejected[order] = passed
    return rejected, levels


@dataclasses.dataclass(frozen=True)
class NoiseFloor:
    """The error the best possible model would still have on a set of windows.

    Attributes:
      trans_percent, rot_percent: translation and rotation error in % of the ``zero`` baseline's on the same windows.
      interval: {"trans_percent", "rot_percent": [low, high]} 95 % sequence-bootstrap interval.
      source: ``"repeats"`` (the spread of repeated pushes: tracking noise and everything that differs between
        repetitions) or ``"tracking"`` (the measurement noise seen in the pose streams and, where given, the motion's
        spread over the pushes' parameters, :mod:`pushjax.loop.variability`; a lower bound, where no push is repeated).
      n_windows: windows it is estimated on.
      from_variability: {"trans_percent", "rot_percent"}: how much of the floor the pushes' parameter spread adds to
        the tracking noise (0 from repeats, which hold it already).
    """

    trans_percent: float
    rot_percent: float
    interval: dict[str, list[float]]
    source: str
    n_windows: int
    from_variability: dict[str, float]

    @property
    def score(self) -> float:
        return self.trans_percent + self.rot_percent

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


MIN_REPEATED_WINDOWS = 20
"""Fewest windows with repetitions that :func:`noise_floor` estimates the floor from; fewer use tracking noise."""


def noise_floor(target: np.ndarray, sequence: np.ndarray, push: np.ndarray, window: np.ndarray,
                tracking_noise: np.ndarray, n_bootstrap: int = 1000, seed: int = 0,
                variability: np.ndarray | None = None) -> NoiseFloor:
    """The error of an oracle that predicts each window's expected motion, estimated from the data.

    With repeated pushes (windows of the same index in several pushes of one sequence), the oracle's error on a
    window is its distance from the other repetitions' mean, times ``sqrt((n - 1) / n)`` (which turns the spread
    about a leave-one-out mean into that about the true mean, for Gaussian spread). Without, the targets are
    differences of two poses each with white tracking noise ``s`` ([N, 3] ``tracking_noise``), and the motion varies by
    ``v`` ([N, 3] ``variability``) with the parameters that differ from push to push, which the oracle does not know
    for the push at hand: with per-axis variances ``2 s^2 + v^2`` (translation: their mean over the two axes) the
    oracle's mean error is Rayleigh's ``sqrt(pi / 2)`` times the standard deviation in translation and ``sqrt(2 / pi)``
    times it in rotation (``s sqrt(pi)`` and ``2 s / sqrt(pi)`` without variability).

    Args:
      target: [N, 3] measured motions (m, m, rad).
      sequence, push, window: [N] the windows' push sequence, push and index in the push.
      tracking_noise: [N, 3] measurement noise (m, m, rad).
      n_bootstrap, seed: the sequence bootstrap of the interval.
      variability: [N, 3] standard deviation of each window's motion over the pushes' parameter spread, object axes
        (m, m, rad; :func:`pushjax.loop.variability.window_spread`), or None.
    """
    target = np.asarray(target, np.float64)
    groups = np.unique(np.stack([sequence, window], axis=1), axis=0, return_inverse=True)[1].reshape(-1)
    sizes = np.bincount(groups)[groups]
    repeated = sizes > 1
    if repeated.sum() >= MIN_REPEATED_WINDOWS:
        source, keep = "repeats", repeated
        totals = np.stack([np.bincount(groups, target[:, axis]) for axis in range(3)], axis=1)[groups]
        n = sizes[:, None].astype(np.float64)
        others = (totals - target) / np.maximum(n - 1, 1)
        deviation = (target - others) * np.sqrt(np.maximum(n - 1, 1) / n)
        errors = [(np.linalg.norm(deviation[:, :2], axis=1), np.abs(deviation[:, 2]))]
    else:
        source, keep = "tracking", np.ones(len(target), bool)
        noise = np.asarray(tracking_noise, np.float64)
        errors = []
        for spread in [np.zeros_like(noise)] + ([] if variability is None else [np.asarray(variability, np.float64)]):
            variance = 2.0 * noise ** 2 + spread ** 2
            errors.append((np.sqrt(np.pi / 2) * np.sqrt(0.5 * (variance[:, 0] + variance[:, 1])),
                           np.sqrt(2 / np.pi) * np.sqrt(variance[:, 2])))

    def oracle_errors(trans, rot):
        return WindowErrors(translation_mm=1e3 * trans[keep], rotation_deg=np.degrees(rot[keep]),
                            zero_translation_mm=1e3 * np.linalg.norm(target[keep, :2], axis=1),
                            zero_rotation_deg=np.degrees(np.abs(target[keep, 2])), sequence=np.asarray(sequence)[keep])

    oracle = oracle_errors(*errors[-1])
    floor, without = summarize(oracle), summarize(oracle_errors(*errors[0]))
    interval = bootstrap_interval(oracle, n_bootstrap, seed)
    return NoiseFloor(trans_percent=floor["trans_percent"], rot_percent=floor["rot_percent"],
                      interval={key: interval[key] for key in ("trans_percent", "rot_percent")}, source=source,
                      n_windows=int(keep.sum()),
                      from_variability={key: floor[key] - without[key] for key in ("trans_percent", "rot_percent")})


@dataclasses.dataclass(frozen=True)
class RandomEffects:
    """One value estimated on several groups, as a random-effects meta-analysis sees it.

    Attributes:
      fixed_mean: the inverse-variance weighted mean (one shared value, no spread between groups).
      q: Cochran's Q of the groups about ``fixed_mean``.
      p_value: Q against chi-square with groups - 1 degrees of freedom (small: the groups differ beyond their errors).
      tau: the between-group standard deviation (:data:`TAU_ESTIMATORS`).
      tau_interval: (low, high) its Q-profile confidence interval (Viechtbauer 2007): the ``tau`` whose generalised Q,
        ``sum (value - mean(tau))^2 / (std^2 + tau^2)``, equals the chi-square quantiles with groups - 1 degrees of
        freedom; a bound is 0 where Q at ``tau = 0`` is below its quantile (the errors alone explain the groups' spread).
      mean, mean_std: the shared value (weights ``1 / (std^2 + tau^2)``) and its standard error.
      shrunk: [G] each group's value shrunk towards ``mean`` by ``tau^2 / (tau^2 + std^2)`` (empirical Bayes).
      shrunk_std: [G] their standard errors: the share of each group's own error that shrinkage keeps, plus the
        shared value's error carried by the share it borrows.
    """

    fixed_mean: float
    q: float
    p_value: float
    tau: float
    tau_interval: tuple[float, float]
    mean: float
    mean_std: float
    shrunk: np.ndarray
    shrunk_std: np.ndarray


TAU_ESTIMATORS = ("dersimonian_laird", "paule_mandel")
"""How :func:`random_effects` estimates ``tau``: DerSimonian-Laird's moment estimator (one step from the fixed-effect
weights), or Paule-Mandel's, the ``tau`` whose generalised Q equals its expectation, groups - 1 (DerSimonian & Kacker
2007). Where the groups' errors differ widely and ``tau`` is large against them, DerSimonian-Laird's falls short of the
spread and can lie below its own Q-profile interval; Paule-Mandel's always lies within it, and the two agree when
every group has the same error."""


def random_effects(value: np.ndarray, std: np.ndarray, level: float = 0.95,
                   estimator: str = "dersimonian_laird") -> RandomEffects:
    """Pools [G] group estimates with [G] standard errors (all > 0, G >= 2); see :class:`RandomEffects` (``level``: of
    ``tau_interval``; ``estimator``: one of :data:`TAU_ESTIMATORS`)."""
    if estimator not in TAU_ESTIMATORS:
        raise ValueError(f"estimator: expected one of {', '.join(TAU_ESTIMATORS)}, got {estimator!r}")
    value, variance = np.asarray(value, np.float64), np.asarray(std, np.float64) ** 2
    weight = 1.0 / variance
    fixed_mean = float(np.sum(weight * value) / np.sum(weight))
    q = float(np.sum(weight * (value - fixed_mean) ** 2))
    if estimator == "dersimonian_laird":
        tau_squared = max(0.0, (q - (len(value) - 1)) / (np.sum(weight) - np.sum(weight ** 2) / np.sum(weight)))
    else:
        tau_squared = _q_root(value, variance, len(value) - 1)
    random_weight = 1.0 / (variance + tau_squared)
    mean = float(np.sum(random_weight * value) / np.sum(random_weight))
    keep = tau_squared / (tau_squared + variance)
    return RandomEffects(fixed_mean=fixed_mean, q=q, p_value=float(stats.chi2.sf(q, len(value) - 1)),
                         tau=float(np.sqrt(tau_squared)), tau_interval=_tau_interval(value, variance, level), mean=mean, mean_std=float(np.sqrt(1.0 / np.sum(random_weight))),
                         shrunk=mean + keep * (value - mean),
                         shrunk_std=np.sqrt(keep * variance + (1.0 - keep) ** 2 / np.sum(random_weight)))


def _generalised_q(value: np.ndarray, variance: np.ndarray, tau_squared: float) -> float:
    """``sum (value - mean(tau))^2 / (variance + tau^2)``, ``mean(tau)`` weighted by ``1 / (variance + tau^2)``."""
    weight = 1.0 / (variance + tau_squared)
    mean = np.sum(weight * value) / np.sum(weight)
    return float(np.sum(weight * (value - mean) ** 2))


def _q_root(value: np.ndarray, variance: np.ndarray, target: float) -> float:
    """The ``tau^2 >= 0`` at which the generalised Q falls to ``target`` (0 where it is below it at ``tau = 0``)."""
    if _generalised_q(value, variance, 0.0) <= target:
        return 0.0
    # Q falls from Q(0) towards 0 as tau^2 grows; by tau^2 = 1e4 times the values' own variance plus the errors' it is
    # below every target that matters.
    largest = 1e4 * (np.var(value) + np.max(variance)) + 1e-300
    return float(optimize.brentq(lambda t: _generalised_q(value, variance, t) - target, 0.0, largest))


def _tau_interval(value: np.ndarray, variance: np.ndarray, level: float) -> tuple[float, float]:
    """The Q-profile interval of the between-group standard deviation (see :class:`RandomEffects`)."""
    low, high = (float(np.sqrt(_q_root(value, variance, stats.chi2.ppf(quantile, len(value) - 1))))
                 for quantile in (0.5 + level / 2, 0.5 - level / 2))
    return low, high


COVERAGE_LEVELS = (0.68, 0.95)
"""Central interval levels whose coverage the report gives (``coverage_68``, ``coverage_95``)."""


def standardised_residuals(mean: np.ndarray, std: np.ndarray, target: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """[N, 3] residuals along the object's axes and of the rotation over their predicted standard deviations.

    Args:
      mean: [N, 3] predicted means, world axes (m, m, rad).
      std: [N, 3] predicted standard deviations along the object's axes and of the rotation (m, m, rad).
      target: [N, 3] measured motions, world axes.
      yaw: [N] object orientation, rad (the axes of ``std``).
    """
    residual = np.asarray(target, np.float64) - np.asarray(mean, np.float64)
    local = np.column_stack([planar.rotate(residual[:, :2], -np.asarray(yaw, np.float64)), residual[:, 2]])
    return local / np.asarray(std, np.float64)


def interval_multipliers(z: np.ndarray, levels: Sequence[float] = COVERAGE_LEVELS) -> np.ndarray:
    """Split-conformal interval half-widths in units of the predicted standard deviation.

    Args:
      z: [N, 3] standardised residuals on calibration windows that chose nothing else about the model
        (:func:`standardised_residuals`; in the loop: out of fold on the select split).
      levels: central interval levels.

    Returns:
      [L, 3] per level and output, the ``ceil((N + 1) level) / N`` empirical quantile of ``|z|``: an interval
      ``mean ± multiplier * std`` then covers at least ``level`` of exchangeable new windows.
    """
    magnitude = np.abs(np.asarray(z, np.float64))
    count = len(magnitude)
    return np.stack([np.quantile(magnitude, min(1.0, np.ceil((count + 1) * level) / count), axis=0, method="higher")
                     for level in levels])


def predictive_scores(mean: np.ndarray, std: np.ndarray, target: np.ndarray, yaw: np.ndarray,
                      multipliers: np.ndarray | None = None) -> dict[str, float]:
    """Scores of Gaussian predictive distributions on [N, 3] targets (dx m, dy m, dtheta rad).

    Args:
      mean: [N, 3] predicted means, world axes (m, m, rad).
      std: [N, 3] predicted standard deviations along the object's axes and of the rotation (m, m, rad);
        the three outputs are independent.
      target: [N, 3] measured motions, world axes.
      yaw: [N] object orientation, rad (the axes of ``std``).
      multipliers: [L, 3] calibrated half-widths of the :data:`COVERAGE_LEVELS` intervals
        (:func:`interval_multipliers`), or None.

    Returns:
      {"nlpd": mean negative log predictive density per window (translation in mm, rotation in deg),
      "coverage_68", "coverage_95": shares of the outputs inside their central 68 % and 95 % Gaussian intervals,
      and with ``multipliers`` "calibrated_coverage_68", "calibrated_coverage_95": the same for the calibrated
      intervals}.
    """
    z = standardised_residuals(mean, std, target, yaw)
    units = np.array([1e3, 1e3, np.degrees(1.0)])
    log_density = stats.norm.logpdf(z) - np.log(np.asarray(std, np.float64) * units)
    scores = {"nlpd": float(-np.mean(log_density.sum(axis=1)))}
    for level in COVERAGE_LEVELS:
        scores[f"coverage_{round(100 * level)}"] = float(np.mean(np.abs(z) <= stats.norm.ppf(0.5 + level / 2)))
    if multipliers is not None:
        for level, half_width in zip(COVERAGE_LEVELS, multipliers):
            scores[f"calibrated_coverage_{round(100 * level)}"] = float(np.mean(np.abs(z) <= half_width))
    return scores
