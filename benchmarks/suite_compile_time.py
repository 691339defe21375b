"""Where the test suite's time goes: CPU time, and XLA compilation against everything else, per test file.

A pytest plugin, run from the repository root:

    PYTHONPATH=benchmarks MUJOCO_GL=egl .venv/bin/python -m pytest -q -p suite_compile_time \
        --compile_report=work/suite_compile_time

Each process (every pytest-xdist worker) records, per test, its wall time, its CPU time (user + system, of the
worker and of the subprocesses the test started and waited for: a measure that other work on the machine does
not inflate the way it inflates wall time) and the seconds JAX spent in XLA backend compilation
(`jax.monitoring`'s backend-compile event; programs compiled by the subprocesses some tests start are not seen)
and writes `<compile_report>.<worker>.json`; the controller merges them into `<compile_report>.json` and prints
the totals and the 25 files with the most CPU time. A session fixture's work (e.g. a smoke dataset) counts
towards the first test that asks for it.
"""

from __future__ import annotations

import collections
import json
import os
import resource
import time
from pathlib import Path

import jax.monitoring
import pytest

_BACKEND_COMPILE = "/jax/core/compile/backend_compile_duration"
_compile_seconds = [0.0]
_rows: list[tuple[str, float, float, float]] = []


def _count_compilation(event: str, duration: float, **kwargs) -> None:
    if event == _BACKEND_COMPILE:
        _compile_seconds[0] += duration


jax.monitoring.register_event_duration_secs_listener(_count_compilation)


def pytest_addoption(parser):
    parser.addoption("--compile_report", default="suite_compile_time",
                     help="path prefix of the per-process and merged JSON reports")


def _cpu_seconds() -> float:
    """User + system CPU time of this process and of its waited-for children so far."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    compile_before, start, cpu_before = _compile_seconds[0], time.perf_counter(), _cpu_seconds()
    yield
    _rows.append((item.nodeid, time.perf_counter() - start, _compile_seconds[0] - compile_before,
                  _cpu_seconds() - cpu_before))


def pytest_sessionfinish(session):
    prefix = Path(session.config.getoption("compile_report"))
    prefix.parent.mkdir(parents=True, exist_ok=True)
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if worker:
        Path(f"{prefix}.{worker}.json").write_text(json.dumps(_rows))
        return
    rows = list(_rows)
    for path in sorted(prefix.parent.glob(f"{prefix.name}.gw*.json")):
        rows.extend(json.loads(path.read_text()))
        path.unlink()
    per_file = collections.defaultdict(lambda: [0.0, 0.0, 0.0])
    for node, seconds, compiling, cpu in rows:
        for index, value in enumerate((seconds, compiling, cpu)):
            per_file[node.split("::")[0]][index] += value
    Path(f"{prefix}.json").write_text(json.dumps({"tests": rows, "files": per_file}, indent=1))
    total, compiling, cpu = (sum(row[index] for row in rows) for index in (1, 2, 3))
    lines = [f"suite_compile_time: {len(rows)} tests, {cpu / 60:.1f} min of CPU time, {total / 60:.1f} min of test "
             f"time, of which XLA compilation {compiling / 60:.1f} min ({100 * compiling / max(total, 1e-9):.0f} %); "
             "costliest files (CPU s, %, wall s, compile s):"]
    for name, (seconds, compile_part, cpu_part) in sorted(per_file.items(), key=lambda item: -item[1][2])[:25]:
        lines.append(f"  {cpu_part:7.1f} {100 * cpu_part / max(cpu, 1e-9):4.1f} {seconds:7.1f} {compile_part:7.1f}"
                     f"  {name}")
    lines.append(f"suite_compile_time: wrote {prefix}.json")
    print("\n" + "\n".join(lines))
