"""Means over seeds, sequence-bootstrap standard errors and paired differences (pushjax.paper.statistics)."""

import numpy as np
import pytest

from pushjax.paper import statistics, tables
from pushjax import stats
from pushjax.train import evaluate


def _examples(sequences=20, windows=10, seed=0):
    rng = np.random.default_rng(seed)
    motion = np.zeros((sequences * windows, 3), np.float32)
    motion[:, 0] = 0.01 * np.repeat(rng.uniform(0.5, 1.5, sequences), windows)
    motion[:, 2] = 0.02
    # How hard each sequence is: the windows of one sequence share it, so they are not independent.
    difficulty = np.repeat(rng.uniform(0.1, 2.0, sequences), windows) * (1 + 0.05 * rng.standard_normal(len(motion)))
    # Sequence ids are unique within a dataset, so another split (seed) has other ids.
    ids = 100 * seed + np.arange(sequences)
    return {"motion": motion, "sequence_id": np.repeat(ids, windows).astype(np.int32),
            "contact_flag": np.ones(len(motion), np.float32), "difficulty": difficulty.astype(np.float32)}


def _row(examples, fraction, seed, model="hybrid"):
    predicted = examples["motion"] + fraction * examples["difficulty"][:, None] * np.float32([0.005, 0.0, 0.01])
    metrics = evaluate.error_metrics({"motion": predicted}, examples)
    return {"model": model, "kind": "trained", "train_split": "train", "test_split": "test", "train_size": 100,
            "seed": seed, "l_scale": 1.0, **metrics}


def test_sequence_bootstrap_is_wider_than_treating_windows_as_independent():
    examples = _examples()
    with_sequences = _row(examples, 0.7, 0)
    without = _row({k: v for k, v in examples.items() if k != "sequence_id"}, 0.7, 0)
    assert with_sequences["trans_percent"] == pytest.approx(without["trans_percent"])
    assert with_sequences["trans_percent_se"] > 2 * without["trans_percent_se"]
    assert len(with_sequences["sequences"]["id"]) == 20


def test_estimate_combines_sequences_and_seeds():
    examples = _examples()
    rows = [_row(examples, fraction, seed) for seed, fraction in enumerate((0.6, 0.7, 0.8))]
    estimate = statistics.estimate(rows, "trans_percent")
    values = [row["trans_percent"] for row in rows]
    assert estimate.value == pytest.approx(np.mean(values))
    assert estimate.se_seeds == pytest.approx(np.std(values, ddof=1) / np.sqrt(3))
    assert estimate.se == pytest.approx(np.hypot(estimate.se_sequences, estimate.se_seeds))
    [aggregated] = tables.aggregate(rows)
    assert aggregated["trans_percent_se"] == pytest.approx(estimate.se)
    assert aggregated["trans_percent_se_seeds"] == pytest.approx(estimate.se_seeds)


def test_difference_on_one_test_split_is_paired():
    examples = _examples()
    a = statistics.estimate([_row(examples, 0.70, 0)], "score")
    b = statistics.estimate([_row(examples, 0.72, 0, model="neural")], "score")
    paired = statistics.difference(a, b)
    unpaired = np.hypot(a.se_sequences, b.se_sequences)
    assert paired.value == pytest.approx(a.value - b.value)
    # Both models err on the same sequences, so the paired difference is far more precise than either.
    assert paired.se_sequences < 0.2 * unpaired
    other_split = statistics.estimate([_row(_examples(seed=1), 0.72, 0)], "score")
    assert statistics.difference(a, other_split).se_sequences == pytest.approx(
        np.hypot(a.se_sequences, other_split.se_sequences))


def test_mean_over_independent_splits_shrinks_the_sequence_error():
    splits = [statistics.estimate([_row(_examples(seed=k), 0.7, 0)], "trans_percent") for k in range(4)]
    mean = statistics.mean_over(splits)
    assert mean.value == pytest.approx(np.mean([s.value for s in splits]))
    assert mean.se_sequences == pytest.approx(np.sqrt(np.sum([s.se_sequences ** 2 for s in splits])) / 4, rel=0.15)


def test_bootstrap_is_deterministic_and_differs_between_splits():
    first = stats.sequence_bootstrap_weights([1, 2, 3, 4])
    assert np.array_equal(first, stats.sequence_bootstrap_weights([1, 2, 3, 4]))
    assert not np.array_equal(first, stats.sequence_bootstrap_weights([5, 6, 7, 8]))
    assert np.all(first.sum(axis=1) == 4)
