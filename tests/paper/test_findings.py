"""The paper's findings checked on hand-made results, and the findings binary on smoke runs."""

import json

import pytest
from absl import app

from pushjax.paper import findings
from tests.paper.conftest import run_binary


def _row(model, score, se=0.5, *, size=None, test_split="test", train_split="train", l_scale=1.0):
    return {"model": model, "kind": "baseline" if size is None else "trained", "train_split": train_split,
            "test_split": test_split, "train_size": size, "seed": None if size is None else 0, "l_scale": l_scale,
            "trans_percent": score, "trans_percent_se": se, "rot_percent": score, "rot_percent_se": se}


def _results(name, rows, test_splits=("test",)):
    return {"name": name, "config": {"test_splits": list(test_splits)}, "rows": rows}


def _data_efficiency(small, large):
    rows = [_row(model, value, size=2500) for model, value in small.items()]
    rows += [_row(model, value, size=20000) for model, value in large.items()]
    return {"data_efficiency": _results("data_efficiency", rows)}


def _verdicts(results):
    return {finding.key: finding.verdict for finding in findings.check(results)}


def test_data_efficiency_findings_are_decided_three_ways():
    small = {"hybrid": 20.0, "error": 21.0, "neural": 40.0, "simple": 35.0}
    large = {"neural": 10.0, "hybrid": 12.0, "simple": 15.0, "error": 11.0, "neural_dyn": 5.0}
    verdicts = _verdicts(_data_efficiency(small, large))
    assert verdicts["small_data"] == findings.HOLDS and verdicts["most_data"] == findings.HOLDS
    # error − simple = -0.5 ± 0.5 is within two standard errors ("clearly"), neural − error = 0.3 ± 0.5 within
    # one; neural_dyn does not count as a perception variant.
    verdicts = _verdicts(_data_efficiency({**small, "simple": 21.5}, {**large, "error": 9.7}))
    assert verdicts["small_data"] == findings.UNDECIDED and verdicts["most_data"] == findings.UNDECIDED
    verdicts = _verdicts(_data_efficiency({**small, "simple": 15.0}, {**large, "error": 8.0}))
    assert verdicts["small_data"] == findings.FAILS and verdicts["most_data"] == findings.FAILS
    assert _verdicts(_data_efficiency({"hybrid": 1.0}, {"hybrid": 1.0}))["small_data"] == findings.UNCHECKED


def _velocity_rows(tests, speeds, neural_20_50):
    rows = []
    for split, speed in zip(tests, speeds):
        rows.append(_row("physics", 30.0, test_split=split))
        for model, score in (("hybrid", 32.0 + speed / 100), ("neural", 20.0 + speed / 5),
                             ("neural_dyn", 18.0 + speed / 5)):
            rows.append(_row(model, score, size=1000, test_split=split, train_split="train_20"))
        rows.append(_row("neural", neural_20_50(speed), size=1000, test_split=split, train_split="train_20_50"))
    return rows


def test_velocity_findings():
    tests, speeds = ("test_20", "test_50", "test_100", "test_300"), (20, 50, 100, 300)
    rows = _velocity_rows(tests, speeds, lambda speed: 20.0 + speed / 10)
    verdicts = _verdicts({"velocities": _results("velocities", rows, tests)})
    assert verdicts["extrapolation"] == findings.HOLDS and verdicts["faster_training"] == findings.HOLDS
    same = _velocity_rows(tests, speeds, lambda speed: 20.0 + speed / 5)
    assert _verdicts({"velocities": _results("velocities", same, tests)})["faster_training"] == findings.UNDECIDED
    # A model worse with the faster training set breaks "improves for all models" even when another gains.
    worse = rows + [_row("hybrid", 40.0, size=1000, test_split=split, train_split="train_20_50") for split in tests]
    assert _verdicts({"velocities": _results("velocities", worse, tests)})["faster_training"] == findings.FAILS


def test_wrong_l_and_new_pushes_findings():
    rows = [_row(model, value, size=2500, l_scale=scale)
            for scale, values in ((1.0, {"hybrid": 10.0, "error": 10.0}), (3.0, {"hybrid": 30.0, "error": 15.0}))
            for model, value in values.items()]
    pushes = [_row("neural", 30.0, size=2500), _row("hybrid", 20.0, size=2500), _row("error", 25.0, size=2500)]
    verdicts = _verdicts({"error_variants": _results("error_variants", rows),
                          "new_pushes": _results("new_pushes", pushes)})
    assert verdicts["wrong_l"] == findings.HOLDS and verdicts["new_pushes"] == findings.HOLDS
    assert verdicts["small_data"] == findings.UNCHECKED


def test_findings_binary_on_smoke_results(smoke_results, tmp_path, capsys):
    output = tmp_path / "findings.md"
    workdirs = [smoke_results("data_efficiency"), smoke_results("error_variants")]
    run_binary("findings", f"--workdirs={','.join(map(str, workdirs))}", f"--output={output}")
    table = output.read_text()
    printed = capsys.readouterr().out.strip()
    assert printed.endswith(f"{table.strip()}\nwrote the table to {output}")
    assert table.count("\n| ") == len(findings.CHECKS) + 1  # the header
    assert f"| {findings.CHECKS['wrong_l'][0]} | error_variants |" in table


def test_findings_binary_rejects_missing_and_foreign_files(tmp_path):
    with pytest.raises(app.UsageError, match="results.json does not exist"):
        run_binary("findings", f"--workdirs={tmp_path}")
    (tmp_path / "results.json").write_text(json.dumps([1, 2]))
    with pytest.raises(app.UsageError, match="is not a results.json"):
        run_binary("findings", f"--workdirs={tmp_path}")
