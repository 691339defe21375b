"""The physics baseline's error decomposed (`pushjax.paper.residual`), on the suite's smoke data."""

import dataclasses
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from absl import app, flags

from pushjax.data import configs
from pushjax.sim import dataset as sim_dataset
from pushjax.sim.testbed import IDEAL, REALISTIC
from pushjax.paper import residual
from tests.paper.conftest import run_binary

REPOSITORY = Path(__file__).resolve().parents[2]
QUIET = REALISTIC.with_overrides("tracking_noise_xy=0;tracking_noise_yaw=0;timestamp_jitter=0;drop_rate=0")
"""The realistic profile without its motion capture."""


@pytest.fixture(scope="module")
def smoke_jobs(smoke_data):
    """(the smoke data directory, its test split's recording jobs)."""
    data_dir = smoke_data("data_efficiency")
    builder = residual.dataset_builder(data_dir, "smoke")
    plan = configs.plan_splits(builder.dataset_config, builder.raw_dir)
    return data_dir, [plan.jobs[i] for i in plan.splits["test"]]


def _recorded(job, folder: Path, testbed):
    """``job`` recorded again under ``testbed`` into ``folder``."""
    moved = dataclasses.replace(job, path=folder / job.path.name, testbed=testbed)
    sim_dataset.record_push(moved)
    return moved


def test_the_truth_is_the_files_push_without_its_motion_capture(smoke_jobs, tmp_path):
    _, jobs = smoke_jobs
    job = jobs[0]
    quiet = _recorded(job, tmp_path, QUIET)
    # Switching the motion capture off changes no other draw: the same simulation, the same pusher friction.
    assert np.array_equal(sim_dataset.simulate_job(quiet).true_object_pose,
                          sim_dataset.simulate_job(job).true_object_pose)
    assert sim_dataset.job_conditions(quiet).pusher_friction == sim_dataset.job_conditions(job).pusher_friction
    truth, quiet_truth = residual.sequence_truth(job, 0), residual.sequence_truth(quiet, 0)
    # Without motion capture the noise-free poses are the recorded ones.
    np.testing.assert_allclose(quiet_truth.clean, quiet_truth.noisy, rtol=0, atol=1e-12)
    # With it, they differ by the tracking noise (0.2 mm per axis), centred, and agree with the quiet push's truth
    # up to the clock's jittered start (< 1 ms at 20 mm/s).
    noise = (truth.noisy - truth.clean)[:, :2]
    assert 1e-4 < noise.std() < 3e-4 and np.abs(noise.mean(axis=0)).max() < 5e-5
    assert np.abs(truth.clean - quiet_truth.clean)[:, :2].max() < 2e-5
    assert truth.mu_factor == quiet_truth.mu_factor != 1.0
    # The drawn load is uneven and moves with the plate over the table; the plate's own is fixed.
    assert not np.allclose(truth.drawn_weights[0], truth.areas)
    assert not np.allclose(truth.drawn_weights[0], truth.drawn_weights[-1])
    assert truth.measured_weights.shape == truth.drawn_weights.shape and np.all(truth.measured_weights >= 0)


def test_the_ideal_testbed_draws_nothing(smoke_jobs, tmp_path):
    _, jobs = smoke_jobs
    truth = residual.sequence_truth(_recorded(jobs[1], tmp_path, IDEAL), 0)
    np.testing.assert_allclose(truth.clean, truth.noisy, rtol=0, atol=1e-12)
    assert truth.mu_factor == 1.0
    for weights in (truth.object_weights[None], truth.drawn_weights):
        l_factor, offset = residual._load_parameters(weights, truth.support_points, truth.areas)
        np.testing.assert_allclose(l_factor, 1.0, rtol=1e-12)
        np.testing.assert_allclose(offset, 0.0, atol=1e-15)


def test_a_file_the_simulation_does_not_reproduce_is_refused(smoke_jobs, tmp_path):
    _, jobs = smoke_jobs
    job = _recorded(jobs[0], tmp_path, REALISTIC)
    with h5py.File(job.path, "r+") as file:
        file["object_pose"][5, 1] += 1e-6
    with pytest.raises(residual.ReproductionError, match="differs from the file in object_pose"):
        residual.sequence_truth(job, 0)


def test_the_binary_decomposes_the_smoke_test_split(smoke_jobs, tmp_path):
    data_dir, jobs = smoke_jobs
    run_binary("residual_decomposition", f"--data_dir={data_dir}", "--scale=smoke", f"--workdir={tmp_path}")
    results = json.loads((tmp_path / "results.json").read_text())
    rows = {row["component"]: row for row in results["rows"]}
    assert [row["component"] for row in results["rows"]] == [name for name, *_ in (*residual.CHAIN,
                                                                                   *residual.REFERENCES)]
    assert results["sequences"] == results["split_sequences"] == len(jobs) and results["stride"] == 1
    checks = results["checks"]
    assert checks["resimulated_identical"] == len(jobs)
    # The stored windows are found again: the labels cut again from the files are the stored ones.
    assert checks["noisy_motion_max_difference_m"] < 1e-6 and checks["noisy_yaw_max_difference_rad"] < 1e-5
    assert checks["exact_not_converged"] == 0
    for metric in ("trans_percent", "rot_percent"):
        assert rows["physics"][metric] == pytest.approx(checks["table1_physics"][metric], rel=1e-5)
        assert rows["zero"][metric] == pytest.approx(100.0)
        assert 90.0 < rows["zero_clean_labels"][metric] < 110.0
        for row in results["rows"]:
            assert math.isfinite(row[metric]) and math.isfinite(row[f"{metric}_se"])
        assert rows["physics"][f"{metric}_se"] > 0
        for previous, (name, *_) in zip(residual.CHAIN, residual.CHAIN[1:]):
            change = rows[name]["difference"]
            assert change["from"] == previous[0] and math.isfinite(change[f"{metric}_se"])
            assert change[metric] == pytest.approx(rows[name][metric] - rows[previous[0]][metric], abs=1e-4)
        # The physics predictions are the same against both labels; the label noise alone is most of the step.
        assert rows["clean_labels"]["sequences"]["id"] == rows["physics"]["sequences"]["id"]
        assert 0.0 < rows["truth"][metric] < rows["physics"][metric]
        # A noise-free model told the hidden draws' effect scores, against the noisy labels, at least the noise.
        assert rows["state_floor"][metric] >= rows["truth"][metric] * 0.9
    # The label noise is of the motion capture's size: 0.2 mm per axis at both ends of the window.
    assert 0.1 < rows["truth"]["trans_mm"] < 0.5
    assert results["parts"]["tracking"]["trans_percent"] == pytest.approx(
        rows["physics"]["trans_percent"] - rows["clean_state"]["trans_percent"], abs=1e-4)
    text = (tmp_path / "results.md").read_text()
    assert "## What it bounds" in text and "| (a) | `physics` |" in text


def test_bad_flags_are_usage_errors(smoke_jobs, tmp_path):
    data_dir, _ = smoke_jobs
    with pytest.raises(flags.IllegalFlagValueError, match="scale"):
        run_binary("residual_decomposition", f"--data_dir={data_dir}", "--scale=huge")
    with pytest.raises(app.UsageError, match="--data_dir: dataset push_effects/data_efficiency_smoke is not built"):
        run_binary("residual_decomposition", f"--data_dir={tmp_path}", "--scale=smoke", f"--workdir={tmp_path}/out")
    # From the command line: one line naming the flag, no traceback.
    process = subprocess.run([sys.executable, "-m", "experiments.residual_decomposition", f"--data_dir={data_dir}",
                              "--max_sequences=0"], cwd=REPOSITORY, capture_output=True, text=True, timeout=120,
                             env={**os.environ, "JAX_PLATFORMS": "cpu"})
    assert process.returncode != 0 and "Traceback" not in process.stderr
    assert "--max_sequences" in process.stderr.strip().splitlines()[-1]
