"""Which push sequences do what: **fit** effect parameters, **select** (rank, accept, stop), **test** (report).

The test split is drawn first and touched only to report the chosen model's error. The other sequences
(the pool) fit and select: with enough of them, a single split into a fit part and a select part; with
fewer (a select part below :data:`CROSS_FIT_BELOW` sequences), cross-fitting over :data:`CROSS_FIT_FOLDS`
sequence folds, where every pool sequence is selected on by a model fitted without it. Either way the
selection decisions see only out-of-fold errors, and the reported model is refitted on the whole pool.

Refusing to guess: the loop needs at least :data:`MIN_SEQUENCES` push sequences (measured, see the
constant), :data:`MIN_TEST_SEQUENCES` of them in the test split, and enough selection sequences that the
sign-flip test (:func:`pushjax.loop.metrics.sign_flip_pvalues`) can pass the family-wise level at all:
its smallest p-value over ``S`` sequences is ``2^-S``, which must be below ``alpha / candidates``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from pushjax.loop.metrics import smallest_pvalue
from pushjax.loop.windows import Examples

MIN_SEQUENCES = 12
"""Fewest push sequences the loop selects on. Measured (``python benchmarks/close_loop_min_data.py``,
BENCHMARKS.md): on clean data sets of 12 to 48 sequences nothing was selected in any of 50 draws, so the
minimum is the smallest of that grid, which is also the sign-flip test's own floor for the 10 library
effects at 0.05 (8 select and 4 test sequences)."""
MIN_TEST_SEQUENCES = 4
"""Fewest sequences in the test split: fewer give no usable interval of the reported error."""
CROSS_FIT_BELOW = 100
"""A single select split needs at least this many sequences; below, the pool is cross-fitted (every pool sequence
selects, so the test sees three times the sequences of a 25 % select split). Measured (``benchmarks/close_loop_power.py
--start_poses scattered`` of commit 1135d3f, BENCHMARKS.md): at 200 pushes a single split of 50 select
sequences accepted a centre-of-mass offset adding 22 % to the error in 2 of 5 data sets, cross-fitting in 5 of 5,
with the level kept on a sign-flipped null (both scripts as of commit 1135d3f); 100 is twice the size measured short."""
CROSS_FIT_FOLDS = 4
TEST_FRACTION = 0.25
SELECT_FRACTION = 0.25
"""Default shares of all sequences in the test and the select split (the rest fits)."""


@dataclasses.dataclass(frozen=True, eq=False)
class Split:
    """The roles of the windows.

    Attributes:
      pool: the windows of every sequence that is not in the test split.
      test: the test split's windows.
      folds: [(fit indices, select indices)] into ``pool``; one pair for a single split, else the
        cross-fitting folds (their select indices partition the pool).
    """

    pool: Examples
    test: Examples
    folds: list[tuple[np.ndarray, np.ndarray]]

    @property
    def cross_fitted(self) -> bool:
        return len(self.folds) > 1

    @property
    def select_index(self) -> np.ndarray:
        """Pool indices of the selection windows, in the order of the folds."""
        return np.concatenate([select for _, select in self.folds])

    def n_pushes(self) -> dict[str, int]:
        """{"fit", "select", "test"}: pushes whose windows fit the parameters (of the first fold), select and test."""
        fit, select = self.folds[0][0], self.select_index
        return {"fit": self.pool.select(fit).n_pushes, "select": self.pool.select(select).n_pushes,
                "test": self.test.n_pushes}


def needed_sequences(n_candidates: int, alpha: float) -> int:
    """Fewest selection sequences with which the sign-flip test can reach ``alpha / n_candidates``."""
    return next(n for n in range(1, 64) if smallest_pvalue(n) <= alpha / max(n_candidates, 1))


def minimum_sequences(n_candidates: int, alpha: float, test_fraction: float = TEST_FRACTION) -> int:
    """Fewest push sequences :func:`split` accepts for ``n_candidates`` effects at the level ``alpha``."""
    n = MIN_SEQUENCES
    while True:
        n_test = _n_test(n, test_fraction)
        if n_test >= MIN_TEST_SEQUENCES and n - n_test >= needed_sequences(n_candidates, alpha):
            return n
        n += 1


def _n_test(n_sequences: int, test_fraction: float) -> int:
    return max(MIN_TEST_SEQUENCES, round(test_fraction * n_sequences))


def split(examples: Examples, n_candidates: int, alpha: float = 0.05, test_fraction: float = TEST_FRACTION,
          select_fraction: float = SELECT_FRACTION, seed: int = 0) -> Split:
    """Draws the test split and the fit/select roles of the other sequences.

    Args:
      examples: all windows.
      n_candidates: candidate effects of the first selection round (sets the test's family-wise level).
      alpha: family-wise error level of each selection decision.
      test_fraction: share of the sequences in the test split.
      select_fraction: share of all sequences in the select split (when not cross-fitted).
      seed: seed of the draw.

    Raises:
      ValueError: a fraction outside (0, 1), or too few push sequences ("push sequences: found N, need at
        least M ...").
    """
    for name, value in (("test_fraction", test_fraction), ("select_fraction", select_fraction)):
        if not 0 < value < 1:
            raise ValueError(f"{name}: expected a fraction in (0, 1), got {value!r}")
    if not test_fraction + select_fraction < 1:
        raise ValueError(f"test_fraction + select_fraction: expected less than 1, got {test_fraction + select_fraction}")
    sequences = np.unique(examples.sequence)
    needed = minimum_sequences(n_candidates, alpha, test_fraction)
    if len(sequences) < needed:
        raise ValueError(
            f"push sequences: found {len(sequences)}, need at least {needed} to select effects (at least "
            f"{MIN_TEST_SEQUENCES} to test on and {needed_sequences(n_candidates, alpha)} to select among "
            f"{n_candidates} effects at the level {alpha:g})")
    order = np.random.default_rng(seed).permutation(sequences)
    n_test = _n_test(len(sequences), test_fraction)
    is_test = np.isin(examples.sequence, order[:n_test])
    pool, test = examples.select(~is_test), examples.select(is_test)
    rest = order[n_test:]
    n_select = round(select_fraction * len(sequences))
    if n_select >= CROSS_FIT_BELOW:
        groups = [rest[:n_select]]
    else:
        groups = [rest[k::CROSS_FIT_FOLDS] for k in range(min(CROSS_FIT_FOLDS, len(rest)))]
    folds = []
    for group in groups:
        selected = np.isin(pool.sequence, group)
        folds.append((np.flatnonzero(~selected), np.flatnonzero(selected)))
    return Split(pool=pool, test=test, folds=folds)


