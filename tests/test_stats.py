"""The project's one decision rule (`pushjax.stats.decide`)."""

import math

import pytest

from pushjax import stats


def test_a_difference_is_decided_beyond_two_standard_errors():
    assert stats.DECISION_STANDARD_ERRORS == 2.0
    assert stats.decide(-2.1, 1.0) == stats.HOLDS
    assert stats.decide(2.1, 1.0) == stats.FAILS
    for within in (-1.99, -1.0, 0.0, 1.3, 1.99):
        assert stats.decide(within, 1.0) == stats.UNDECIDED


def test_an_unknown_standard_error_decides_nothing():
    for error in (None, math.nan, math.inf):
        assert stats.decide(-100.0, error) == stats.UNDECIDED
    assert stats.decide(math.nan, 1.0) == stats.UNDECIDED


def test_later_looks_need_pococks_larger_bound():
    assert stats.decision_bound() == stats.DECISION_STANDARD_ERRORS
    bounds = [stats.decision_bound(looks) for looks in sorted(stats.SEQUENTIAL_STANDARD_ERRORS)]
    assert bounds == sorted(bounds) and bounds[1] == pytest.approx(2.178)
    assert stats.decide(-2.1, 1.0, looks=2) == stats.UNDECIDED
    assert stats.decide(-2.2, 1.0, looks=2) == stats.HOLDS
    with pytest.raises(ValueError, match="looks"):
        stats.decide(-3.0, 1.0, looks=0)
