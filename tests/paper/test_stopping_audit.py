"""The audit of a convergence-criterion run under the trend rule, on records made here."""

import json

import numpy as np
import pytest
from absl import app

from pushjax.paper import stopping_audit
from tests.paper.conftest import run_binary


def _record(key, scores, converged=True, decay=1_000, fixed_budget=False):
    steps = [1_000 * (index + 1) for index in range(len(scores))]
    validation = [{"step": step, "trans_percent": score - 5.0, "rot_percent": score + 5.0}
                  for step, score in zip(steps, scores)]
    if decay:
        validation.append({"step": steps[-1] + decay, "trans_percent": 0.0, "rot_percent": 0.0})  # after the decay
    variant, size, seed = key.rsplit("_", 2)
    return {"key": key, "row": {"model": variant, "train_size": int(size), "seed": int(seed[len("seed"):]),
                                "constant_steps": steps[-1], "converged": converged, "steps": steps[-1] + decay},
            "validation": validation, "criterion": {"stop_on_plateau": not fixed_budget}}


def _write(folder, *records):
    (folder / "models").mkdir(parents=True)
    for record in records:
        (folder / "models" / f"{record['key']}.json").write_text(json.dumps(record))


def test_a_falling_curve_is_improving_and_a_flat_one_is_stopped(tmp_path):
    rng = np.random.default_rng(0)
    falling = 40.0 - 0.15 * np.arange(30) + rng.normal(0, 0.2, 30)  # 1.5 points per 10 000 steps
    flat = 30.0 + rng.normal(0, 0.2, 30)
    short = 40.0 - 0.5 * np.arange(8)
    _write(tmp_path, _record("neural_100_seed0", falling), _record("hybrid_100_seed0", flat),
           _record("error_100_seed0", short, converged=False))
    results = stopping_audit.audit(tmp_path)
    rows = {row["key"]: row for row in results["rows"]}
    assert rows["neural_100_seed0"]["improving"] and not rows["neural_100_seed0"]["rule_stops"]
    assert rows["neural_100_seed0"]["end_trend"]["gain"] == pytest.approx(1.5, abs=0.5)
    assert not rows["hybrid_100_seed0"]["improving"] and rows["hybrid_100_seed0"]["rule_stops"]
    assert rows["hybrid_100_seed0"]["first_stop"] is not None
    assert rows["error_100_seed0"]["too_short"] and rows["error_100_seed0"]["improving"]
    assert results["counts"] == {"models": 3, "criterion_met": 2, "stopped_while_improving": 1,
                                 "budget_ended_while_improving": 1, "rule_would_not_stop": 1, "rule_too_short": 0,
                                 "rule_agrees": 1}


def test_the_binary_writes_the_audit_and_rejects_a_folder_without_records(tmp_path):
    _write(tmp_path / "run", _record("neural_100_seed0", list(40.0 - 0.1 * np.arange(25))))
    run_binary("stopping_audit", f"--run={tmp_path / 'run'}", f"--workdir={tmp_path / 'out'}")
    assert "| neural_100_seed0 | 25,000 | met |" in (tmp_path / "out" / "results.md").read_text()
    assert json.loads((tmp_path / "out" / "results.json").read_text())["counts"]["models"] == 1
    with pytest.raises(app.UsageError, match="--run: no model records in"):
        run_binary("stopping_audit", f"--run={tmp_path / 'empty'}", f"--workdir={tmp_path / 'out'}")


def test_fixed_budgets_continue_when_a_seed_still_falls_and_stop_when_none_does(tmp_path):
    rng = np.random.default_rng(1)
    flat = [30.0 + rng.normal(0, 0.1, 75) for _ in range(3)]
    falling = 40.0 - 0.2 * np.arange(75) + rng.normal(0, 0.1, 75)  # 2 points per 10 000 steps
    records = [_record(f"hybrid_190080_seed{seed}", curve, converged=False, decay=0, fixed_budget=True)
               for seed, curve in enumerate(flat)]
    records += [_record(f"neural_190080_seed{seed}", curve, converged=False, decay=0, fixed_budget=True)
                for seed, curve in enumerate([flat[0], falling, flat[2]])]
    records.append(_record("neural_100_seed0", flat[0]))  # the criterion's: not a fixed budget
    _write(tmp_path / "run", *records)
    results = stopping_audit.audit(tmp_path / "run")
    rows = {row["variant"]: row for row in results["continuations"]}
    assert set(rows) == {"hybrid", "neural"} and rows["neural"]["size"] == 190_080
    assert rows["hybrid"]["rule_stops"] == [True, True, True] and not rows["hybrid"]["continues"]
    assert rows["hybrid"]["next_steps"] is None
    assert rows["neural"]["rule_stops"] == [True, False, True] and rows["neural"]["continues"]
    assert rows["neural"]["next_steps"] == 150_000 and rows["neural"]["steps"] == [75_000] * 3
    assert rows["neural"]["trends"][1]["gain"] == pytest.approx(2.0, abs=0.3)
    run_binary("stopping_audit", f"--run={tmp_path / 'run'}", f"--workdir={tmp_path / 'out'}")
    markdown = (tmp_path / "out" / "results.md").read_text()
    assert "| neural | 190,080 | 1 | 75,000 |" in markdown and "| continues to 150,000 |" in markdown
    assert "| hybrid | 190,080 | 0 | 75,000 |" in markdown and markdown.count("| stops |") == 3
