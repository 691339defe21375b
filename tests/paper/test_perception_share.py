"""The perception's share of hybrid's error, on the smoke run of data_efficiency_full."""

import json

import numpy as np
import pytest
from absl import app

from pushjax.paper import baselines, perception_share
from tests.paper.conftest import run_binary


def test_true_state_is_physics_with_the_window_action():
    rng = np.random.default_rng(0)
    n = 16
    angle = rng.uniform(0, 2 * np.pi, n)
    examples = {"motion": np.zeros((n, 3), np.float32), "contact": rng.normal(0, 0.03, (n, 2)),
                "normal": np.stack([np.cos(angle), np.sin(angle)], -1), "action": rng.normal(0, 0.005, (n, 2)),
                "l": np.full(n, 0.03), "mu": np.full(n, 0.25), "contact_flag": np.ones(n)}
    examples["action_from_contact"] = examples["action"]
    np.testing.assert_allclose(perception_share.true_state_predictions(examples)["motion"],
                               baselines.predictions("physics", examples)["motion"])
    examples["action_from_contact"] = 0.5 * examples["action"]  # contact halfway through the window
    assert not np.allclose(perception_share.true_state_predictions(examples)["motion"],
                           baselines.predictions("physics", examples)["motion"])


def test_the_binary_pairs_each_hybrid_with_the_true_state(smoke_results, smoke_data, tmp_path):
    workdir = smoke_results("data_efficiency_full")
    run_binary("perception_share", f"--data_dir={smoke_data('data_efficiency')}", f"--workdir={tmp_path}",
               f"--runs=smoke:{workdir}", "--train_size=80", "--scale=smoke")
    results = json.loads((tmp_path / "results.json").read_text())
    rows = {row["model"]: row for row in results["rows"]}
    assert set(rows) == {"physics", "hybrid_true_state", "hybrid"} and rows["hybrid"]["seeds"] == 1
    share = rows["hybrid"]["perception_share"]["score"]
    assert share["value"] == pytest.approx(rows["hybrid"]["score"]["value"] - rows["hybrid_true_state"]["score"]["value"],
                                           abs=1e-3)
    assert share["se"] > 0 and {"contact_mm", "normal_deg", "s"} <= set(rows["hybrid"]["state_errors"])
    assert "| smoke | hybrid | 1 |" in (tmp_path / "results.md").read_text()
    with pytest.raises(app.UsageError, match="--runs: expected label:workdir"):
        run_binary("perception_share", f"--workdir={tmp_path}", "--runs=nolabel")
