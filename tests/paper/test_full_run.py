"""The paper-composition run (issue 30) on the smoke data: one model per unit, records, resuming."""

import datetime
import hashlib
import json
import shutil
import types

import numpy as np
import pytest
from absl import app

from pushjax import provenance, train as train_lib
from pushjax.paper import findings, full_run, runner
from pushjax.train import evaluate
from pushjax.train.batching import batch_indices, gather
from pushjax.train.predictor import checkpoint_variables, load_model
from tests.paper.conftest import RUNS, SMOKE, run_binary


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


def test_select_keeps_the_given_order_and_names_unknown_keys():
    units = full_run.plan()
    wide = ["hybrid_190080_seed0_wide", "neural_190080_seed0_wide"]
    assert [unit.key for unit in full_run.select(units, wide + wide[:1])] == wide
    assert all(unit.wide for unit in full_run.select(units, wide))
    with pytest.raises(ValueError, match="neural_190080_seed7 not in the plan; its models are neural_2500_seed0"):
        full_run.select(units, ["neural_190080_seed7"])


def test_results_of_the_records(smoke_results):
    workdir = smoke_results("data_efficiency_full")
    results = json.loads((workdir / "results.json").read_text())
    assert results["name"] == "data_efficiency_full" and results["progress"] == {"planned": 8, "done": 8, "missing": []}
    trained = [row for row in results["rows"] if row["kind"] == "trained"]
    assert sorted((row["model"], row["train_size"]) for row in trained) == sorted(
        [(m, 40) for m in ("neural", "hybrid", "error")]
        + [(m, 80) for m in ("neural", "hybrid", "error", "simple", "neural_dyn")])
    # The tiny criterion's budget of 10 steps ends every model before the criterion can (2 scores, window 2).
    assert all(row["converged"] is False and row["steps"] == 12 and row["sequences"]["id"] for row in trained)
    assert {row["model"] for row in results["rows"] if row["kind"] == "baseline"} == {"zero", "physics"}
    assert results["config"]["criterion"]["eval_every"] == 5
    assert len(results["curves"]) == 3 * len(trained)  # steps 5, 10 and after the decay
    markdown = (workdir / "results.md").read_text()
    assert "## Convergence: criterion met per model" in markdown and "0/1 met, 12 steps" in markdown
    # The build the baselines were scored on, and every record naming its build and its final parameters.
    build = provenance.parse_digests((workdir / full_run.DATASET_DIGESTS).read_text())
    assert len(build) >= 2 and all(len(digest) == 64 for digest in build.values())
    built = hashlib.sha256((workdir / full_run.DATASET_DIGESTS).read_bytes()).hexdigest()
    saved = [json.loads(path.read_text()) for path in (workdir / "models").iterdir()]
    assert {record["dataset_sha256"] for record in saved} == {built}
    assert len({record["params_sha256"] for record in saved}) == len(saved)
    keys = {finding.key: finding for finding in findings.check(findings.load([workdir]))}
    assert keys["crossover"].experiment == "data_efficiency_full"


def test_a_fresh_checkout_trains_only_the_missing_models(smoke_results, smoke_data, tmp_path):
    # The smoke run trained two models at once (the binary's default); these two are trained again one at a time and
    # must give the same records.
    workdir = tmp_path / "run"
    shutil.copytree(smoke_results("data_efficiency_full"), workdir)
    records = workdir / "models"
    before = {path.name: path.read_text() for path in records.iterdir()}
    missing = ["hybrid_80_seed0", "neural_80_seed0"]
    for key in missing:
        (records / f"{key}.json").unlink()
    (workdir / "results.json").unlink()
    _, arguments = RUNS["data_efficiency_full"]
    run_binary("data_efficiency_full", *SMOKE, f"--data_dir={smoke_data('data_efficiency')}", f"--workdir={workdir}",
               *arguments, "--max_models=0")
    results = json.loads((workdir / "results.json").read_text())
    assert sorted(results["progress"]["missing"]) == missing
    run_binary("data_efficiency_full", *SMOKE, f"--data_dir={smoke_data('data_efficiency')}", f"--workdir={workdir}",
               *arguments, "--models_at_once=1")
    after = {path.name: path.read_text() for path in records.iterdir()}
    assert set(after) == set(before)
    assert all(after[name] == text for name, text in before.items() if name[:-len(".json")] not in missing)
    for key in missing:
        retrained, original = (json.loads(texts[f"{key}.json"]) for texts in (after, before))
        assert retrained["row"] == original["row"] and retrained["validation"] == original["validation"]
        assert retrained["params_sha256"] == original["params_sha256"]  # bit-identical parameters
    assert json.loads((workdir / "results.json").read_text())["progress"]["done"] == 8
    assert not any((workdir / full_run.IN_TRAINING).iterdir())  # the training state goes with the record


def test_a_run_on_another_build_of_its_dataset_says_so(tmp_path):
    lines = []
    digests = {"a.array_record-00000-of-00002": "0" * 64, "a.array_record-00001-of-00002": "1" * 64}
    # Baselines scored before builds were recorded: nothing to compare with, and nothing claimed.
    first = full_run.check_dataset(tmp_path, digests, lines.append)
    assert len(lines) == 1 and "cannot be compared" in lines[0] and not (tmp_path / full_run.DATASET_DIGESTS).exists()
    lines.clear()
    (tmp_path / full_run.DATASET_DIGESTS).write_text(provenance.digests_text(digests))
    assert full_run.check_dataset(tmp_path, dict(digests), lines.append) == first and lines == []
    other = {**digests, "a.array_record-00001-of-00002": "2" * 64}
    assert full_run.check_dataset(tmp_path, other, lines.append) != first
    assert len(lines) == 1 and "differs from the one the baselines were scored on" in lines[0]
    assert "in 1 of 2 data files (a.array_record-00001-of-00002)" in lines[0]
    assert provenance.parse_digests((tmp_path / full_run.DATASET_DIGESTS).read_text()) == digests  # kept


def test_models_read_only_their_rows_and_see_the_batches_of_the_whole_split():
    split = {"l": np.arange(1000, dtype=np.float32), "motion": np.arange(3000, dtype=np.float32).reshape(1000, 3)}
    source = [{name: values[index] for name, values in split.items()} for index in range(1000)]
    units = [full_run.Unit("neural", 100, seed) for seed in (0, 1)] + [full_run.Unit("hybrid", 100, 0)]
    training = full_run.read_training_examples(source, ["l", "motion"], units)
    assert 100 < len(training.rows) <= 200 and training.split_size == 1000
    for unit in units:
        (whole,) = train_lib.subset_specs(1000, (unit.size,), (unit.seed,))
        spec = training.model_spec(unit)
        for step in (0, 3, 7):  # steps 3 and 7 cross into the next epoch of 100 examples
            np.testing.assert_array_equal(
                gather(training.examples, batch_indices(spec, step, 32), ["motion"])["motion"],
                gather(split, batch_indices(whole, step, 32), ["motion"])["motion"])
    everything = full_run.read_training_examples(source, ["l"], [full_run.Unit("neural", 5000, 0)])
    np.testing.assert_array_equal(everything.rows, np.arange(1000))


def test_the_queue_hands_out_units_in_order_until_the_limit_or_the_deadline():
    units = full_run.plan(sizes=(40, 80), seeds=(0,), side_sizes=(), wide=False)
    lines = []
    queue = full_run._UnitQueue(units, 2, None, lines.append)
    assert [queue.next(), queue.next(), queue.next(), queue.next()] == [units[0], units[1], None, None]
    past = datetime.datetime(2000, 1, 1, tzinfo=datetime.timezone.utc)
    queue = full_run._UnitQueue(units, None, past, lines.append)
    assert queue.next() is None and queue.next() is None and len(lines) == 1 and units[0].key in lines[0]
    queue = full_run._UnitQueue(units, None, None, lines.append)
    queue.stop()
    assert queue.next() is None


def test_bad_criterion_and_deadline(tmp_path):
    with pytest.raises(app.UsageError, match="--criterion: unknown field 'patience'"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--criterion=patience=3")
    with pytest.raises(app.UsageError, match="--criterion: window expects a int"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--criterion=window=x")
    with pytest.raises(app.UsageError, match="--deadline"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--deadline=soon")
    with pytest.raises(app.UsageError, match="--only: simple_50000_seed0 not in the plan"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--only=simple_50000_seed0")


def test_a_recorded_model_loads_from_the_run_and_scores_as_recorded(smoke_results, smoke_data):
    workdir = smoke_results("data_efficiency_full")
    record = json.loads((workdir / "models" / "hybrid_80_seed0.json").read_text())
    assert record["device"] == {"platform": "cpu", "kind": "cpu", "matmul_precision": "default"}
    predictor = load_model(workdir, model="hybrid_80_seed0")
    assert predictor.variant == "hybrid" and predictor.name == "size=80/seed=0"
    assert predictor.checkpoint == (workdir / full_run.CHECKPOINTS / "hybrid_80_seed0", record["row"]["steps"])
    spec = full_run.make_spec(smoke_data("data_efficiency"), sizes=(40, 80), seeds=(0,), scale="smoke", build=False)
    test = train_lib.examples_from_source(runner.load_splits(spec, spec.dataset, False)["test"], spec.example_fields())
    state = types.SimpleNamespace(params=predictor.variables["params"], batch_stats=predictor.variables["batch_stats"])
    assert provenance.tree_digest(checkpoint_variables(state)) == record["params_sha256"]
    scores = evaluate.evaluate(predictor.model, state, test)
    for key in ("trans_percent", "rot_percent"):
        assert scores[key] == pytest.approx(record["row"][key], rel=1e-5)
    with pytest.raises(ValueError, match=r"model: .* one checkpoint folder per model; expected one of \[.*'neural_40_seed0'"):
        load_model(workdir, model="hybrid_99_seed0")


def test_the_paper_schedule_trains_a_fixed_budget_and_continues_it(smoke_data, smoke_results, tmp_path):
    workdir = tmp_path / "long"
    arguments = (*SMOKE, f"--data_dir={smoke_data('data_efficiency')}", f"--workdir={workdir}", "--sizes=80",
                 "--seeds=0", "--variants=neural", "--nowide", "--schedule=paper", "--criterion=eval_every=5")
    run_binary("data_efficiency_full", *arguments, "--steps=10")
    record = json.loads((workdir / "models" / "neural_80_seed0.json").read_text())
    assert record["row"]["steps"] == 10 and record["row"]["decay_steps"] == 0 and record["row"]["converged"] is False
    assert [point["step"] for point in record["validation"]] == [5, 10]
    results = json.loads((workdir / "results.json").read_text())
    assert results["config"]["train"]["learning_rate"] == 1e-4 and results["config"]["train"]["batch_size"] == 32
    assert results["config"]["criterion"]["stop_on_plateau"] is False
    assert (workdir / full_run.IN_TRAINING / "neural_80_seed0").is_dir()  # kept, to be continued
    run_binary("data_efficiency_full", *arguments, "--steps=20")
    continued = json.loads((workdir / "models" / "neural_80_seed0.json").read_text())
    assert continued["row"]["steps"] == 20 and continued["validation"][:2] == record["validation"]
    assert [point["step"] for point in continued["validation"]] == [5, 10, 15, 20]
    # Its cell replaces the criterion's in Table 1, and the findings are decided both ways.
    full = smoke_results("data_efficiency_full")
    merged = full_run.with_models_of(json.loads((full / "results.json").read_text()), workdir)
    neural_80 = [row for row in merged["rows"] if row["model"] == "neural" and row["train_size"] == 80]
    assert [row["steps"] for row in neural_80] == [20] and merged["replaced"]["cells"] == [["neural", 80]]
    assert sum(row["model"] == "hybrid" for row in merged["rows"]) == 2  # sizes 40 and 80, untouched
    assert not any(curve["model"] == "neural" and curve["train_size"] == 80 for curve in merged["curves"])
    output = tmp_path / "findings.md"
    run_binary("findings", f"--workdirs={full}", f"--replace_with={workdir}", f"--output={output}")
    table = output.read_text()
    assert f"| as run | with {workdir} | changed |" in table and "neural" in table
    with pytest.raises(app.UsageError, match="--replace_with: no model records in"):
        run_binary("findings", f"--workdirs={full}", f"--replace_with={tmp_path / 'none'}")
    with pytest.raises(app.UsageError, match="--variants: simpel not trained by this run"):
        run_binary("data_efficiency_full", f"--workdir={tmp_path}", "--variants=simpel")
