"""An experiment's outputs in its work directory: ``results.json``, the markdown tables and one figure."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path


def write_results(workdir: str | os.PathLike, results: dict, tables: str, figure_name: str,
                  draw: Callable[[dict, Path], None]) -> list[Path]:
    """Writes ``results.json``, ``results.md`` (``tables``) and ``figure_name`` (``draw(results, path)``) to
    ``workdir`` (created); returns their paths."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    paths = [workdir / "results.json", workdir / "results.md", workdir / figure_name]
    paths[0].write_text(json.dumps(results, indent=1))
    paths[1].write_text(tables)
    draw(results, paths[2])
    return paths
