"""The paper-composition run (issue 30) on the smoke data: one model per unit, records, resuming."""

import json

import pytest
from absl import app

from pushjax.paper import findings, full_run
from tests.paper.conftest import run_binary

TINY = "--criterion=eval_every=5;window=2;base_steps=10;steps_per_example=0;max_steps=10;min_decay_steps=2"


def test_plan_covers_the_issue():
    units = full_run.plan()
    sizes = sorted({unit.size for unit in units if not unit.wide})
    assert len(sizes) >= 7 and sizes[-1] >= 150_000 and len({unit.key for unit in units}) == len(units)
    for size in sizes:
        variants = {unit.variant for unit in units if unit.size == size and not unit.wide}
        expected = {"neural", "hybrid", "error"} | ({"simple", "neural_dyn"} if size in full_run.SIDE_SIZES else set())
        assert variants == expected
        assert all({u.seed for u in units if u.size == size and u.variant == v} == {0, 1, 2} for v in variants)
    assert [unit.key for unit in units if unit.wide] == ["neural_190080_seed0_wide", "hybrid_190080_seed0_wide"]


def test_records_resume_and_results(smoke_data, tmp_path):
    data_dir, workdir = smoke_data("data_efficiency"), tmp_path / "run"
    arguments = (f"--workdir={workdir}", f"--data_dir={data_dir}", "--scale=smoke", "--sizes=40,80",
                 "--side_sizes=80", "--seeds=0", "--nowide", TINY)
    run_binary("data_efficiency_full", *arguments, "--max_models=1")
    first = workdir / "models" / "neural_40_seed0.json"
    assert sorted(path.name for path in (workdir / "models").iterdir()) == [first.name]
    recorded = first.read_text()
    results = json.loads((workdir / "results.json").read_text())
    assert results["progress"]["done"] == 1 and results["progress"]["planned"] == 8
    run_binary("data_efficiency_full", *arguments)
    assert first.read_text() == recorded  # skipped, not trained again
    results = json.loads((workdir / "results.json").read_text())
    assert results["name"] == "data_efficiency_full" and results["progress"]["missing"] == []
    trained = [row for row in results["rows"] if row["kind"] == "trained"]
    assert sorted((row["model"], row["train_size"]) for row in trained) == sorted(
        [(m, 40) for m in ("neural", "hybrid", "error")]
        + [(m, 80) for m in ("neural", "hybrid", "error", "simple", "neural_dyn")])
    assert all(row["converged"] is False and row["steps"] == 12 and row["sequences"]["id"] for row in trained)
    assert {row["model"] for row in results["rows"] if row["kind"] == "baseline"} == {"zero", "physics"}
    assert results["config"]["criterion"]["eval_every"] == 5
    markdown = (workdir / "results.md").read_text()
    assert "## Convergence: criterion met per model" in markdown and "0/1 met, 12 steps" in markdown
    keys = {finding.key: finding for finding in findings.check(findings.load([workdir]))}
    assert keys["crossover"].experiment == "data_efficiency_full"
    assert keys["crossover"].verdict in (findings.HOLDS, findings.NOT_REACHED.format(size=80))


def test_bad_criterion_and_deadline(tmp_path):
    with pytest.raises(app.UsageError, match="--criterion: unknown field 'patience'"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--criterion=patience=3")
    with pytest.raises(app.UsageError, match="--criterion: window expects a int"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--criterion=window=x")
    with pytest.raises(app.UsageError, match="--deadline"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--deadline=soon")
