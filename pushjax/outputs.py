"""An experiment's outputs in its work directory: ``results.json``, the markdown tables and one figure; a study's
``results.json`` and ``results.md`` (`write_report`), its numbers rounded to 7 digits (`compact`). Every
``results.json`` written here names the code that made it (``provenance``: `pushjax.provenance.write_source_diff`)."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Mapping
from pathlib import Path

from pushjax import provenance


def compact(value):
    """`value` (nested dicts, lists, tuples) with its floats rounded to 7 significant digits: records stay small and
    diff well."""
    if isinstance(value, float):
        return value if not math.isfinite(value) else float(f"{value:.7g}")
    if isinstance(value, dict):
        return {key: compact(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [compact(item) for item in value]
    return value


def write_report(workdir: str | os.PathLike, results: Mapping, markdown: str) -> list[Path]:
    """Writes ``results.json`` (`compact`) and ``results.md`` (`markdown`) to `workdir` (created); returns their
    paths."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    paths = [workdir / "results.json", workdir / "results.md"]
    paths[0].write_text(json.dumps(compact(_with_provenance(results, workdir)), indent=1) + "\n")
    paths[1].write_text(markdown)
    return paths


def write_results(workdir: str | os.PathLike, results: dict, tables: str, figure_name: str,
                  draw: Callable[[dict, Path], None]) -> list[Path]:
    """Writes ``results.json``, ``results.md`` (``tables``) and ``figure_name`` (``draw(results, path)``) to
    ``workdir`` (created); returns their paths."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    recorded = workdir / "results.json"
    recorded.write_text(json.dumps(_with_provenance(results, workdir), indent=1))
    return [recorded, *write_tables(workdir, results, tables, figure_name, draw)]


def write_tables(workdir: str | os.PathLike, results: Mapping, tables: str, figure_name: str,
                 draw: Callable[[dict, Path], None]) -> list[Path]:
    """Writes ``results.md`` (``tables``) and ``figure_name`` (``draw(results, path)``) to ``workdir`` (created),
    leaving ``results.json`` and the provenance of the run it records as they are (a published run's tables written
    again after a change of its report); returns their paths."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    paths = [workdir / "results.md", workdir / figure_name]
    paths[0].write_text(tables)
    draw(dict(results), paths[1])
    return paths


def _with_provenance(results: Mapping, workdir: Path) -> dict:
    """`results` with ``provenance``: the commit of the code writing them, and for changed code the diff beside them
    (nothing outside a git checkout)."""
    return {**results, "provenance": provenance.write_source_diff(workdir, provenance.source_state())}
