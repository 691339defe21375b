"""Where the experiments' results live by default (one place for the binaries' docs and the notebooks), and
whether a folder given on the command line can take them.

``$PUSHJAX_RESULTS_DIR`` when it is set, else the ``work/`` folder of the source checkout pushjax runs from (the
folder the README's main command writes to: ``--workdir=work/data_efficiency``), or of the current folder when
pushjax is installed (``pip install .``). Each experiment's results are in
``<results dir>/<experiment>/results.json``. The git commit of the code (`git_commit`) is known in a checkout only.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
from pathlib import Path

RESULTS_DIR_VARIABLE = "PUSHJAX_RESULTS_DIR"


def source_checkout() -> Path | None:
    """The source tree pushjax is imported from (its ``pyproject.toml`` beside the package), or None when it is
    installed (site-packages)."""
    root = Path(__file__).resolve().parents[2]
    return root if (root / "pyproject.toml").is_file() and (root / "pushjax" / "__init__.py").is_file() else None


def results_dir() -> Path:
    """The folder holding one work directory per experiment."""
    return Path(os.environ.get(RESULTS_DIR_VARIABLE, (source_checkout() or Path.cwd()) / "work"))


def git_commit() -> str | None:
    """The git commit of the source checkout, ``+changes`` appended when its work tree differs from it; None when
    pushjax is installed, the checkout is not a git repository, or git is missing."""
    root = source_checkout()
    if root is None or not (root / ".git").exists():
        return None
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True,
                                check=True).stdout.strip()
        changed = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                                 capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return commit + ("+changes" if changed else "")


def check_writable_folder(path: str | os.PathLike) -> None:
    """Raises ``ValueError`` saying why not unless `path` is a folder files can be written in, or can be created.

    Leaves nothing behind: it opens a nameless temporary file in `path` or, when `path` does not exist yet, in
    its nearest existing parent.
    """
    if not os.fspath(path):
        raise ValueError("expected a folder, got an empty path")
    path = Path(path).absolute()
    existing = next(folder for folder in (path, *path.parents) if folder.exists())
    if not existing.is_dir():
        raise ValueError(f"expected a folder, but {existing} is a file")
    try:
        tempfile.TemporaryFile(dir=existing).close()
    except OSError as error:
        raise ValueError(f"expected a writable folder, but {existing} is not writable ({error.strerror})") from None
