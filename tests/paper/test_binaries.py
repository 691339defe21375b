"""Every experiment binary end to end at smoke scale (a few training steps), and its usage errors."""

import json
import math

import pytest
from absl import app

from .conftest import run_binary


def _strict_json(path):
    def reject(constant):
        raise ValueError(f"{path}: non-standard JSON constant {constant}")

    return json.loads(path.read_text(), parse_constant=reject)


def _check_results(workdir, name, models, pngs):
    results = _strict_json(workdir / "results.json")
    assert results["name"] == name
    assert results["config"]["scale"] == "smoke"
    assert results["config"]["dataset"]["scale"] == "smoke"
    assert {row["model"] for row in results["rows"]} == set(models)
    for row in results["rows"]:
        for metric in ("trans_percent", "trans_percent_se", "rot_percent", "rot_percent_se"):
            assert math.isfinite(row[metric]), (row["model"], metric)
    table = (workdir / "results.md").read_text()
    assert all(f"| {model} |" in table for model in models)
    for png in pngs:
        assert (workdir / png).read_bytes()[:4] == b"\x89PNG"
    return results


def test_data_efficiency_clips_sizes_and_writes_tables(smoke_results):
    tmp_path = smoke_results("data_efficiency")
    results = _check_results(tmp_path, "data_efficiency", ("hybrid", "neural_dyn", "zero", "physics"),
                             ["fig5_data_efficiency.png"])
    train_size = {row["train_size"] for row in results["rows"] if row["kind"] == "trained"}
    assert min(train_size) == 20 and max(train_size) < 1_000_000
    physics = next(row for row in results["rows"] if row["model"] == "physics")
    assert physics["trans_percent"] < 50  # Lynch's model on the true state beats predicting no motion
    assert "Table 2" in (tmp_path / "results.md").read_text()


def test_new_pushes(smoke_results):
    tmp_path = smoke_results("new_pushes")
    _check_results(tmp_path, "new_pushes", ("hybrid", "zero"), ["new_pushes.png"])


def test_velocities(smoke_results):
    tmp_path = smoke_results("velocities")
    results = _check_results(tmp_path, "velocities", ("hybrid", "physics"), ["fig6_velocities.png"])
    assert {row["train_split"] for row in results["rows"] if row["kind"] == "trained"} == {
        "train_20", "train_10_20", "train_20_50"}
    assert len({row["test_split"] for row in results["rows"]}) == 8


def test_objects(smoke_results):
    tmp_path = smoke_results("objects")
    results = _check_results(tmp_path, "objects", ("hybrid", "zero"), ["fig7_objects.png"])
    assert {row["test_split"] for row in results["rows"]} == {"test_ellipses", "test_triangles"}


def test_error_variants_scales_l(smoke_results):
    tmp_path = smoke_results("error_variants")
    results = _check_results(tmp_path, "error_variants", ("error", "error_grad", "physics"),
                             ["table4_error_variants.png", "table5_wrong_l.png"])
    scaled = {(row["model"], row["l_scale"]) for row in results["rows"]}
    assert scaled == {(m, 1.0) for m in ("error", "error_grad", "physics")} | {
        (m, s) for m in ("error", "physics") for s in (1.5, 3.0)}
    physics = {row["l_scale"]: row["trans_percent"] for row in results["rows"] if row["model"] == "physics"}
    assert physics[3.0] > physics[1.0]  # a wrong limit-surface ratio hurts the analytical model


def test_viewpoint(smoke_results):
    tmp_path = smoke_results("viewpoint")
    results = _check_results(tmp_path, "viewpoint", ("hybrid", "zero", "physics"), ["viewpoint.png"])
    assert results["config"]["dataset"]["camera"] == "free"


@pytest.mark.parametrize("arguments, message", [
    (("--variants=hybrid,transformer",), "transformer"),
    (("--sizes=100,-5",), "sizes"),
    (("--sizes=ten",), "sizes"),
    (("--sizes=0",), "sizes"),
    (("--data_dir=/nonexistent/pushjax",), "data_dir"),
])
def test_bad_flags_are_usage_errors(tmp_path, arguments, message):
    with pytest.raises(app.UsageError, match=message):
        run_binary("data_efficiency", "--scale=smoke", f"--workdir={tmp_path}", *arguments)


def test_clipped_sizes_warn():
    from pushjax.paper import runner

    with pytest.warns(UserWarning, match=r"exceed the 100 examples of training split 'train'; clipped to 100"):
        assert runner.clip_sizes([50, 200, 300], 100) == (50, 100)


def test_missing_workdir_is_a_usage_error():
    with pytest.raises(app.UsageError, match="workdir"):
        run_binary("data_efficiency", "--scale=smoke")


@pytest.mark.parametrize("binary", ["data_efficiency", "train"])
def test_nobuild_names_the_missing_dataset_where_it_looked_and_build(tmp_path, binary):
    message = (r"^--build: dataset push_effects/data_efficiency_smoke is not built \(looked in "
               f"{tmp_path}/push_effects/data_efficiency_smoke/3.0.0" r"\) and --nobuild forbids building it; "
               "--build builds it there$")
    with pytest.raises(app.UsageError, match=message):
        run_binary(binary, "--scale=smoke", f"--workdir={tmp_path / 'work'}", f"--data_dir={tmp_path}", "--nobuild")
    assert not (tmp_path / "push_effects").exists()


def test_nobuild_names_the_other_versions_it_found(tmp_path):
    (tmp_path / "push_effects" / "data_efficiency_smoke" / "2.0.0").mkdir(parents=True)
    (tmp_path / "push_effects" / "data_efficiency_smoke" / "2.0.0" / "dataset_info.json").write_text("{}")
    message = (r"^--build: dataset push_effects/data_efficiency_smoke is not built \(looked in "
               f"{tmp_path}/push_effects/data_efficiency_smoke/3.0.0; found version 2.0.0 beside it, which this "
               r"pushjax does not read\) and --nobuild forbids building it; --build builds it there$")
    with pytest.raises(app.UsageError, match=message):
        run_binary("data_efficiency", "--scale=smoke", f"--workdir={tmp_path / 'work'}", f"--data_dir={tmp_path}",
                   "--nobuild")


@pytest.mark.parametrize("build", ["--build", "--nobuild"])
def test_a_dataset_folder_of_another_version_is_a_usage_error(tmp_path, build):
    folder = tmp_path / "push_effects" / "data_efficiency_smoke" / "3.0.0"
    folder.mkdir(parents=True)
    (folder / "dataset_info.json").write_text('{"name": "push_effects", "version": "2.0.0"}')
    with pytest.raises(app.UsageError, match=f"^--data_dir: {folder} is not a readable push_effects 3.0.0 dataset "
                                             r"\(AssertionError: .*Proto version: 2.0.0\); delete the folder"):
        run_binary("data_efficiency", "--scale=smoke", f"--workdir={tmp_path / 'work'}", f"--data_dir={tmp_path}",
                   build)
    assert not (tmp_path / "work" / "train").exists()


def test_a_workdir_of_other_models_is_a_usage_error(tmp_path, monkeypatch):
    from pushjax.paper import runner
    from pushjax.train import sweep_trainer

    def conflict(spec, workdir):
        raise sweep_trainer.WorkdirConflictError(f"workdir: {workdir}/train holds a checkpoint of different models")

    monkeypatch.setattr(runner, "run", conflict)
    with pytest.raises(app.UsageError, match=f"^--workdir: {tmp_path}/train holds a checkpoint of different models$"):
        run_binary("data_efficiency", "--scale=smoke", f"--workdir={tmp_path}")


@pytest.mark.parametrize("binary, last_line", [
    ("data_efficiency", "wrote results.json, results.md and 1 figure (fig5_data_efficiency.png) to {workdir}"),
    ("train", "wrote results.json and 0 sweep folders (checkpoints, metrics.csv) to {workdir}"),
])
def test_binaries_end_with_what_they_wrote_where(smoke_data, tmp_path, capsys, binary, last_line):
    workdir = tmp_path / "work"
    run_binary(binary, "--scale=smoke", f"--data_dir={smoke_data('data_efficiency')}", f"--workdir={workdir}",
               "--variants=zero,physics")
    assert capsys.readouterr().out.splitlines()[-1] == last_line.format(workdir=workdir)
    assert (workdir / "results.json").is_file()


def test_visualize(smoke_results):
    tmp_path = smoke_results("visualize")
    _check_results(tmp_path, "visualize", ("hybrid", "neural"), ["fig8_repeated_pushes.png"])


def test_unreadable_paper_tables_stop_the_run_before_training(tmp_path, monkeypatch):
    bad = tmp_path / "paper_tables.json"
    bad.write_text("not json")
    monkeypatch.setenv("PUSHJAX_PAPER_TABLES", str(bad))
    with pytest.raises(app.UsageError, match=f"^PUSHJAX_PAPER_TABLES: {bad} is not a readable JSON file"):
        run_binary("data_efficiency", "--scale=smoke", f"--workdir={tmp_path / 'work'}", "--nobuild")
    assert not (tmp_path / "work").exists()
