"""Tests for pushjax.sim.dataset and experiments/record_pushes: determinism, resuming, attributes, the CLI."""

import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from pushjax.data.mit_push import load_push, parse_push_file_name, read_raw_push
from pushjax.sim import dataset
from pushjax.sim.effects import Effects

REPO = Path(__file__).resolve().parents[2]


def files(root: Path) -> dict[str, bytes]:
    return {path.relative_to(root).as_posix(): path.read_bytes() for path in sorted(root.rglob("*.h5"))}


def test_same_seed_same_bytes_for_any_worker_count(tmp_path):
    arguments = dict(objects=["rect1", "tri1"], surfaces=["abs"], pushes=3, seed=5, velocities=(20.0, 50.0),
                     effects=Effects(tracking_noise=(5e-4, 0.005)), progress=False)
    serial = dataset.record_pushes(tmp_path / "serial", workers=1, **arguments)
    parallel = dataset.record_pushes(tmp_path / "parallel", workers=2, **arguments)
    assert len(serial.written) == len(parallel.written) == 6
    assert files(tmp_path / "serial") == files(tmp_path / "parallel")
    other_seed = dataset.record_pushes(tmp_path / "other", workers=1, **{**arguments, "seed": 6})
    assert files(tmp_path / "other") != files(tmp_path / "serial")
    assert len(other_seed.written) == 6


def test_existing_files_are_skipped(tmp_path):
    arguments = dict(objects=["hex"], surfaces=["delrin"], pushes=4, seed=1, velocities=(50.0,), workers=1,
                     progress=False)
    first = dataset.record_pushes(tmp_path, **arguments)
    assert len(first.written) == 4 and not first.skipped
    before = files(tmp_path)
    again = dataset.record_pushes(tmp_path, **arguments)
    assert not again.written and sorted(again.skipped) == sorted(first.written)
    first.written[2].unlink()
    resumed = dataset.record_pushes(tmp_path, **arguments)
    assert resumed.written == [first.written[2]] and len(resumed.skipped) == 3
    assert files(tmp_path) == before


def test_files_follow_the_mit_layout_and_declare_effects(tmp_path):
    effects = Effects(table_tilt_deg=1.0, tracking_bias=(0.001, 0.0, 0.0))
    summary = dataset.record_pushes(tmp_path, ["ellip2"], ["plywood"], pushes=2, seed=3, velocities=(20.0,),
                                    effects=effects, workers=1, progress=False)
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
    summary = dataset.record_pushes(tmp_path, ["rect3"], ["pu"], pushes=1, seed=0, velocities=(50.0,),
                                    effects=Effects(com_offset=(0.01, 0.0)), declare_effects=False, workers=1,
                                    progress=False)
    with h5py.File(summary.written[0], "r") as file:
        assert sorted(file.keys()) == ["ft_wrench", "object_pose", "tip_pose"]
        assert len(file.attrs) == 0
        for name in file:
            assert len(file[name].attrs) == 0


def test_repeats_write_rep_files_of_one_push(tmp_path):
    summary = dataset.record_pushes(tmp_path, ["tri3"], ["abs"], pushes=2, seed=2, velocities=(50.0,), repeats=3,
                                    effects=Effects(tracking_noise=(1e-3, 0.0)), workers=1, progress=False)
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
    jobs = dataset.plan_pushes(tmp_path, ["rect1"], ["abs"], pushes=300, velocities=(20.0,))
    assert len({job.path for job in jobs}) == 300
    with pytest.raises(ValueError, match="pushes"):
        dataset.plan_pushes(tmp_path, ["rect1"], ["abs"], pushes=4 * 11 * 9 + 1, velocities=(20.0,))
    for arguments, message in [
        (dict(objects=["cube"]), "objects"), (dict(surfaces=["ice"]), "surfaces"), (dict(pushes=0), "pushes"),
        (dict(velocities=(0.0,)), "velocities"), (dict(accelerations=(-1.0,)), "accelerations"),
        (dict(repeats=0), "repeats"), (dict(support="ring"), "support"), (dict(objects="rect1"), "objects"),
    ]:
        with pytest.raises(ValueError, match=message):
            dataset.plan_pushes(tmp_path, **{"objects": ["rect1"], "surfaces": ["abs"], "pushes": 1, **arguments})
    with pytest.raises(ValueError, match="workers"):
        dataset.record_pushes(tmp_path, ["rect1"], ["abs"], 1, workers=0)


def run_cli(*flags):
    return subprocess.run([sys.executable, "-m", "experiments.record_pushes", *flags], cwd=REPO,
                          capture_output=True, text=True, timeout=120)


def test_cli_records_and_resumes(tmp_path):
    flags = [f"--out_dir={tmp_path}", "--objects=rect1,tri2", "--surfaces=abs", "--velocities=20,50", "--pushes=2",
             "--seed=4", "--workers=1", "--effects=com_offset=0.005,0.0;table_tilt_deg=0.5",
             "--declare_effects=false"]
    result = run_cli(*flags)
    assert result.returncode == 0, result.stderr
    assert "wrote 4 files" in result.stdout
    assert len(list(tmp_path.rglob("*.h5"))) == 4
    assert "skipped 4" in run_cli(*flags).stdout


@pytest.mark.parametrize("flag, message", [
    ("--objects=cube", "--objects"), ("--velocities=fast", "--velocities"), ("--effects=gravity=1", "--effects"),
])
def test_cli_rejects_bad_flags(tmp_path, flag, message):
    result = run_cli(f"--out_dir={tmp_path}", flag)
    assert result.returncode != 0
    assert message in result.stderr
