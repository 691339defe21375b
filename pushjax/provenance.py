"""Where a record comes from: the git commit of the code that made it, and the diff of changed code kept beside it.

The commit is known in a source checkout only (`source_checkout`); a record made from changed code names the commit
with ``+changes`` and keeps the diff in its work directory (`write_source_diff`), so that the code behind it can be
rebuilt. Every experiment record written through `pushjax.outputs` carries it as ``provenance``.
"""

from __future__ import annotations

import hashlib
import os
import subprocess
from collections.abc import Mapping
from pathlib import Path

import numpy as np


def source_checkout() -> Path | None:
    """The source tree pushjax is imported from (its ``pyproject.toml`` beside the package), or None when it is
    installed (site-packages)."""
    root = Path(__file__).resolve().parents[1]
    return root if (root / "pyproject.toml").is_file() and (root / "pushjax" / "__init__.py").is_file() else None


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


DATA_FILE_PATTERN = "*.array_record-*"
"""The data files of a built dataset (TFDS's ``array_record`` shards): what a model trained on and was scored on."""


def file_digests(folder: str | os.PathLike, pattern: str = DATA_FILE_PATTERN) -> dict[str, str]:
    """{file name: sha256 hex digest} of the files of `folder` matching `pattern`, sorted by name."""
    digests = {}
    for path in sorted(Path(folder).glob(pattern)):
        digest = hashlib.sha256()
        with path.open("rb") as file:
            for block in iter(lambda: file.read(1 << 20), b""):
                digest.update(block)
        digests[path.name] = digest.hexdigest()
    return digests


def digests_text(digests: dict[str, str]) -> str:
    """`file_digests` in ``sha256sum``'s format (``<digest>  <name>`` a line), which ``sha256sum -c`` checks."""
    return "".join(f"{digest}  {name}\n" for name, digest in digests.items())


def parse_digests(text: str) -> dict[str, str]:
    """The {file name: digest} of a ``sha256sum``-format text (`digests_text`)."""
    return {name: digest for digest, _, name in (line.partition("  ") for line in text.splitlines() if line.strip())}


def tree_digest(tree: Mapping) -> str:
    """sha256 hex digest of nested mappings of arrays (e.g. a model's variables): every leaf's path, dtype, shape and
    bytes in the order of its sorted keys, so that two trees have one digest exactly when they are bit-identical."""
    digest = hashlib.sha256()

    def add(node, path: str) -> None:
        if isinstance(node, Mapping):
            for key in sorted(node):
                add(node[key], f"{path}/{key}")
            return
        value = np.ascontiguousarray(np.asarray(node))
        digest.update(f"{path}:{value.dtype.str}:{value.shape};".encode())
        digest.update(value.tobytes())

    add(tree, "")
    return digest.hexdigest()
