"""Tests of the fit / select / test roles of push sequences and of the refusal to select on too few."""

import numpy as np
import pytest

from pushjax.loop import splits
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes


@pytest.fixture(scope="module")
def examples(record):
    return build_examples(iter_pushes(record("clean")))[0]


def _sequences(examples, index=None):
    return set(np.unique(examples.sequence if index is None else examples.sequence[index]))


def test_single_split_keeps_the_roles_apart_and_is_seeded(examples, monkeypatch):
    monkeypatch.setattr(splits, "CROSS_FIT_BELOW", 30)  # the 120 recorded sequences as if they were many
    split = splits.split(examples, n_candidates=10, seed=3)
    assert not split.cross_fitted
    (fit, select), = split.folds
    assert split.n_pushes() == {"fit": 60, "select": 30, "test": 30}
    fit_sequences, select_sequences = _sequences(split.pool, fit), _sequences(split.pool, select)
    test_sequences = _sequences(split.test)
    assert not fit_sequences & select_sequences and not (fit_sequences | select_sequences) & test_sequences
    assert len(split.pool) + len(split.test) == len(examples)
    again = splits.split(examples, n_candidates=10, seed=3)
    np.testing.assert_array_equal(again.test.sequence, split.test.sequence)
    assert _sequences(splits.split(examples, n_candidates=10, seed=4).test) != test_sequences


def test_few_sequences_are_cross_fitted_and_never_tested_on(examples):
    subset = examples.select(examples.sequence < 40)
    split = splits.split(subset, n_candidates=10, seed=0)
    assert split.cross_fitted and len(split.folds) == splits.CROSS_FIT_FOLDS
    assert split.test.n_sequences == 10
    selected = np.sort(split.select_index)
    np.testing.assert_array_equal(selected, np.arange(len(split.pool)))  # every pool window selects once
    for fit, select in split.folds:
        assert not _sequences(split.pool, fit) & _sequences(split.pool, select)
    assert not _sequences(split.pool) & _sequences(split.test)


def test_too_few_sequences_are_refused_with_the_numbers(examples):
    needed = splits.minimum_sequences(10, 0.05)
    assert needed >= splits.MIN_SEQUENCES and splits.needed_sequences(10, 0.05) == 8  # 2^-8 <= 0.05 / 10 < 2^-7
    with pytest.raises(ValueError, match=f"push sequences: found 3, need at least {needed}"):
        splits.split(examples.select(examples.sequence < 3), n_candidates=10)
    splits.split(examples.select(examples.sequence < needed), n_candidates=10)
    with pytest.raises(ValueError, match="test_fraction"):
        splits.split(examples, n_candidates=10, test_fraction=0.0)

