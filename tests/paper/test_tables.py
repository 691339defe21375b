"""Seed aggregation and table layout of pushjax.paper.tables, on hand-made rows."""

import math

import pytest

from pushjax.paper import tables


def _row(model, size, seed, trans, trans_se):
    return {"model": model, "kind": "trained" if size else "baseline", "train_split": "train", "test_split": "test",
            "train_size": size, "seed": seed, "l_scale": 1.0, "trans_percent": trans, "trans_percent_se": trans_se,
            "rot_percent": 2 * trans, "rot_percent_se": None}


def test_aggregate_averages_seeds_and_combines_standard_errors():
    [row] = tables.aggregate([_row("hybrid", 100, 0, 10.0, 3.0), _row("hybrid", 100, 1, 20.0, 4.0)])
    assert row["seeds"] == [0, 1]
    assert row["trans_percent"] == pytest.approx(15.0)
    assert row["trans_percent_se"] == pytest.approx(math.sqrt(9 + 16) / 2)
    assert row["rot_percent_se"] is None


def test_pivot_table_repeats_baselines_in_every_size_column():
    rows = [_row("zero", None, None, 100.0, 1.0), _row("hybrid", 100, 0, 10.0, 1.0), _row("hybrid", 2500, 0, 5.0, 0.5)]
    table = tables.pivot_table(tables.aggregate(rows), ["model"], "train_size")
    assert "| model | train_size=100 | train_size=2500 |" in table
    assert "| zero | 100.0 ± 1.0 / 200.0 | 100.0 ± 1.0 / 200.0 |" in table
    assert "| hybrid | 10.0 ± 1.0 / 20.0 | 5.0 ± 0.5 / 10.0 |" in table
