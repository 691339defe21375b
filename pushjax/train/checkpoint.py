"""Orbax checkpoints of a (stacked) train state plus JSON metadata.

Orbax writes each step into a temporary folder that it renames when complete, so a run killed while
saving leaves the previous checkpoint intact; :meth:`Checkpointer.restore_latest` returns the newest
complete one.

With several processes (`pushjax.train.distributed`) every process calls every method with the same
arguments; the state is saved from host copies, which orbax writes once (from process 0), so the folder
must be one that all processes see (a shared file system). A checkpoint restores on any number of
processes and devices.
"""

from __future__ import annotations

import logging
import os
from typing import Any

import jax
import numpy as np
import orbax.checkpoint as ocp
from absl import logging as absl_logging


class _OrbaxInfoFilter(logging.Filter):
    """Drops orbax's per-save INFO lines (hundreds per run) from the absl log; warnings pass."""

    def filter(self, record: logging.LogRecord) -> bool:
        return record.levelno >= logging.WARNING or f"{os.sep}orbax{os.sep}" not in record.pathname


absl_logging.get_absl_logger().addFilter(_OrbaxInfoFilter())


class Checkpointer:
    """Saves and restores ``(state, metadata)`` pairs under ``directory/<step>``.

    Args:
      directory: the checkpoint folder (created when missing, unless `read_only`).
      max_to_keep: newest checkpoints kept on disk.
      read_only: only restore; the folder is never written (e.g. a user's trained model, `pushjax.train.predictor`).
    """

    def __init__(self, directory: str | os.PathLike, max_to_keep: int = 2, read_only: bool = False):
        self._manager = ocp.CheckpointManager(
            os.path.abspath(directory),
            options=ocp.CheckpointManagerOptions(
                max_to_keep=None if read_only else max_to_keep, enable_async_checkpointing=False,
                create=not read_only, read_only=read_only, save_interval_steps=0 if read_only else 1,
            ),
            item_names=("state", "metadata"),
        )

    def latest_step(self) -> int | None:
        """Step of the newest complete checkpoint, or None."""
        return self._manager.latest_step()

    def save(self, step: int, state: Any, metadata: dict) -> None:
        """Writes `state` (a pytree of arrays, the same on every process) and JSON-serialisable `metadata` at `step`."""
        self._manager.save(
            step,
            args=ocp.args.Composite(
                state=ocp.args.StandardSave(jax.tree.map(np.asarray, state)),
                metadata=ocp.args.JsonSave(metadata),
            ),
            force=True,
        )
        self._manager.wait_until_finished()

    def all_steps(self) -> list[int]:
        """Steps of the complete checkpoints, oldest first."""
        return sorted(self._manager.all_steps())

    def latest_metadata(self) -> dict | None:
        """The metadata of the newest checkpoint (without reading its state), or None."""
        step = self.latest_step()
        if step is None:
            return None
        restored = self._manager.restore(step, args=ocp.args.Composite(metadata=ocp.args.JsonRestore()))
        return restored.metadata

    def restore_latest(self, abstract_state: Any) -> tuple[int, Any, dict] | None:
        """(step, state, metadata) of the newest checkpoint, or None when there is none.

        Args:
          abstract_state: a pytree with the state's structure, shapes and dtypes (e.g. the freshly
            initialised state, or `jax.eval_shape` of its constructor).
        """
        step = self.latest_step()
        if step is None:
            return None
        abstract = jax.tree.map(ocp.utils.to_shape_dtype_struct, abstract_state)
        restored = self._manager.restore(
            step,
            args=ocp.args.Composite(
                state=ocp.args.StandardRestore(abstract), metadata=ocp.args.JsonRestore()
            ),
        )
        return step, restored.state, restored.metadata

    def restore_arrays(self, step: int) -> tuple[Any, dict]:
        """(state, metadata) of the checkpoint at `step`, the state as saved (nested dicts of NumPy arrays), without
        needing its structure beforehand."""
        restored = self._manager.restore(
            step, args=ocp.args.Composite(state=ocp.args.StandardRestore(), metadata=ocp.args.JsonRestore()))
        return restored.state, restored.metadata

    def close(self) -> None:
        self._manager.close()
