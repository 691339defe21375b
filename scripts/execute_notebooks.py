"""Re-executes the notebooks in place, keeping their outputs, on the committed results (no training).

    .venv/bin/python scripts/execute_notebooks.py [--results_dir=results] [--timeout=600] [NOTEBOOK ...]

Runs every notebook under ``notebooks/`` (or the ones named) in a fresh kernel, one after the other, with
``PUSHJAX_RESULTS_DIR`` set to ``--results_dir`` (default: the repository's ``results/``, the published results
behind RESULTS.md), ``MUJOCO_GL=egl`` (unless set) and ``PYTHONHASHSEED=0``, and writes each back with its
outputs. A notebook whose experiment has no ``results.json`` there says so in its output instead of failing. The
README's picture of a notebook's figure (``README_FIGURES``) is written again with it.

Written so that a second run on unchanged results changes nothing: no execution timings are recorded, the
notebook's own metadata is kept (not the kernel's Python version), and stderr streams (log lines with their times,
library warnings) are dropped; outputs, execution counts and figures are those of the run. A notebook that raises
is left as it was, named on stderr, and the exit status is 1.
"""

from __future__ import annotations

import argparse
import base64
import copy
import os
import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError, CellTimeoutError

REPOSITORY = Path(__file__).resolve().parents[1]
NOTEBOOKS = REPOSITORY / "notebooks"
README_FIGURES = {NOTEBOOKS / "use_a_trained_model.ipynb": REPOSITORY / "docs" / "use_a_trained_model.png"}
"""notebook -> the file its last PNG output is copied to (the README shows it)."""


def strip_volatile(notebook: nbformat.NotebookNode, metadata: dict) -> nbformat.NotebookNode:
    """`notebook` with `metadata` as its metadata, no per-cell execution records and no stderr streams."""
    notebook.metadata = nbformat.from_dict(copy.deepcopy(metadata))
    for cell in notebook.cells:
        cell.metadata.pop("execution", None)
        if cell.cell_type == "code":
            cell.outputs = [output for output in cell.outputs
                            if not (output.output_type == "stream" and output.name == "stderr")]
    return notebook


def last_png(notebook: nbformat.NotebookNode) -> bytes | None:
    """The last PNG among `notebook`'s outputs, None without one."""
    found = [output.data["image/png"] for cell in notebook.cells if cell.cell_type == "code"
             for output in cell.outputs if "image/png" in output.get("data", {})]
    return base64.b64decode(found[-1]) if found else None


def execute(path: Path, timeout: int) -> nbformat.NotebookNode:
    """The notebook at `path` executed in a fresh ``python3`` kernel started in its folder (raises on an error)."""
    notebook = nbformat.read(path, as_version=4)
    metadata = copy.deepcopy(dict(notebook.metadata))
    NotebookClient(notebook, timeout=timeout, kernel_name="python3", record_timing=False,
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    return strip_volatile(notebook, metadata)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("notebooks", nargs="*", type=Path, help="default: every notebooks/*.ipynb")
    parser.add_argument("--results_dir", type=Path, default=REPOSITORY / "results",
                        help="the folder of one work directory per experiment (PUSHJAX_RESULTS_DIR); "
                             "default: the repository's results/")
    parser.add_argument("--timeout", type=int, default=600, help="seconds a cell may run")
    args = parser.parse_args(argv)
    paths = args.notebooks or sorted(NOTEBOOKS.glob("*.ipynb"))
    if not args.results_dir.is_dir():
        print(f"error: --results_dir: expected a folder, got {args.results_dir}", file=sys.stderr)
        return 2
    os.environ["PUSHJAX_RESULTS_DIR"] = str(args.results_dir.resolve())
    os.environ.setdefault("MUJOCO_GL", "egl")
    # The kernels' string hashing, fixed: an order that follows a set of names (a figure's panels) is then the same
    # in every run.
    os.environ["PYTHONHASHSEED"] = "0"
    failed = []
    started = time.perf_counter()
    for path in paths:
        begin = time.perf_counter()
        try:
            notebook = execute(path, args.timeout)
        except (CellExecutionError, CellTimeoutError) as error:
            failed.append(path)
            print(f"{path}: failed, left as it was\n{error}", file=sys.stderr)
            continue
        nbformat.write(notebook, path)
        figure = README_FIGURES.get(path.resolve())
        if figure is not None and last_png(notebook) is not None:
            figure.parent.mkdir(exist_ok=True)
            figure.write_bytes(last_png(notebook))
        print(f"{path}: {time.perf_counter() - begin:.0f} s, {path.stat().st_size / 1024:.0f} KiB", flush=True)
    print(f"{len(paths) - len(failed)} of {len(paths)} notebooks executed in {time.perf_counter() - started:.0f} s "
          f"on {args.results_dir}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
