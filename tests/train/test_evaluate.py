import numpy as np
import pytest

from pushjax import stats
from pushjax.train import evaluate


def test_error_metrics_against_the_zero_baseline(examples):
    zero = {"motion": np.zeros_like(examples["motion"])}
    metrics = evaluate.error_metrics(zero, examples)
    assert metrics["trans_percent"] == pytest.approx(100.0)
    assert metrics["rot_percent"] == pytest.approx(100.0)
    perfect = {name: examples[name] for name in ("motion", "object_pos", "contact", "normal")}
    perfect["s"] = examples["contact_flag"]
    metrics = evaluate.error_metrics(perfect, examples)
    for name in ("trans_percent", "rot_percent", "pos_mm", "contact_mm", "normal_deg", "s"):
        assert metrics[name] == pytest.approx(0.0, abs=1e-3), name
    assert metrics["push_velocity_deg"] < 0.1


def test_state_errors_are_bootstrapped_over_sequences(examples):
    rng = np.random.default_rng(0)
    noisy = {name: examples[name] + rng.normal(0.0, 0.005, examples[name].shape).astype(np.float32)
             for name in ("motion", "object_pos", "contact", "normal")}
    noisy["s"] = np.clip(examples["contact_flag"] + rng.normal(0.0, 0.2, len(examples["motion"])), 0, 1)
    metrics = evaluate.error_metrics(noisy, examples)
    sequences = metrics["sequences"]
    touching = examples["contact_flag"] > 0.5
    assert sum(sequences["contact_count"]) == touching.sum()
    # The ratio of the per-sequence sums is the metric, and its standard error is the sequence bootstrap's.
    for metric in ("contact_mm", "normal_deg", "s", "push_velocity_deg"):
        numerator, denominator, _ = stats.SEQUENCE_RATIOS[metric]
        assert sum(sequences[numerator]) / sum(sequences[denominator]) == pytest.approx(metrics[metric], rel=1e-6)
        replicates = stats.bootstrap_replicates(sequences, metric)
        assert metrics[f"{metric}_se"] == pytest.approx(replicates.std(ddof=1)) and metrics[f"{metric}_se"] > 0
    # Without sequence ids the examples count as independent.
    alone = evaluate.error_metrics(noisy, {k: v for k, v in examples.items() if k != "sequence_id"})
    errors = np.linalg.norm(noisy["contact"] - examples["contact"], axis=-1)[touching] * 1000
    assert alone["contact_mm_se"] == pytest.approx(errors.std(ddof=1) / np.sqrt(errors.size), rel=1e-4)
