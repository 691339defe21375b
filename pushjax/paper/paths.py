"""Where the experiments' results live by default (one place for the binaries' docs and the notebooks), and
whether a folder given on the command line can take them.

``$PUSHJAX_RESULTS_DIR`` when it is set, else the ``work/`` folder of the source checkout pushjax runs from (the
folder the README's main command writes to: ``--workdir=work/data_efficiency``), or of the current folder when
pushjax is installed (``pip install .``). Each experiment's results are in
``<results dir>/<experiment>/results.json``. The git commit of the code (`git_commit`, `source_state`) is known in a
checkout only; a record made from changed code keeps the diff beside it (`write_source_diff`).
"""

from __future__ import annotations

import hashlib
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


SOURCE_PATHS = ("pushjax", "experiments", "pyproject.toml")
"""The files whose state a result's provenance records: the code that made it, not the results beside it."""
PROVENANCE_DIR = "provenance"
"""The folder of a work directory holding the source diffs its records name (`write_source_diff`)."""


def source_state(root: str | os.PathLike | None = None) -> dict | None:
    """The git commit of the source checkout `root` (default: `source_checkout`) and how its code differs from it.

    Returns {"commit": the HEAD commit, "clean": whether `SOURCE_PATHS` match it (a result tree's own changes do not
    count), "diff": ``git diff HEAD`` of those paths followed by every untracked file under them, "" when clean}; None
    when pushjax is installed, the checkout is not a git repository, or git is missing."""
    root = Path(root) if root is not None else source_checkout()
    if root is None or not (root / ".git").exists():
        return None

    def git(*arguments: str) -> str:
        return subprocess.run(["git", *arguments], cwd=root, capture_output=True, text=True, check=True).stdout

    try:
        commit = git("rev-parse", "HEAD").strip()
        diff = git("diff", "HEAD", "--", *SOURCE_PATHS)
        untracked = git("ls-files", "--others", "--exclude-standard", "--", *SOURCE_PATHS).split()
    except (OSError, subprocess.CalledProcessError):
        return None
    for name in sorted(untracked):
        text = (root / name).read_text(errors="replace")
        diff += f"--- /dev/null\n+++ b/{name} (untracked)\n" + "".join(f"+{line}\n" for line in text.splitlines())
    return {"commit": commit, "clean": not diff, "diff": diff}


def git_commit(root: str | os.PathLike | None = None) -> str | None:
    """The git commit of the source checkout, ``+changes`` appended when its code (`SOURCE_PATHS`) differs from it;
    None when pushjax is installed, the checkout is not a git repository, or git is missing."""
    state = source_state(root)
    return None if state is None else state["commit"] + ("" if state["clean"] else "+changes")


def write_source_diff(workdir: str | os.PathLike, state: dict | None) -> dict:
    """A record's provenance from `state` (`source_state`): {"commit": ...} for a clean checkout; for a changed one
    also {"source_diff": "provenance/<sha256 of the diff, 16 hex>.diff"}, the diff written there (once per diff) so
    that the code behind the record can be rebuilt from the commit and the diff; {} without a checkout."""
    if state is None:
        return {}
    if state["clean"]:
        return {"commit": state["commit"]}
    digest = hashlib.sha256(state["diff"].encode()).hexdigest()[:16]
    relative = f"{PROVENANCE_DIR}/{state['commit'][:12]}-{digest}.diff"
    path = Path(workdir) / relative
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(state["diff"])
    return {"commit": state["commit"] + "+changes", "source_diff": relative}


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
