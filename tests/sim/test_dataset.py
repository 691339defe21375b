"""Tests for pushjax.sim.dataset and experiments/record_pushes: determinism, resuming, attributes, the CLI."""

import dataclasses
import json
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from pushjax.mit.files import load_push, parse_push_file_name, read_raw_push, write_push
from pushjax.sim import dataset
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import IDEAL, REALISTIC
from pushjax.sim.testbed import Testbed as Profile

REPO = Path(__file__).resolve().parents[2]


def ideal(**fields) -> dataset.RecordingConfig:
    """Recording settings on the ideal testbed: the files recorded before testbeds existed, and fast."""
    return dataset.RecordingConfig(**{"testbed": IDEAL, **fields})


def files(root: Path) -> dict[str, bytes]:
    return {path.relative_to(root).as_posix(): path.read_bytes() for path in sorted(root.rglob("*.h5"))}


def test_same_seed_same_bytes_for_any_worker_count(tmp_path):
    arguments = dict(objects=["rect1", "tri1"], surfaces=["abs"], pushes=3, progress=False)
    settings = ideal(seed=5, velocities=(20.0, 50.0), effects=Effects(tracking_noise=(5e-4, 0.005)))
    serial = dataset.record_pushes(tmp_path / "serial", settings=settings, workers=1, **arguments)
    parallel = dataset.record_pushes(tmp_path / "parallel", settings=settings, workers=2, **arguments)
    assert len(serial.written) == len(parallel.written) == 6
    assert files(tmp_path / "serial") == files(tmp_path / "parallel")
    other_seed = dataset.record_pushes(tmp_path / "other", settings=dataclasses.replace(settings, seed=6), workers=1,
                                       **arguments)
    assert files(tmp_path / "other") != files(tmp_path / "serial")
    assert len(other_seed.written) == 6


def test_existing_files_are_skipped(tmp_path):
    arguments = dict(objects=["hex"], surfaces=["delrin"], pushes=4, settings=ideal(seed=1, velocities=(50.0,)),
                     workers=1, progress=False)
    first = dataset.record_pushes(tmp_path, **arguments)
    assert len(first.written) == 4 and not first.skipped
    before = files(tmp_path)
    again = dataset.record_pushes(tmp_path, **arguments)
    assert not again.written and sorted(again.skipped) == sorted(first.written)
    first.written[2].unlink()
    resumed = dataset.record_pushes(tmp_path, **arguments)
    assert resumed.written == [first.written[2]] and len(resumed.skipped) == 3
    assert files(tmp_path) == before


def test_invalid_existing_files_are_rerecorded(tmp_path):
    arguments = dict(objects=["rect1"], surfaces=["abs"], pushes=3, settings=ideal(seed=2, velocities=(20.0,)),
                     workers=1, progress=False)
    first = dataset.record_pushes(tmp_path, **arguments)
    before = files(tmp_path)
    truncated, overwritten, intact = first.written
    truncated.write_bytes(truncated.read_bytes()[:2000])
    overwritten.write_bytes(b"not an HDF5 file")
    again = dataset.record_pushes(tmp_path, **arguments)
    assert sorted(again.rerecorded) == sorted(again.written) == sorted([truncated, overwritten])
    assert again.skipped == [intact]
    assert files(tmp_path) == before


def test_files_with_a_flung_object_are_rerecorded(tmp_path):
    """A file recorded before the plausibility check, whose object jumps 3 cm, is recorded again."""
    arguments = dict(objects=["rect1"], surfaces=["abs"], pushes=2, settings=ideal(seed=2, velocities=(20.0,)),
                     workers=1, progress=False)
    first = dataset.record_pushes(tmp_path, **arguments)
    before = files(tmp_path)
    flung, intact = first.written
    raw = read_raw_push(flung)
    object_pose = np.array(raw.object_pose)
    object_pose[len(object_pose) // 2:, 1] += 0.03
    write_push(flung, raw.params, raw.tip_pose, object_pose, raw.ft_wrench, attributes=raw.attributes)
    job = next(job for job in dataset.plan_pushes(tmp_path, ["rect1"], ["abs"], 2, arguments["settings"]) if job.path == flung)
    assert "behind a pusher at 20 mm/s" in dataset.recorded_file_problem(job)
    again = dataset.record_pushes(tmp_path, **arguments)
    assert again.rerecorded == [flung] and again.skipped == [intact]
    assert files(tmp_path) == before


SELECTION = dict(objects=["rect1"], surfaces=["abs"], pushes=1)
RECORDED = ideal(seed=4, velocities=(20.0,), accelerations=(0.0,), repeats=1, effects=Effects(table_tilt_deg=1.0),
                 declare_effects=True, support="grid")


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A folder recorded with `RECORDED`."""
    out_dir = tmp_path_factory.mktemp("recorded")
    dataset.record_pushes(out_dir, **SELECTION, settings=RECORDED, workers=1, progress=False)
    return out_dir


def test_manifest_records_the_settings(recorded):
    settings = json.loads((recorded / dataset.MANIFEST_NAME).read_text())["settings"]
    assert settings["seed"] == 4 and settings["velocities"] == [20.0] and settings["support"] == "grid"
    assert Effects.from_json(json.dumps(settings["effects"])) == RECORDED.effects
    assert settings == RECORDED.to_dict()


@pytest.mark.parametrize("change", [
    dict(seed=5), dict(effects=Effects(table_tilt_deg=2.0)), dict(declare_effects=False), dict(support="hull"),
    dict(velocities=(50.0,)), dict(velocities=(20.0, 50.0)), dict(accelerations=(0.0, 100.0)), dict(repeats=2),
    dict(testbed=REALISTIC),
])
def test_resume_with_other_settings_is_refused_naming_them(recorded, change):
    before = files(recorded)
    with pytest.raises(dataset.OutDirConflictError) as raised:
        dataset.record_pushes(recorded, **SELECTION, settings=dataclasses.replace(RECORDED, **change), workers=1,
                              progress=False)
    message = str(raised.value)
    assert "\n" not in message and str(recorded) in message and dataset.MANIFEST_NAME in message
    assert all(f" {setting} " in message for setting in change), message
    assert files(recorded) == before


def test_more_pushes_objects_and_surfaces_with_the_same_settings_add_to_the_folder(tmp_path):
    more = dict(pushes=2, objects=["rect1", "tri1"], surfaces=["abs", "pu"], settings=RECORDED)
    together = dataset.record_pushes(tmp_path / "together", **more, workers=1, progress=False)
    dataset.record_pushes(tmp_path / "added", **SELECTION, settings=RECORDED, workers=1, progress=False)
    added = dataset.record_pushes(tmp_path / "added", **more, workers=1, progress=False)
    assert len(together.written) == 8 and len(added.written) == 7 and len(added.skipped) == 1
    assert files(tmp_path / "added") == files(tmp_path / "together")


def test_a_folder_not_made_by_record_pushes_is_refused(tmp_path):
    foreign = write_push(tmp_path / "abs" / "rect1" / "real.h5", None, *[
        np.column_stack([np.arange(3) / 250.0, np.zeros((3, 3))])] * 3)
    content = foreign.read_bytes()
    with pytest.raises(dataset.OutDirConflictError, match=rf"1 \.h5 file.*no {dataset.MANIFEST_NAME}"):
        dataset.record_pushes(tmp_path, ["rect1"], ["abs"], pushes=1, settings=ideal(), workers=1, progress=False)
    assert [path.name for path in tmp_path.rglob("*") if path.is_file()] == ["real.h5"]
    assert foreign.read_bytes() == content


def test_files_follow_the_mit_layout_and_declare_effects(tmp_path):
    effects = Effects(table_tilt_deg=1.0, tracking_bias=(0.001, 0.0, 0.0))
    summary = dataset.record_pushes(tmp_path, ["ellip2"], ["plywood"], pushes=2,
                                    settings=ideal(seed=3, velocities=(20.0,), effects=effects), workers=1,
                                    progress=False)
    for path in summary.written:
        assert path.parent == tmp_path / "plywood" / "ellip2"
        params = parse_push_file_name(path)
        assert params.shape == "ellip2" and params.surface == "plywood" and params.velocity == 20.0
        raw = read_raw_push(path)
        assert Effects.from_json(raw.attributes["pushjax_effects"]) == effects
        assert raw.attributes["pushjax_seed"] == 3 and raw.attributes["pushjax_support"] == "grid"
        assert raw.declared_effects == effects.to_dict()
        push = load_push(path)
        assert push.time[1] == pytest.approx(0.004)
        assert np.linalg.norm(push.object[-1, :2] - push.object[0, :2]) > 0.005  # the MIT grid pushes hit


def test_undeclared_files_hold_only_the_three_datasets(tmp_path):
    settings = ideal(seed=0, velocities=(50.0,), effects=Effects(com_offset=(0.01, 0.0)), declare_effects=False)
    summary = dataset.record_pushes(tmp_path, ["rect3"], ["pu"], pushes=1, settings=settings, workers=1,
                                    progress=False)
    with h5py.File(summary.written[0], "r") as file:
        assert sorted(file.keys()) == ["ft_wrench", "object_pose", "tip_pose"]
        assert len(file.attrs) == 0
        for name in file:
            assert len(file[name].attrs) == 0


def test_repeats_write_rep_files_of_one_push(tmp_path):
    settings = ideal(seed=2, velocities=(50.0,), repeats=3, effects=Effects(tracking_noise=(1e-3, 0.0)))
    summary = dataset.record_pushes(tmp_path, ["tri3"], ["abs"], pushes=2, settings=settings, workers=1,
                                    progress=False)
    params = [parse_push_file_name(path) for path in summary.written]
    assert sorted(p.repetition for p in params) == [0, 0, 1, 1, 2, 2]
    assert len({(p.side, p.point, p.angle) for p in params}) == 2
    first = [path for path, p in zip(summary.written, params) if (p.side, p.point, p.angle) == (
        params[0].side, params[0].point, params[0].angle)]
    poses = [read_raw_push(path).object_pose for path in first]
    tips = [read_raw_push(path).tip_pose for path in first]
    np.testing.assert_array_equal(tips[0], tips[1])
    assert not np.array_equal(poses[0], poses[1])  # independent tracking noise per repetition


def test_plan_draws_distinct_pushes_and_checks_arguments(tmp_path):
    jobs = dataset.plan_pushes(tmp_path, ["rect1"], ["abs"], pushes=300, settings=ideal(velocities=(20.0,)))
    assert len({job.path for job in jobs}) == 300
    with pytest.raises(ValueError, match="pushes"):
        dataset.plan_pushes(tmp_path, ["rect1"], ["abs"], pushes=4 * 11 * 9 + 1, settings=ideal(velocities=(20.0,)))
    for arguments, message in [
        (dict(objects=["cube"]), "objects"), (dict(surfaces=["ice"]), "surfaces"), (dict(pushes=0), "pushes"),
        (dict(objects="rect1"), "objects"), (dict(settings=dict(seed=4)), "settings"),
    ]:
        with pytest.raises(ValueError, match=message):
            dataset.plan_pushes(tmp_path, **{"objects": ["rect1"], "surfaces": ["abs"], "pushes": 1, **arguments})
    for fields, message in [
        (dict(velocities=(0.0,)), "velocities"), (dict(accelerations=(-1.0,)), "accelerations"),
        (dict(repeats=0), "repeats"), (dict(seed=-1), "seed"), (dict(support="feet"), "support"),
        (dict(start_poses="random"), "start_poses"), (dict(testbed="realistic"), "testbed"),
        (dict(effects={}), "effects"),
    ]:
        with pytest.raises(ValueError, match=message):
            dataset.RecordingConfig(**fields)
    with pytest.raises(ValueError, match="workers"):
        dataset.record_pushes(tmp_path, ["rect1"], ["abs"], 1, workers=0)


def test_the_library_records_on_the_realistic_testbed_like_every_command(tmp_path):
    assert dataset.RecordingConfig().testbed == REALISTIC
    assert all(job.testbed == REALISTIC for job in dataset.plan_pushes(tmp_path, ["rect1"], ["abs"], 2))


def test_scattered_start_poses_move_each_push_to_its_own_drawn_pose(tmp_path):
    fixed = dataset.plan_pushes(tmp_path, ["tri1"], ["abs"], pushes=40, settings=ideal(velocities=(20.0,)))
    scattered_settings = ideal(velocities=(20.0,), start_poses="scattered")
    scattered = dataset.plan_pushes(tmp_path, ["tri1"], ["abs"], pushes=40, settings=scattered_settings)
    assert [job.path for job in scattered] == [job.path for job in fixed]  # the same pushes, other places
    assert all(job.initial_pose == (0.0, 0.0, 0.0) for job in fixed)
    poses = np.array([job.initial_pose for job in scattered])
    assert np.all(np.abs(poses[:, :2]) <= dataset.START_SCATTER_M) and np.all(np.abs(poses[:, 2]) <= np.pi)
    assert np.ptp(poses[:, 2]) > np.pi and np.ptp(poses[:, 0]) > dataset.START_SCATTER_M  # spread, not one place
    again = dataset.plan_pushes(tmp_path, ["tri1"], ["abs"], pushes=40, settings=scattered_settings)
    assert [job.initial_pose for job in again] == [job.initial_pose for job in scattered]

    recorded = ideal(seed=3, velocities=(20.0,), start_poses="scattered")
    summary = dataset.record_pushes(tmp_path / "pushes", ["tri1"], ["abs"], pushes=2, settings=recorded, workers=1,
                                    progress=False)
    for path, job in zip(summary.written, dataset.plan_pushes(tmp_path, ["tri1"], ["abs"], 2, recorded)):
        raw = read_raw_push(path)
        np.testing.assert_allclose(raw.object_pose[0, 1:3], job.initial_pose[:2], atol=1e-3)
        assert abs(np.angle(np.exp(1j * (raw.object_pose[0, 3] - job.initial_pose[2])))) < 1e-2
        with h5py.File(path) as file:
            np.testing.assert_array_equal(file.attrs["pushjax_initial_pose"], job.initial_pose)
    with pytest.raises(dataset.OutDirConflictError, match="start_poses"):
        dataset.record_pushes(tmp_path / "pushes", ["tri1"], ["abs"], pushes=2,
                              settings=dataclasses.replace(recorded, start_poses="fixed"), workers=1, progress=False)


def run_cli(*flags):
    return subprocess.run([sys.executable, "-m", "experiments.record_pushes", *flags], cwd=REPO,
                          capture_output=True, text=True, timeout=120)


def test_cli_records_and_resumes(tmp_path):
    flags = [f"--out_dir={tmp_path}", "--objects=rect1,tri2", "--surfaces=abs", "--velocities=20,50", "--pushes=2",
             "--seed=4", "--workers=1", "--effects=com_offset=0.005,0.0;table_tilt_deg=0.5",
             "--declare_effects=false"]
    result = run_cli(*flags)
    assert result.returncode == 0, result.stderr
    assert "wrote 4 files (0 replacing invalid files)" in result.stdout
    assert len(list(tmp_path.rglob("*.h5"))) == 4
    assert "reused 4 valid existing files" in run_cli(*flags).stdout
    next(tmp_path.rglob("*.h5")).write_bytes(b"truncated")
    assert "wrote 1 files (1 replacing invalid files), reused 3" in run_cli(*flags).stdout
    refused = run_cli(*[flag for flag in flags if not flag.startswith("--seed")], "--seed=5")
    assert refused.returncode != 0 and "Traceback" not in refused.stderr
    assert " seed " in refused.stderr and "pushjax_manifest.json" in refused.stderr


CLI_FLAGS = ["--objects=rect1", "--surfaces=abs", "--velocities=20", "--pushes=4", "--seed=6", "--workers=1"]


@pytest.fixture(scope="module")
def alone(tmp_path_factory) -> Path:
    """The folder of one uninterrupted CLI run with `CLI_FLAGS`, which the two tests below compare theirs with."""
    folder = tmp_path_factory.mktemp("alone")
    result = run_cli(f"--out_dir={folder}", *CLI_FLAGS)
    assert result.returncode == 0, result.stderr
    return folder


def test_cli_runs_at_once_in_one_folder_give_the_files_of_one_run(tmp_path, alone):
    command = [sys.executable, "-m", "experiments.record_pushes", f"--out_dir={tmp_path / 'shared'}", *CLI_FLAGS]
    runs = [subprocess.Popen(command, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for _ in range(2)]
    for run in runs:
        _, stderr = run.communicate(timeout=120)
        assert run.returncode == 0, stderr
    assert files(tmp_path / "shared") == files(alone)
    manifest = dataset.MANIFEST_NAME
    assert (tmp_path / "shared" / manifest).read_bytes() == (alone / manifest).read_bytes()
    assert not [path for path in (tmp_path / "shared").rglob("*") if path.name.endswith(".partial")]


def test_cli_killed_and_resumed_gives_the_files_of_one_run(tmp_path, alone):
    flags = [f"--out_dir={tmp_path / 'killed'}", *CLI_FLAGS]
    run = subprocess.Popen([sys.executable, "-m", "experiments.record_pushes", *flags], cwd=REPO,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while not list((tmp_path / "killed").rglob("*.h5")) and time.monotonic() < deadline:
        time.sleep(0.01)
    run.kill()
    run.wait()
    written_before_kill = len(list((tmp_path / "killed").rglob("*.h5")))
    assert 1 <= written_before_kill < 4
    resumed = run_cli(*flags)
    assert resumed.returncode == 0, resumed.stderr
    assert f"reused {written_before_kill} valid existing files" in resumed.stdout
    assert files(tmp_path / "killed") == files(alone)


def test_cli_records_a_realistic_testbed_with_overrides(tmp_path):
    result = run_cli(f"--out_dir={tmp_path}", "--objects=tri1", "--surfaces=delrin", "--velocities=50", "--pushes=1",
                     "--workers=1", "--testbed=realistic", "--testbed_overrides=drop_rate=0;pusher_friction_sigma=0.5")
    assert result.returncode == 0, result.stderr
    settings = json.loads((tmp_path / dataset.MANIFEST_NAME).read_text())["settings"]
    expected = Profile.from_dict({**REALISTIC.to_dict(), "drop_rate": 0.0, "pusher_friction_sigma": 0.5})
    assert Profile.from_dict(settings["testbed"]) == expected
    raw = read_raw_push(next(tmp_path.rglob("*.h5")))
    assert len(raw.object_pose) == len(raw.tip_pose)  # no dropped samples
    assert Profile.from_dict(json.loads(raw.attributes["pushjax_testbed"])) == expected
