"""The training logs of a sweep: ``metrics.csv`` and TensorBoard event files.

``metrics.csv`` (`MetricsLog`), one row per logged step and model. Columns: ``step`` (steps completed), ``model`` (index into the sweep's models), ``name`` (the model's
label) and the loss's metrics (``loss`` and its terms in mm / degrees, see `pushjax.train.losses`),
written with 6 significant digits. A resumed sweep keeps the rows up to its restored step and appends
after them, so the file of a killed and resumed run equals that of an uninterrupted one.

``tensorboard/`` (`TensorBoardLog`, written with tensorboardX, no TensorFlow): one TensorBoard run per model and
stream, ``tensorboard/<model name>/<stream>`` (``train``: the loss and its terms and steps per second, with the
training config as hparams; ``curves``: the learning curves of `pushjax.train.curves`). A resumed log marks the
step it resumes from, so TensorBoard drops what the killed run wrote from there on (its ``purge_step``), as
``metrics.csv`` drops those rows: ``tensorboard --logdir=<workdir>`` shows every sweep of a run.
"""

from __future__ import annotations

import csv
import dataclasses
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from tensorboardX import SummaryWriter
from tensorboardX.summary import hparams as hparams_summary


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


TENSORBOARD_DIR = "tensorboard"
"""The TensorBoard folder of a sweep's work directory."""
HParams = Mapping[str, "int | float | str | bool"]


class TensorBoardLog:
    """Scalars of K models, one TensorBoard run each: ``<folder>/<model name>/<stream>``.

    Args:
      folder: the sweep's TensorBoard folder (``<workdir>/tensorboard``).
      names: [K] the models' labels.
      stream: the runs' last folder, e.g. ``train`` or ``curves``.
      first_step: the first step this log writes. Events an earlier (killed) run wrote at this step or later are
        dropped when TensorBoard reads the runs; with 0, the runs' event files are removed first.
    """

    def __init__(self, folder: str | os.PathLike, names: Sequence[str], stream: str, first_step: int):
        self._writers = []
        for name in names:
            logdir = Path(folder) / name / stream
            if first_step == 0:
                for events in logdir.glob("events.out.tfevents.*"):
                    events.unlink()
            # tensorboardX names a file by the second it was opened: a run resumed within the same second would
            # overwrite the killed run's file without a suffix of its own (which also keeps the files in step order).
            self._writers.append(SummaryWriter(str(logdir), purge_step=first_step or None,
                                               filename_suffix=f".from_step_{first_step:010d}"))

    def write_hparams(self, hparams: Sequence[HParams], metric_tags: Sequence[str]) -> None:
        """Each model's hyperparameters ({name: int, float, str or bool}), linked to the scalars `metric_tags`."""
        for writer, model_hparams in zip(self._writers, hparams, strict=True):
            for summary in hparams_summary(dict(model_hparams), dict.fromkeys(metric_tags, 0.0)):
                writer.file_writer.add_summary(summary)

    def append(self, step: int, scalars: Mapping[str, np.ndarray]) -> None:
        """Writes {tag: [K] values} at `step`, one value per model, and flushes them to disk."""
        for k, writer in enumerate(self._writers):
            for tag, values in scalars.items():
                writer.add_scalar(tag, float(values[k]), step)
            writer.flush()

    def close(self) -> None:
        for writer in self._writers:
            writer.close()


def flat_hparams(config: object, prefix: str = "") -> dict[str, int | float | str | bool]:
    """A (nested) dataclass as TensorBoard hparams: ``{"learning_rate": 1e-3, "model.head_features": "(64, 32)"}``."""
    flat = {}
    for field in dataclasses.fields(config):
        value = getattr(config, field.name)
        if dataclasses.is_dataclass(value):
            flat.update(flat_hparams(value, f"{prefix}{field.name}."))
        else:
            flat[prefix + field.name] = value if isinstance(value, (int, float, str, bool)) else str(value)
    return flat
