"""``python -m experiments.track --scale=smoke``: simulated testbed pushes tracked end to end, with a trained hybrid
model's perception (the committed ``results/track_perception/model``) as a second observation stream."""

import dataclasses
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pushjax.studies import tracking
from pushjax.sim.testbed import REALISTIC

REPOSITORY = Path(__file__).resolve().parents[2]
PERCEPTION_MODEL = REPOSITORY / "results" / "track_perception" / "model"
"""A trained hybrid (``experiments.data_efficiency_full``'s hybrid_5000_seed0, cpu_full data), committed beside the
perception run's results; a real trained network, read only."""


def test_smoke_run_writes_the_tables_and_the_figure(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "experiments.track", "--scale=smoke", f"--workdir={tmp_path}",
         "--testbed_overrides=drop_rate=0.2", f"--perception={PERCEPTION_MODEL}", "--perception_scale=cpu_full"],
        cwd=REPOSITORY, env={**os.environ, "MUJOCO_GL": "egl"}, capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stderr[-3000:]
    assert f"wrote {tmp_path / 'results.json'}" in result.stdout
    results = json.loads((tmp_path / "results.json").read_text())
    assert (tmp_path / "mu_over_time.png").stat().st_size > 1000
    assert "| ekf |" in (tmp_path / "results.md").read_text()
    summary = results["summary"]
    assert set(summary) == {*tracking.FILTERS, *tracking.PERCEPTION_FILTERS, "constant_velocity", "raw", "perception"}
    for name, entry in summary.items():
        assert all(math.isfinite(value) for value in entry.values()), (name, entry)
        assert 0.0 < entry["position_rmse_mm"] < 5.0
    # The perception: readings at 2.5 Hz of the 5 Hz clock (every other step), its noise from seed + 1's pushes.
    info = results["perception"]
    assert info["every_steps"] == 2 and info["rate_hz"] == 2.5 and "hybrid" in info["model"]
    assert info["noise_readings"] > 10 and all(0.0 < std < 0.01 for std in info["std"])
    assert summary["perception"]["readings"] == sum(push["steps"] // 2 + 1 for push in results["pushes"])
    # The scenes are rendered as the model's training data were (camera, image size, pose convention): the trained
    # network locates the centre of mass to about a millimetre (a wrong camera or pose puts it centimetres off).
    assert summary["perception"]["position_rmse_mm"] < 2.0
    # Perception alone after the first motion-capture sample is not the process model alone: the readings are used.
    alone, open_loop = summary["ekf_perception_only"], summary["ekf_prediction_only"]
    assert alone["position_rmse_mm"] != open_loop["position_rmse_mm"] and alone["position_rmse_mm"] < 2.0
    assert "| ekf_perception |" in (tmp_path / "results.md").read_text()
    # The raw measurements are the testbed's motion capture: their RMSE is its noise.
    assert 0.5 < summary["raw"]["position_rmse_mm"] / (1e3 * math.sqrt(2) * REALISTIC.tracking_noise_xy) < 1.5
    # ekf_learned: the noise learned on other pushes (seed + 1) in the scale's steps, reported beside the hand-set.
    assert "| ekf_learned |" in (tmp_path / "results.md").read_text()
    assert results["training_seed"] == results["seed"] + tracking.TRAINING_SEED_OFFSET
    learning = results["noise_learning"]
    assert learning["steps"] == tracking.SCALES["smoke"].learn_steps and results["scale"] == "smoke"
    curve = learning["loss_curve"]
    assert len(curve) == learning["steps"] + 1 and curve[-1] < curve[0]
    hand_set, learned = results["noise"]["hand_set"], results["noise"]["learned"]
    for key, size in (("process_std", 5), ("measurement_std", 3)):
        assert len(hand_set[key]) == len(learned[key]) == size and hand_set[key] != learned[key]
        assert all(value > 0 for value in learned[key])
    np.testing.assert_allclose(hand_set["measurement_std"], results["measurement_std"])
    pushes = results["pushes"]
    assert len(pushes) == tracking.SCALES["smoke"].pushes
    assert sum(push["dropped"] for push in pushes) > 0  # 20 % of the samples dropped: skipped, not zeros
    for push in pushes:
        for name in (*tracking.FILTERS, *tracking.PERCEPTION_FILTERS):
            mu = np.asarray(push["filters"][name]["mu"])
            assert len(mu) == push["steps"] + 1 and np.all(np.isfinite(mu)) and np.all(mu > 0)


def test_simulated_pushes_keep_their_truth_and_their_gaps():
    pushes = tracking.simulate_pushes(["tri2"], 1, seed=3, testbed=REALISTIC.with_overrides("drop_rate=0.5"),
                                      rate_hz=25.0)
    push = pushes[0]
    dropped = np.isnan(push.measurements[:, 0])
    assert 0.2 < dropped.mean() < 0.8 and not dropped[0]
    error = push.measurements[~dropped, :2] - push.truth[~dropped, :2]
    assert np.abs(error).max() < 6 * REALISTIC.tracking_noise_xy
    assert push.mu_true != push.mu_nominal > 0
    assert len(push.pusher) == len(push.truth) > 50  # 25 Hz over a push of a few seconds


@pytest.mark.parametrize("field, value", [
    ("objects", ()), ("objects", ("box",)), ("objects", ("rect1", "rect1")), ("pushes", 0), ("particles", 0),
    ("particles", 2.0), ("rate_hz", 0.0), ("rate_hz", 7.0), ("rate_hz", math.nan), ("rate_hz", 500.0),
    ("learn_steps", 0), ("learn_steps", -3), ("filters", ()), ("filters", ("kalman",)), ("filters", ("ekf", "ekf")),
    ("seed", -1), ("seed", 1.5)])
def test_a_bad_field_is_a_value_error_naming_it(field, value):
    with pytest.raises(ValueError, match=rf"^{re.escape(field)}: "):
        tracking.TrackingConfig.from_scale("smoke", **{field: value})


def test_scales_are_configs_with_their_overrides():
    smoke = tracking.TrackingConfig.from_scale("smoke")
    assert smoke == dataclasses.replace(tracking.SCALES["smoke"], scale="smoke")
    assert (smoke.objects, smoke.pushes, smoke.particles, smoke.rate_hz, smoke.learn_steps) == (
        ("rect1",), 2, 64, 5.0, 3)
    assert smoke.filters == tracking.FILTERS and smoke.seed == 0 and smoke.testbed == REALISTIC
    changed = tracking.TrackingConfig.from_scale("cpu", filters=["ekf"], rate_hz=None, seed=3)
    assert changed.filters == ("ekf",) and changed.rate_hz == tracking.SCALES["cpu"].rate_hz and changed.seed == 3
    assert (changed.learns, changed.training_seed) == (False, 3 + tracking.TRAINING_SEED_OFFSET)
    assert changed.measurement_std == (REALISTIC.tracking_noise_xy, REALISTIC.tracking_noise_xy,
                                       REALISTIC.tracking_noise_yaw)
    with pytest.raises(ValueError, match="^scale: "):
        tracking.TrackingConfig.from_scale("huge")
    # The perception's rate must divide the filter rate, checked only with a perception (a stand-in sensor here).
    assert tracking.TrackingConfig.from_scale("smoke", perception_hz=3.0).perception_hz == 3.0
    with pytest.raises(ValueError, match="^perception_hz: expected the filter rate 5 Hz divided by a whole number"):
        tracking.TrackingConfig.from_scale("smoke", perception_hz=3.0, perception=object())
    assert tracking.TrackingConfig.from_scale("smoke", perception_hz=2.5, perception=object()).perception_hz == 2.5


def _record(seed: int, ekf_errors, raw_errors) -> dict:
    pushes = [{"errors": {"ekf": {"position_rmse_mm": e}, "raw": {"position_rmse_mm": r}}}
              for e, r in zip(ekf_errors, raw_errors)]
    return {"seed": seed, "pushes": pushes,
            "summary": {"ekf": {"position_rmse_mm": float(np.mean(ekf_errors))},
                        "raw": {"position_rmse_mm": float(np.mean(raw_errors))}}}


def test_compare_over_seeds_decides_on_the_untuned_seeds_by_push():
    # The tuning seed's pushes favour the EKF by far; the untuned seeds' do not decide: the verdict ignores seed 0.
    tuned = _record(tracking.TUNING_SEED, [0.1] * 10, [0.3] * 10)
    untuned = [_record(seed, [0.20, 0.30, 0.25, 0.28], [0.25, 0.26, 0.27, 0.26]) for seed in (1, 2)]
    comparison = tracking.compare_over_seeds([tuned, *untuned])
    (row,) = comparison["comparisons"]
    assert (row["better"], row["worse"], row["pushes"]) == ("ekf", "raw", 8)
    assert math.isclose(row["difference_mm"], np.mean([-0.05, 0.04, -0.02, 0.02]))
    assert row["verdict"] == "not decided"
    assert comparison["untuned_seeds"] == [1, 2] and set(comparison["per_seed"]) == {"0", "1", "2"}
    clear = [_record(seed, [0.20, 0.21, 0.19, 0.20], [0.30, 0.29, 0.31, 0.30]) for seed in (1, 2)]
    assert tracking.compare_over_seeds([tuned, *clear])["comparisons"][0]["verdict"] == "holds"
    assert "0 (tuning seed)" in tracking.seeds_table(comparison)


def test_seeds_flag_runs_each_seed_and_compares_them(tmp_path):
    arguments = [sys.executable, "-m", "experiments.track", "--scale=smoke", f"--workdir={tmp_path}",
                 "--filters=ekf", "--seeds=0,1"]
    result = subprocess.run(arguments, cwd=REPOSITORY, env={**os.environ, "MUJOCO_GL": "egl"}, capture_output=True,
                            text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stderr[-3000:]
    combined = json.loads((tmp_path / "results.json").read_text())
    assert combined["untuned_seeds"] == [1] and combined["seeds"] == [0, 1]
    assert {row["better"] for row in combined["comparisons"]} == {"ekf"}
    seed1 = json.loads((tmp_path / "seed1" / "results.json").read_text())
    assert seed1["seed"] == 1 and len(seed1["pushes"]) == combined["comparisons"][0]["pushes"]
    again = subprocess.run(arguments, cwd=REPOSITORY, env={**os.environ, "MUJOCO_GL": "egl"}, capture_output=True,
                           text=True, timeout=600, check=False)
    assert again.returncode == 0 and "seed 1: read" in again.stdout
    assert json.loads((tmp_path / "results.json").read_text()) == combined
