"""Statistics over push sequences, the unit of every standard error in pushjax (NumPy only).

The windows of one push sequence share the object, the push and its unmodelled physics, so they are not
independent: uncertainty comes from resampling whole sequences (`resample_sequences`). Evaluation
(`pushjax.train.evaluate`), the tables of results (`pushjax.paper.statistics`) and the closed loop
(`pushjax.loop.metrics`) resample with this one function.

* `SEQUENCE_RATIOS` names each evaluation metric by the per-sequence sums it is a ratio of (``trans_percent``:
  100 x translation error / the ``zero`` baseline's, in mm); `bootstrap_replicates` resamples it.
* `decide` is the project's one decision rule: every verdict of an experiment (the paper's findings, the rollouts'
  expectations, the push-to-goal comparisons) is a paired difference against `DECISION_STANDARD_ERRORS` of its
  standard error, or the larger `SEQUENTIAL_STANDARD_ERRORS` when the same question is looked at more than once.
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping, Sequence

import numpy as np

BOOTSTRAP_SAMPLES = 2000
"""Resamples of the push sequences behind every sequence-bootstrap standard error of evaluation."""

SEQUENCE_RATIOS = {
    "trans_percent": ("trans_mm", "trans_zero_mm", 100.0),
    "rot_percent": ("rot_deg", "rot_zero_deg", 100.0),
    "pos_mm": ("pos_mm", "count", 1.0),
    "contact_mm": ("contact_mm", "contact_count", 1.0),
    "normal_deg": ("normal_deg", "normal_count", 1.0),
    "s": ("s", "count", 1.0),
    "push_velocity_deg": ("push_velocity_deg", "push_velocity_count", 1.0),
}
"""metric -> (numerator, denominator, factor): the metric is factor * sum(numerator) / sum(denominator) over the
per-sequence sums of ``sequences`` (so a resample of the sequences gives a bootstrap replicate of it)."""


def resample_sequences(count: int, samples: int, seed: int | Sequence[int]) -> np.ndarray:
    """[samples, count] how often each of `count` sequences is drawn in each of `samples` bootstrap resamples.

    Args:
      count: the number of push sequences S.
      samples: the number of resamples B.
      seed: `np.random.default_rng` entropy (an int or a sequence of ints).
    """
    return np.random.default_rng(seed).multinomial(count, np.full(count, 1.0 / count), size=samples)


def sequence_bootstrap_weights(ids: Sequence[int], samples: int = BOOTSTRAP_SAMPLES) -> np.ndarray:
    """[samples, S] float `resample_sequences` of the S sequences `ids`, seeded by the ids.

    So every model evaluated on one test split is resampled identically (differences between models are paired)
    and different splits independently.
    """
    ids = np.asarray(ids, np.int64)
    return resample_sequences(len(ids), samples, [len(ids), samples, zlib.crc32(ids.tobytes())]).astype(np.float64)


def bootstrap_replicates(sequences: Mapping[str, Sequence[float]], metric: str) -> np.ndarray:
    """[BOOTSTRAP_SAMPLES] replicates of `metric` (a key of `SEQUENCE_RATIOS`) over resampled sequences.

    Args:
      sequences: per-sequence sums (`pushjax.train.evaluate.error_metrics`'s ``sequences``): {"id": [S], "count":
        [S], sums: [S]}.
      metric: e.g. ``"trans_percent"``.
    """
    numerator, denominator, factor = SEQUENCE_RATIOS[metric]
    weights = sequence_bootstrap_weights(sequences["id"])
    return factor * (weights @ np.asarray(sequences[numerator], np.float64)) / (
        weights @ np.asarray(sequences[denominator], np.float64))


DECISION_STANDARD_ERRORS = 2.0
"""The project's decision rule: a paired difference (better − worse, in the difference's own unit) decides a
comparison when it lies more than this many of its standard errors from zero (`decide`). The standard error is
that of the *paired* difference, and each caller names its unit of resampling: push sequences of a test split (with
the spread over world seeds where several were trained: `pushjax.paper.statistics`) for the paper's findings and
the rollouts' expectations; goals for the push-to-goal comparisons (`pushjax.studies.push_to_goal.compare`). At one
look this is the two-sided 5 % level of a normal difference (1.96), rounded up."""

SEQUENTIAL_STANDARD_ERRORS = {1: DECISION_STANDARD_ERRORS, 2: 2.178, 3: 2.289, 4: 2.361, 5: 2.413}
"""looks -> the bound of `decide` when the same comparison is looked at that many times as its data grow (equally
spaced looks; Pocock's two-sided boundary at the 5 % level for two and more). A verdict of a later look uses its
look's bound, and the record says how many looks were taken."""

HOLDS, FAILS, UNDECIDED = "holds", "does not hold", "not decided"
"""The verdicts of `decide`: the difference is below −bound standard errors (the claim "better beats worse"
holds), above +bound (it does not hold: worse beats better), or in between (not decided with these data)."""


def decision_bound(looks: int = 1) -> float:
    """Standard errors a difference must exceed at the last of `looks` looks (`SEQUENTIAL_STANDARD_ERRORS`).

    Raises:
      ValueError: `looks` is not one of `SEQUENTIAL_STANDARD_ERRORS`' keys (1-5).
    """
    if looks not in SEQUENTIAL_STANDARD_ERRORS:
        raise ValueError(f"looks: expected one of {sorted(SEQUENTIAL_STANDARD_ERRORS)}, got {looks}")
    return SEQUENTIAL_STANDARD_ERRORS[looks]


def decide(difference: float, standard_error: float | None, looks: int = 1) -> str:
    """The verdict on the claim "better beats worse" from their paired difference (better − worse, lower is better).

    Args:
      difference: better − worse, in the compared quantity's unit (e.g. points of % of zero, s).
      standard_error: the standard error of `difference`, same unit; None, NaN or infinite: unknown, so not decided.
      looks: how many times this comparison has been looked at, this one included (`decision_bound`).

    Returns:
      `HOLDS` when `difference` < −bound × `standard_error`, `FAILS` when it is > +bound × `standard_error`, else
      `UNDECIDED` (also for a NaN `difference`).
    """
    bound = decision_bound(looks)
    if standard_error is None or not np.isfinite(standard_error) or not np.isfinite(difference):
        return UNDECIDED
    if difference < -bound * standard_error:
        return HOLDS
    return FAILS if difference > bound * standard_error else UNDECIDED
