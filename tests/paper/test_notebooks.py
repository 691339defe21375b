"""Every notebook under notebooks/ executes (nbclient) on the smoke results of its binary; the committed notebooks
show their outputs on the published results, and the command that re-executes them in place works."""

import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

from .conftest import RUNS

REPOSITORY = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((REPOSITORY / "notebooks").glob("*.ipynb"))
EXECUTE = REPOSITORY / "scripts" / "execute_notebooks.py"


def _binary(notebook: Path) -> str:
    source = "\n".join(cell.source for cell in nbformat.read(notebook, as_version=4).cells)
    return next(name for name in RUNS if f'/ "{name}" /' in source)


def _outputs(notebook: nbformat.NotebookNode) -> list:
    return [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]


def _has(notebook: nbformat.NotebookNode, mime: str) -> bool:
    return any(mime in output.get("data", {}) for output in _outputs(notebook))


def test_every_binary_has_a_notebook():
    assert {_binary(path) for path in NOTEBOOKS} == set(RUNS)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda path: path.stem)
def test_notebook_executes(path, smoke_results, monkeypatch):
    workdir = smoke_results(_binary(path))
    monkeypatch.setenv("PUSHJAX_RESULTS_DIR", str(workdir.parent))
    notebook = nbformat.read(path, as_version=4)
    NotebookClient(notebook, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}
                   ).execute()
    assert _has(notebook, "image/png")
    assert _has(notebook, "text/markdown")


def test_committed_notebooks_show_their_outputs():
    """Committed as `scripts/execute_notebooks.py` leaves them: outputs and figures, no errors, nothing volatile."""
    notebooks = {path.stem: nbformat.read(path, as_version=4) for path in NOTEBOOKS}
    assert len([name for name, notebook in notebooks.items() if _outputs(notebook)]) >= 8
    assert len([name for name, notebook in notebooks.items() if _has(notebook, "image/png")]) >= 5
    for name, notebook in notebooks.items():
        assert not [output for output in _outputs(notebook) if output.output_type == "error"], name
        assert not [output for output in _outputs(notebook) if output.get("name") == "stderr"], name
        assert not [cell for cell in notebook.cells if "execution" in cell.metadata], name
        assert notebook.metadata.get("language_info") == {"name": "python"}, name
    assert sum(path.stat().st_size for path in NOTEBOOKS) < 8 * 2 ** 20


def test_readme_pictures_exist():
    pictures = re.findall(r"!\[[^\]]*\]\(([^)\s]+)\)", (REPOSITORY / "README.md").read_text())
    assert len(pictures) >= 2
    assert [picture for picture in pictures if not (REPOSITORY / picture).is_file()] == []


def test_readme_figures_match_their_notebooks():
    execute_notebooks = _import_script()
    for notebook, figure in execute_notebooks.README_FIGURES.items():
        assert figure.read_bytes() == execute_notebooks.last_png(nbformat.read(notebook, as_version=4)), figure


def _import_script():
    sys.path.insert(0, str(EXECUTE.parent))
    try:
        import execute_notebooks
    finally:
        sys.path.remove(str(EXECUTE.parent))
    return execute_notebooks


def _execute(*arguments):
    result = subprocess.run([sys.executable, str(EXECUTE), *map(str, arguments)], capture_output=True, text=True,
                            timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    return result


def test_execute_notebooks_in_place(tmp_path):
    """The command re-executes copies in place on the committed results (a cheap notebook: viewpoint's), keeping
    the outputs; a second run changes nothing; an experiment without results says so instead of failing."""
    results = tmp_path / "results"
    results.mkdir()
    (results / "viewpoint").symlink_to(REPOSITORY / "results" / "viewpoint")  # visualize's results are missing
    present, missing = (tmp_path / "sec5_viewpoint.ipynb", tmp_path / "fig8_repeated_pushes.ipynb")
    for copy in (present, missing):
        notebook = nbformat.read(REPOSITORY / "notebooks" / copy.name, as_version=4)
        for cell in notebook.cells:
            if cell.cell_type == "code":
                cell.outputs, cell.execution_count = [], None
        nbformat.write(notebook, copy)
    _execute(f"--results_dir={results}", present, missing)
    executed = nbformat.read(present, as_version=4)
    assert _has(executed, "image/png") and _has(executed, "text/markdown")
    assert not [output for output in _outputs(executed) if output.get("name") == "stderr"]
    assert "execution" not in executed.cells[1].metadata
    assert executed.metadata == nbformat.read(REPOSITORY / "notebooks" / present.name, as_version=4).metadata
    said = [output.data["text/markdown"] for output in _outputs(nbformat.read(missing, as_version=4))]
    assert len(said) == 1 and said[0].startswith("**No results yet:**") and "visualize/results.json" in said[0]
    first = present.read_bytes()
    _execute(f"--results_dir={results}", present)
    assert present.read_bytes() == first
