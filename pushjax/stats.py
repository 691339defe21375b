"""Statistics over push sequences, the unit of every standard error in pushjax (NumPy only).

The windows of one push sequence share the object, the push and its unmodelled physics, so they are not
independent: uncertainty comes from resampling whole sequences (`resample_sequences`). Evaluation
(`pushjax.train.evaluate`), the tables of results (`pushjax.paper.statistics`) and the closed loop
(`pushjax.loop.metrics`) resample with this one function.

* `SEQUENCE_RATIOS` names each evaluation metric by the per-sequence sums it is a ratio of (``trans_percent``:
  100 x translation error / the ``zero`` baseline's, in mm); `bootstrap_replicates` resamples it.
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
