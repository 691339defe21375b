"""Every notebook under notebooks/ executes (nbclient) on the smoke results of its binary."""

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

from .conftest import RUNS

NOTEBOOKS = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("*.ipynb"))


def _binary(notebook: Path) -> str:
    source = "\n".join(cell.source for cell in nbformat.read(notebook, as_version=4).cells)
    return next(name for name in RUNS if f'/ "{name}" /' in source)


def test_every_binary_has_a_notebook():
    assert {_binary(path) for path in NOTEBOOKS} == set(RUNS)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_notebook_executes(path, smoke_results, monkeypatch):
    workdir = smoke_results(_binary(path))
    monkeypatch.setenv("PUSHJAX_RESULTS_DIR", str(workdir.parent))
    notebook = nbformat.read(path, as_version=4)
    NotebookClient(notebook, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}
                   ).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert any("image/png" in output.get("data", {}) for output in outputs)
    assert any("text/markdown" in output.get("data", {}) for output in outputs)
