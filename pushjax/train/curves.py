"""Learning curves: every model's error on its own training subset and on a validation split, against steps.

`LearningCurves` is a `sweep` ``checkpoint_callback``: at the start and at every checkpoint it evaluates each model
on up to ``train_config.curve_examples`` of its training examples and of each curve split (e.g. ``validation``),
in the paper's units (translation and rotation error in % of the ``zero`` baseline, `pushjax.train.evaluate`), and
appends the rows to ``curves.csv``: ``step, model, name, split, trans_percent, rot_percent``. A resumed sweep
restarts the file at its restored step, so the file of a killed and resumed run equals that of an uninterrupted
one. With a TensorBoard folder the same scores go to the run ``<folder>/<model name>/curves`` (tags
``<split>/trans_percent`` and ``<split>/rot_percent``, `pushjax.train.metrics_log.TensorBoardLog`). The examples are evenly spaced over the subset, so they cover all of its push sequences.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import jax
import numpy as np

from pushjax.models import ERROR_OPTIONS, PushModel
from pushjax.train import distributed
from pushjax.train.batching import Examples, ModelSpec
from pushjax.train.evaluate import evaluate
from pushjax.train.metrics_log import TensorBoardLog
from pushjax.train.train_state import TrainState

COLUMNS = ("step", "model", "name", "split", "trans_percent", "rot_percent")
TRAIN = "train"
"""The curve split of each model's own training examples."""


def _evenly_spaced(indices: np.ndarray, count: int) -> np.ndarray:
    return indices[np.unique(np.linspace(0, len(indices) - 1, min(count, len(indices))).round().astype(int))]


def _take(examples: Examples, indices: np.ndarray) -> Examples:
    return {name: values[indices] for name, values in examples.items()}


class LearningCurves:
    """Writes ``curves.csv`` for one sweep (see the module docstring).

    Args:
      path: the CSV file.
      model: the sweep's model.
      specs: the sweep's K models.
      train_examples: {field: [N, ...]} the training split the specs index.
      curve_sets: curve split name -> {field: [M, ...]} examples (e.g. the validation split); may be empty.
      max_examples: examples per model and split.
      batch_size: examples per evaluation call.
      tensorboard_dir: the sweep's TensorBoard folder (`pushjax.train.metrics_log.TENSORBOARD_DIR` in its work
        directory), or None for the CSV only.
    """

    def __init__(self, path: str | os.PathLike, model: PushModel, specs: Sequence[ModelSpec],
                 train_examples: Examples, curve_sets: Mapping[str, Examples], max_examples: int, batch_size: int,
                 tensorboard_dir: str | os.PathLike | None = None):
        self._path = Path(path)
        self._tensorboard_dir, self._tensorboard = tensorboard_dir, None
        self._model, self._specs, self._batch_size = model, list(specs), batch_size
        self._train_sets = [_take(train_examples, _evenly_spaced(np.sort(spec.train_indices), max_examples))
                            for spec in specs]
        self._curve_sets = {name: _take(examples, _evenly_spaced(np.arange(len(examples["motion"])), max_examples))
                            for name, examples in curve_sets.items()}
        self._started = False

    def _rows_before(self, step: int) -> list[dict]:
        if not self._path.exists():
            return []
        with self._path.open(newline="") as file:
            return [row for row in csv.DictReader(file) if int(row["step"]) < step]

    def __call__(self, step: int, state: TrainState) -> None:
        """Evaluates the K models of the stacked `state` at `step` and appends their rows (process 0 only)."""
        if not distributed.is_writer():
            return
        first_call, self._started = not self._started, True
        rows = self._rows_before(step) if first_call else []
        if first_call and self._tensorboard_dir is not None:
            self._tensorboard = TensorBoardLog(self._tensorboard_dir, [spec.name for spec in self._specs], "curves",
                                               step)
        scores = {}
        for k, spec in enumerate(self._specs):
            model_state = jax.tree.map(lambda leaf, k=k: leaf[k], state)
            options = None if spec.variant is None else np.asarray(ERROR_OPTIONS[spec.variant], np.float32)
            for split, examples in ((TRAIN, self._train_sets[k]), *self._curve_sets.items()):
                metrics = evaluate(self._model, model_state, examples, self._batch_size, options)
                rows.append({"step": step, "model": k, "name": spec.name, "split": split,
                             "trans_percent": f"{metrics['trans_percent']:.6g}",
                             "rot_percent": f"{metrics['rot_percent']:.6g}"})
                for metric in ("trans_percent", "rot_percent"):
                    scores.setdefault(f"{split}/{metric}", np.zeros(len(self._specs)))[k] = metrics[metric]
        if self._tensorboard is not None:
            self._tensorboard.append(step, scores)
        with self._path.open("w" if first_call else "a", newline="") as file:
            writer = csv.DictWriter(file, fieldnames=COLUMNS)
            if first_call:
                writer.writeheader()
            writer.writerows(rows)


def read(path: str | os.PathLike) -> list[dict]:
    """The rows of a ``curves.csv``, with ``step`` and ``model`` as int and the errors as float."""
    with Path(path).open(newline="") as file:
        return [{**row, "step": int(row["step"]), "model": int(row["model"]),
                 "trans_percent": float(row["trans_percent"]), "rot_percent": float(row["rot_percent"])}
                for row in csv.DictReader(file)]
