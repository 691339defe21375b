"""Tests of ``python -m experiments.close_loop``."""

import json
import os
import subprocess
import sys
from pathlib import Path

import jax

from pushjax.physics import model_file

REPO = Path(__file__).resolve().parents[2]


def run(*arguments):
    cache = jax.config.jax_compilation_cache_dir  # the test run's (tests/conftest.py), so the binary compiles less
    env = {**os.environ, **({"JAX_COMPILATION_CACHE_DIR": cache} if cache else {})}
    return subprocess.run([sys.executable, "-m", "experiments.close_loop", *arguments], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=600)


def first_pushes(root: Path, count: int, folder: Path) -> Path:
    """``folder`` holding links to the first ``count`` push files below ``root``, in the same layout."""
    for path in sorted(root.rglob("*.h5"))[:count]:
        target = folder / path.relative_to(root)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.symlink_to(path)
    return folder


def test_writes_the_report_and_continues_an_unconverged_fit(record, tmp_path):
    # Two candidates and a third of the pushes keep it short; what the loop selects from the whole library on all of
    # them is test_undeclared_effects.py's. At half the default steps the exact surface's fit on these pushes is 10 %
    # above its optimum, and before the convergence check table_tilt took up its misfit (BENCHMARKS.md, "Does the
    # loop's fit converge?"): now the second round continues the fits until the current model's has converged.
    pushes = first_pushes(record("pressure"), 40, tmp_path / "pushes")
    result = run(f"--data_dir={pushes}", f"--workdir={tmp_path / 'out'}", "--seed=3",
                 "--effects=limit_surface,table_tilt", "--steps=150")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["selected"] == ["limit_surface"]  # the centre-loaded pressure: the exact surface's rim mode
    second = json.loads((tmp_path / "out" / "details.json").read_text())["rounds"][1]
    assert second["continuations"] >= 1 and second["converged"] and "the fits had not converged" not in result.stderr
    assert sorted(entry["effect"] for entry in report["ranking"]) == ["limit_surface", "table_tilt"]
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 4 and lines[0].endswith("selected: limit_surface") and lines[-1].startswith("wrote ")
    assert (tmp_path / "out" / "report.md").is_file() and (tmp_path / "out" / "details.json").is_file()
    assert model_file.read(tmp_path / "out" / "model.json").effects == tuple(report["selected"])


def test_missing_or_empty_data_dir_names_the_flag(tmp_path):
    missing = run(f"--data_dir={tmp_path / 'nowhere'}", f"--workdir={tmp_path / 'out'}")
    assert missing.returncode != 0 and "--data_dir" in missing.stderr and "not a directory" in missing.stderr
    (tmp_path / "empty").mkdir()
    empty = run(f"--data_dir={tmp_path / 'empty'}", f"--workdir={tmp_path / 'out'}")
    assert empty.returncode != 0 and "--data_dir" in empty.stderr and "no push files" in empty.stderr
    assert not (tmp_path / "out" / "report.json").exists()


def test_too_few_push_sequences_stop_with_one_line(record, tmp_path):
    few = first_pushes(record("clean"), 3, tmp_path / "few")
    result = run(f"--data_dir={few}", f"--workdir={tmp_path / 'out'}")
    assert result.returncode != 0 and "Traceback" not in result.stderr
    line = result.stderr.strip().splitlines()[-1]
    assert "--data_dir" in line and "push sequences: found 3, need at least" in line
    assert not (tmp_path / "out" / "report.json").exists()
