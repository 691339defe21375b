"""scripts/same_results.py, the before / after check of a refactoring, on hand-made work directories."""

import json
import subprocess
import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]
SCRIPT = REPOSITORY / "scripts" / "same_results.py"


def _write(folder: Path, name: str, contents) -> None:
    (folder / name).parent.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(json.dumps(contents))


def _run(*arguments):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, arguments)], capture_output=True, text=True,
                          timeout=60)


def _record(trans, *, seconds=1.0, commit="abc", steps=10):
    return {"row": {"model": "hybrid", "trans_percent": trans, "steps": steps}, "train_seconds": seconds,
            "commit": commit, "validation": [{"step": 5, "trans_percent": trans + 1}]}


def test_runs_that_differ_only_in_times_and_provenance_are_the_same(tmp_path):
    for side, (seconds, commit) in {"old": (1.0, "abc"), "new": (7.5, "def+changes")}.items():
        _write(tmp_path / side, "models/hybrid_80_seed0.json", _record(40.0, seconds=seconds, commit=commit))
        _write(tmp_path / side, "results.json", {"rows": [{"trans_percent": 40.0}], "provenance": {"commit": commit},
                                                 "config": {"data_dir": f"/tmp/{side}"}})
    result = _run(tmp_path / "old", tmp_path / "new", "--ignore=data_dir")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 of 2 files the same" in result.stdout
    assert _run(tmp_path / "old", tmp_path / "new").returncode == 1  # the data folder differs unless ignored


def test_a_changed_number_a_changed_curve_and_a_missing_record_are_reported(tmp_path):
    _write(tmp_path / "old", "models/a.json", _record(40.0))
    _write(tmp_path / "old", "models/b.json", _record(40.0))
    _write(tmp_path / "old", "models/c.json", _record(40.0))
    _write(tmp_path / "new", "models/a.json", _record(40.000001))
    _write(tmp_path / "new", "models/b.json", _record(40.0, steps=11))
    result = _run(tmp_path / "old", tmp_path / "new")
    assert result.returncode == 1
    lines = result.stdout.splitlines()
    assert "models/a.json: /row/trans_percent: 40.0 != 40.000001; /validation[0]/trans_percent: 41.0 != 41.000001" \
        in lines
    assert "models/b.json: /row/steps: 10 != 11" in lines
    assert any(line.startswith("models/c.json: missing in") for line in lines)
    assert lines[-1] == "0 of 3 files the same"


def test_bad_folders_are_one_line_errors(tmp_path):
    result = _run(tmp_path / "nothing", tmp_path)
    assert result.returncode == 2 and result.stderr == f"error: old: {tmp_path / 'nothing'} is not a directory\n"
    result = _run(tmp_path, tmp_path)
    assert result.returncode == 2 and result.stderr == f"error: old: {tmp_path} holds no results.json and no models/*.json\n"
