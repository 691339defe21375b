"""Means over seeds, their standard errors and paired differences, from the rows of ``results.json``.

A cell of a table (one model, training split and size, ``l`` factor and test split) holds one row per seed. Its
value is the mean over seeds, and two sources of uncertainty make its standard error:

* **sequences**: which push sequences happen to be in the test split. The windows of one sequence are not
  independent, so the unit is the sequence: a bootstrap over the test split's sequences
  (`pushjax.stats.bootstrap_replicates`) of the mean over seeds, every seed resampled alike.
* **seeds**: the training randomness (training subset and initialisation): the spread of the per-seed values,
  sd / sqrt(n). Baselines have no seed and no such part.

``se = sqrt(se_sequences² + se_seeds²)``. Every model evaluated on one test split is resampled with the same
sequence draws, so a difference between two cells on the same split (`difference`) is bootstrapped pairwise.
Rows written without per-sequence sums (older results) fall back to their own standard errors.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np

from pushjax.stats import SEQUENCE_RATIOS, bootstrap_replicates

SCORE = "score"
"""The findings' summary metric: the mean of ``trans_percent`` and ``rot_percent``."""


@dataclasses.dataclass(frozen=True)
class Estimate:
    """A mean over seeds with its parts of uncertainty.

    Attributes:
      value: the mean over seeds.
      se_sequences: standard error from resampling test sequences (None when unknown).
      se_seeds: standard error from the spread over seeds (None with one seed or none).
      seed_values: the per-seed values, in the order of the rows.
      replicates: [B] bootstrap replicates of `value`, or None.
      sequence_ids: the resampled test sequences (pairs replicates of two estimates), or None.
    """

    value: float
    se_sequences: float | None
    se_seeds: float | None
    seed_values: tuple[float, ...] = ()
    replicates: np.ndarray | None = dataclasses.field(default=None, repr=False, compare=False)
    sequence_ids: tuple[int, ...] | None = dataclasses.field(default=None, repr=False, compare=False)

    @property
    def se(self) -> float | None:
        """sqrt(se_sequences² + se_seeds²) over the parts that are known; None when neither is."""
        parts = [part for part in (self.se_sequences, self.se_seeds) if part is not None]
        return math.sqrt(sum(part * part for part in parts)) if parts else None

    def __str__(self) -> str:
        return f"{self.value:.1f}" + (f" ± {self.se:.1f}" if self.se is not None else "")


def _finite(value) -> bool:
    return value is not None and isinstance(value, (int, float)) and math.isfinite(value)


def _row_value(row: Mapping, metric: str) -> float | None:
    if metric == SCORE:
        trans, rot = row.get("trans_percent"), row.get("rot_percent")
        return (trans + rot) / 2.0 if _finite(trans) and _finite(rot) else None
    value = row.get(metric)
    return float(value) if _finite(value) else None


def _row_replicates(row: Mapping, metric: str) -> np.ndarray | None:
    sequences = row.get("sequences")
    if metric == SCORE:
        parts = [_row_replicates(row, name) for name in ("trans_percent", "rot_percent")]
        return None if parts[0] is None or parts[1] is None else (parts[0] + parts[1]) / 2.0
    if not sequences or metric not in SEQUENCE_RATIOS or SEQUENCE_RATIOS[metric][0] not in sequences:
        return None
    return bootstrap_replicates(sequences, metric)


def _row_se(row: Mapping, metric: str) -> float | None:
    if metric == SCORE:
        errors = (row.get("trans_percent_se"), row.get("rot_percent_se"))
        return math.hypot(*errors) / 2.0 if all(_finite(error) for error in errors) else None
    error = row.get(f"{metric}_se")
    return float(error) if _finite(error) else None


def _seed_se(values: Sequence[float]) -> float | None:
    return float(np.std(values, ddof=1) / math.sqrt(len(values))) if len(values) > 1 else None


def estimate(rows: Sequence[Mapping], metric: str) -> Estimate | None:
    """The `Estimate` of `metric` over the seeds of one cell; None when a row lacks the metric.

    Args:
      rows: the cell's rows of ``results.json`` (one per seed; a baseline has one row with seed None).
      metric: ``trans_percent``, ``rot_percent``, ``pos_mm`` (bootstrapped when the rows hold ``sequences``),
        `SCORE`, or any other numeric metric (then the seeds' spread only, besides the rows' own standard errors).
    """
    values = [_row_value(row, metric) for row in rows]
    if not rows or any(value is None for value in values):
        return None
    trained = any(row.get("seed") is not None for row in rows)
    se_seeds = _seed_se(values) if trained else None
    replicates = [_row_replicates(row, metric) for row in rows]
    ids = {tuple(row["sequences"]["id"]) for row in rows if row.get("sequences")}
    if all(replicate is not None for replicate in replicates) and len(ids) == 1 and len(next(iter(ids))) > 1:
        mean_replicates = np.mean(replicates, axis=0)
        return Estimate(float(np.mean(values)), float(mean_replicates.std(ddof=1)), se_seeds, tuple(values),
                        mean_replicates, ids.pop())
    row_errors = [_row_se(row, metric) for row in rows]
    # Without sequence sums the rows' own errors stand in (one test set: they do not average down over seeds).
    se_sequences = float(np.mean(row_errors)) if all(error is not None for error in row_errors) else None
    return Estimate(float(np.mean(values)), se_sequences, se_seeds, tuple(values))


def difference(a: Estimate, b: Estimate) -> Estimate:
    """``a - b`` with its standard error: paired over sequences when both were resampled on the same test
    sequences, else the parts of both combined as independent; the seed parts always as independent."""
    if a.replicates is not None and b.replicates is not None and a.sequence_ids == b.sequence_ids:
        replicates = a.replicates - b.replicates
        se_sequences = float(replicates.std(ddof=1))
    else:
        replicates = None
        parts = [part for part in (a.se_sequences, b.se_sequences) if part is not None]
        se_sequences = math.sqrt(sum(part * part for part in parts)) if parts else None
    seed_parts = [part for part in (a.se_seeds, b.se_seeds) if part is not None]
    se_seeds = math.sqrt(sum(part * part for part in seed_parts)) if seed_parts else None
    return Estimate(a.value - b.value, se_sequences, se_seeds, (), replicates, a.sequence_ids)


def mean_over(estimates: Sequence[Estimate]) -> Estimate:
    """The mean of estimates on different (independent) test splits with the same seeds, e.g. over velocities."""
    count = len(estimates)
    value = sum(e.value for e in estimates) / count
    seed_values = ()
    if all(len(e.seed_values) == len(estimates[0].seed_values) for e in estimates):
        seed_values = tuple(np.mean([e.seed_values for e in estimates], axis=0).tolist())
    se_seeds = _seed_se(seed_values) if all(e.se_seeds is not None for e in estimates) else None
    if all(e.replicates is not None for e in estimates):
        replicates = np.mean([e.replicates for e in estimates], axis=0)
        return Estimate(value, float(replicates.std(ddof=1)), se_seeds, seed_values, replicates,
                        tuple(i for e in estimates for i in e.sequence_ids))
    parts = [e.se_sequences for e in estimates]
    se_sequences = math.sqrt(sum(p * p for p in parts)) / count if all(p is not None for p in parts) else None
    return Estimate(value, se_sequences, se_seeds, seed_values)
