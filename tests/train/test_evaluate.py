import numpy as np
import pytest

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
