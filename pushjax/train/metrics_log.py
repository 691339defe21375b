"""``metrics.csv``: the training metrics of a sweep, one row per logged step and model.

Columns: ``step`` (steps completed), ``model`` (index into the sweep's models), ``name`` (the model's
label) and the loss's metrics (``loss`` and its terms in mm / degrees, see `pushjax.train.losses`),
written with 6 significant digits. A resumed sweep keeps the rows up to its restored step and appends
after them, so the file of a killed and resumed run equals that of an uninterrupted one.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np


class MetricsLog:
    """Appends rows to a ``metrics.csv``.

    Args:
      path: the CSV file (created on the first append).
      resume_step: the step training resumes from (0 for a fresh run). Rows of later steps are
        dropped; with 0, an existing file is removed.
    """

    def __init__(self, path: str | os.PathLike, resume_step: int):
        self._path = Path(path)
        rows = []
        if self._path.exists() and resume_step > 0:
            with self._path.open(newline="") as file:
                rows = [row for row in csv.DictReader(file) if int(row["step"]) <= resume_step]
        self._fieldnames = list(rows[0]) if rows else None
        if rows:
            self._write(rows, mode="w")
        elif self._path.exists():
            self._path.unlink()

    def _write(self, rows: Sequence[Mapping[str, object]], mode: str = "a") -> None:
        new_file = mode == "w" or not self._path.exists()
        if self._fieldnames is None:
            self._fieldnames = list(rows[0])
        with self._path.open(mode, newline="") as file:
            writer = csv.DictWriter(file, fieldnames=self._fieldnames)
            if new_file:
                writer.writeheader()
            writer.writerows(rows)

    def append(self, step: int, names: Sequence[str], metrics: Mapping[str, np.ndarray]) -> None:
        """Writes one row per model.

        Args:
          step: steps completed.
          names: [K] the models' labels.
          metrics: {name: [K] array} that step's metrics, one value per model.
        """
        self._write([
            {"step": step, "model": k, "name": name,
             **{metric: f"{float(values[k]):.6g}" for metric, values in metrics.items()}}
            for k, name in enumerate(names)
        ])
