"""Where the experiments' results live by default (one place for the binaries' docs and the notebooks), and
whether a folder given on the command line can take them.

``$PUSHJAX_RESULTS_DIR`` when it is set, else the ``work/`` folder of the source checkout pushjax runs from (the
folder the README's main command writes to: ``--workdir=work/data_efficiency``), or of the current folder when
pushjax is installed (``pip install .``). Each experiment's results are in
``<results dir>/<experiment>/results.json``. Where a record comes from: `pushjax.provenance`.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from pushjax.provenance import source_checkout

RESULTS_DIR_VARIABLE = "PUSHJAX_RESULTS_DIR"


def results_dir() -> Path:
    """The folder holding one work directory per experiment."""
    return Path(os.environ.get(RESULTS_DIR_VARIABLE, (source_checkout() or Path.cwd()) / "work"))


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
