"""Prediction over time (`pushjax.paper.rollouts`): whole pushes on the models' clock, the pose recovered from a
perceived contact, the analytical rollouts, the per-horizon rows and verdicts, and ``experiments.rollouts`` at
smoke scale (its hybrid model is the velocities smoke run's, resumed, not trained again)."""

import json
import math
import shutil

import numpy as np
import pytest

from pushjax import planar
from pushjax.geometry import annotate, get_object, limit_surface_ratio
from pushjax.mit import protocol
from pushjax.mit.files import PushParams
from pushjax.paper import findings, rollouts, spec as spec_lib
from tests.conftest import once_across_workers

from .conftest import SMOKE, run_binary

SPLITS = ("test_20", "test_100")


def _straight_push(obj: str, pose, steps: int, side: int = 0, angle: float = 0.3, velocity_mm_s: float = 20.0):
    """A `PushSequence` of a straight MIT push of `obj` at `pose`, the true poses all the start pose."""
    params = PushParams("abs", obj, 0.0, velocity_mm_s, side, 0.4, angle)
    start, direction = protocol.pusher_line(obj, params)
    distance = np.minimum(np.arange(steps + 1) * rollouts.STEP_S * velocity_mm_s / 1000.0,
                          protocol.PUSH_DISTANCE + protocol.APPROACH_DISTANCE)
    local = start + distance[:, None] * direction
    pusher = planar.rotate(local, pose[2]) + np.asarray(pose[:2])
    return rollouts.PushSequence(sequence_id=0, obj=obj, surface="abs", l=float(limit_surface_ratio(get_object(obj))),
                                 mu=0.25, poses=np.tile(pose, (steps + 1, 1)), pusher=pusher)


@pytest.mark.parametrize("obj", ["tri1", "rect1", "ellip2"])
def test_pose_from_contact_gives_the_true_pose_s_motion(obj):
    pose = np.array([0.01, -0.02, 0.7])
    sequence = _straight_push(obj, pose, steps=6)
    contact = annotate(obj, pose, sequence.pusher[0], sequence.pusher[1] - sequence.pusher[0])
    com = planar.centre_of_mass(get_object(obj).centroid, pose)
    recovered = rollouts.pose_from_contact(obj, com, contact.contact_rel_com, contact.normal)
    np.testing.assert_allclose(planar.centre_of_mass(get_object(obj).centroid, recovered), com, atol=1e-9)
    # Symmetric objects may come back turned by a symmetry, which moves the same way.
    true_com = planar.centre_of_mass(get_object(obj).centroid, rollouts.physics_chained(sequence))
    recovered_com = planar.centre_of_mass(get_object(obj).centroid, rollouts.physics_chained(sequence, recovered))
    assert np.linalg.norm(true_com[-1] - true_com[0]) > 0.01
    np.testing.assert_allclose(recovered_com, true_com, atol=2e-4)


def test_padding_and_one_long_step():
    sequence = _straight_push("rect1", np.array([0.0, 0.0, 0.3]), steps=6)
    chained = rollouts.physics_chained(sequence)
    np.testing.assert_allclose(rollouts.physics_chained(sequence, steps=9), chained, atol=1e-6)
    long = rollouts.physics_long(sequence, steps=9)
    assert long.shape == chained.shape == (7, 3)
    np.testing.assert_allclose(long[:2], chained[:2], atol=1e-6)  # one step is one step
    assert not np.allclose(long[-1], chained[-1], atol=1e-4)  # the object turns: one long step cannot follow


def _truth(sequence):
    return rollouts._com_and_yaw(sequence, sequence.poses)


def _pushes(count: int):
    """Straight pushes whose true poses are the chained rollout's (so physics_chained is exact)."""
    sequences = []
    for index in range(count):
        sequence = _straight_push("rect1", np.array([0.0, 0.0, 0.2 * index]), 6, side=index % 4,
                                  angle=0.1 * index)
        sequences.append(rollouts.PushSequence(index, "rect1", "abs", sequence.l, sequence.mu,
                                               rollouts.physics_chained(sequence), sequence.pusher))
    return sequences


def test_horizon_rows_and_verdicts():
    sequences = _pushes(6)
    truths = [_truth(s) for s in sequences]
    rows = rollouts.horizon_rows("physics_chained", "test_20", sequences, truths, None)
    rows += rollouts.horizon_rows("physics_long", "test_20", sequences,
                                  [rollouts._com_and_yaw(s, rollouts.physics_long(s)) for s in sequences], None)
    rows += rollouts.horizon_rows("zero", "test_20", sequences, [np.broadcast_to(t[0], t.shape) for t in truths], None)
    assert [row["horizon"] for row in rows[:4]] == ["0.5 s", "1 s", "2 s", rollouts.WHOLE]  # no 4 s in 3 s pushes
    exact = {row["horizon"]: row for row in rows if row["model"] == "physics_chained"}
    assert exact[rollouts.WHOLE]["trans_mm"] == 0.0 and exact[rollouts.WHOLE]["trans_percent"] == 0.0
    zero = {row["horizon"]: row for row in rows if row["model"] == "zero"}
    assert zero[rollouts.WHOLE]["trans_percent"] == 100.0 and zero[rollouts.WHOLE]["trans_mm"] > 10
    assert zero["0.5 s"]["trans_mm"] < zero["1 s"]["trans_mm"] < zero[rollouts.WHOLE]["trans_mm"]
    verdicts = {entry["key"]: entry["verdict"] for entry in rollouts.decide({"horizon_rows": rows})}
    assert verdicts == {"chaining": findings.HOLDS, "hybrid_over_neural_grows": findings.UNCHECKED,
                        "hybrid_beats_neural_whole": findings.UNCHECKED}
    swapped = [{**row, "model": {"physics_long": "physics_chained", "physics_chained": "physics_long"}.get(
        row["model"], row["model"])} for row in rows]
    assert rollouts.decide({"horizon_rows": swapped})[0]["verdict"] == findings.FAILS


def test_setup_takes_a_subset_of_the_test_velocities():
    assert rollouts.setup(SPLITS).test_splits == SPLITS
    assert rollouts.setup(()) == spec_lib.SETUPS["rollouts"]
    for bad in (("test_7",), ("test_20", "test_20")):
        with pytest.raises(ValueError, match="test_splits"):
            rollouts.setup(bad)
    with pytest.raises(ValueError, match="variants: simple"):
        rollouts.check_models(spec_lib.make_spec(spec_lib.SETUPS["rollouts"], "smoke", models=["simple", "zero"]))


@pytest.fixture(scope="session")
def rollouts_run(smoke_results, smoke_data, shared_folder):
    """The smoke run of ``experiments.rollouts`` on two test velocities, with hybrid, neural and the baselines."""
    velocities = smoke_results("velocities")
    workdir = shared_folder / "results" / "rollouts"

    def make():
        # The velocities run's hybrid on train_20 has the same dataset, config and seed: the runner resumes it.
        shutil.copytree(velocities / "train_20" / "l1" / "hybrid", workdir / "train_20" / "l1" / "hybrid")
        run_binary("rollouts", *SMOKE, f"--data_dir={smoke_data('velocities')}", f"--workdir={workdir}",
                   "--variants=hybrid,neural,zero,physics", f"--test_splits={','.join(SPLITS)}")

    return once_across_workers(workdir, make)


def test_load_sequences_puts_whole_pushes_on_the_step_clock(smoke_data):
    spec = spec_lib.make_spec(rollouts.setup(SPLITS), "smoke", data_dir=smoke_data("velocities"), build=False)
    sequences = rollouts.load_sequences(spec)
    assert set(sequences) == set(SPLITS)
    for split, velocity in (("test_20", 20.0), ("test_100", 100.0)):
        duration = (protocol.PUSH_DISTANCE + protocol.APPROACH_DISTANCE) / (velocity / 1000.0)
        for sequence in sequences[split]:
            assert sequence.steps == math.ceil(duration / rollouts.STEP_S)
            np.testing.assert_allclose(_truth(sequence)[0, :2], 0.0, atol=1e-12)
            travelled = np.linalg.norm(sequence.pusher[-1] - sequence.pusher[0])
            assert travelled == pytest.approx(protocol.PUSH_DISTANCE + protocol.APPROACH_DISTANCE, abs=2e-3)
    assert sequences["test_20"][0].horizon_step("2 s") == 4 and sequences["test_20"][0].horizon_step("4 s") is None
    assert sequences["test_100"][0].horizon_step(rollouts.WHOLE) == 2


def test_binary_writes_rows_tables_figure_and_verdicts(rollouts_run):
    results = json.loads((rollouts_run / "results.json").read_text())
    rows = results["horizon_rows"]
    assert {row["model"] for row in rows} == {"zero", "physics_long", "physics_chained", "hybrid", "neural"}
    assert {row["test_split"] for row in rows} == set(SPLITS)
    assert {row["model"] for row in results["rows"]} == {"hybrid", "neural", "zero", "physics"}  # one-step rows
    whole = {row["model"]: row for row in rows if row["test_split"] == "test_20" and row["horizon"] == rollouts.WHOLE}
    assert whole["physics_chained"]["trans_mm"] < whole["zero"]["trans_mm"]
    assert all(math.isfinite(row["trans_mm_se"]) for row in rows)
    assert [entry["key"] for entry in results["expectations"]] == [e.key for e in rollouts.EXPECTATIONS]
    assert all(entry["verdict"] != findings.UNCHECKED for entry in results["expectations"])
    table = (rollouts_run / "results.md").read_text()
    assert "| physics_chained |" in table and "| neural |" in table and "test_100: translation error, mm" in table
    assert (rollouts_run / rollouts.FIGURE).read_bytes()[:4] == b"\x89PNG"
