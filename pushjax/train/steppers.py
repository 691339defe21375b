"""How the one trainer (`pushjax.train.sweep_trainer.sweep`) steps K models of one architecture: their jitted
train step (one model's, vmapped, or unrolled; cached per model, optimiser and mode), and a stepper per mode that
holds the K models' state between steps (`make_stepper`; the modes are `SWEEP_MODES`, described in
`pushjax.train.sweep_trainer`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh

from pushjax.models import ERROR_OPTIONS, ModelConfig, PushModel
from pushjax.train import mesh as mesh_lib
from pushjax.train.batching import ModelSpec
from pushjax.train.train_state import TrainState, make_optimizer, make_train_step

SWEEP_MODES = ("vmap", "unroll", "sequential")
"""How a sweep steps its K models (see `pushjax.train.sweep_trainer`)."""


def error_options(config: ModelConfig, specs: Sequence[ModelSpec]) -> jax.Array | None:
    """[K, 2] per-model error-term flags, or None when no spec overrides the variant."""
    if all(spec.variant is None for spec in specs):
        return None
    if config.variant not in ERROR_OPTIONS:
        raise ValueError(
            f"specs: per-model variants need an error variant model, got variant {config.variant!r}"
        )
    return jnp.asarray([ERROR_OPTIONS[spec.variant or config.variant] for spec in specs], jnp.float32)


def stack(trees: Sequence[Any]) -> Any:
    """K pytrees of one structure -> one pytree whose leaves have a leading axis of size K."""
    return jax.tree.map(lambda *leaves: jnp.stack(leaves), *trees)


def unstack(tree: Any, count: int) -> list[Any]:
    """Inverse of `stack`: the `count` pytrees along the leading axis."""
    return [jax.tree.map(lambda leaf, k=k: leaf[k], tree) for k in range(count)]


@functools.lru_cache(maxsize=16)
def compiled_step(
    model_config: ModelConfig, physics: Callable | None, optimizer_settings: tuple[float, str, int | None, bool],
    weight_decay: float, mode: str, per_model_options: bool, mesh: Mesh | None = None,
):
    """The jitted train step of one model ("sequential") or of K stacked models ("vmap", "unroll").

    Cached, so that repeated runs with the same model and optimiser compile once.

    Args:
      model_config: the models' architecture and variant.
      physics: replaces `PushModel.physics`, or None for the default.
      optimizer_settings: (learning rate, schedule, number of steps or None, adjustable) of `make_optimizer`.
      weight_decay: weight of the loss's weight penalty.
      mode: one of `SWEEP_MODES`.
      per_model_options: whether the step takes [K, 2] per-model error-term flags (else None).
      mesh: for "vmap" and "unroll", the device mesh whose devices each step K/D of the models
        (arguments and outputs sharded with `mesh_lib.shard`), or None for one device.
    """
    model = PushModel(model_config) if physics is None else PushModel(model_config, physics)
    optimizer = make_optimizer(*optimizer_settings)
    train_step = make_train_step(model, optimizer, weight_decay)
    if mode == "sequential":
        return jax.jit(train_step)
    if mode == "vmap":
        step = jax.vmap(train_step, in_axes=(0, 0, 0 if per_model_options else None))
        return jax.jit(step if mesh is None else mesh_lib.map_models(step, mesh))

    def unrolled_step(states, batches, error_options):
        count = jax.tree.leaves(states)[0].shape[0]
        outputs = [
            train_step(
                jax.tree.map(lambda leaf: leaf[k], states), jax.tree.map(lambda leaf: leaf[k], batches),
                None if error_options is None else error_options[k],
            )
            for k in range(count)
        ]
        return stack([state for state, _ in outputs]), stack([metrics for _, metrics in outputs])

    return jax.jit(unrolled_step if mesh is None else mesh_lib.map_models(unrolled_step, mesh))


def with_learning_rate(state: TrainState, value: float) -> TrainState:
    """`state` (one model's or K models') whose adjustable learning rate (`make_optimizer`'s ``adjustable``) is
    `value` for every model."""
    opt_state = state.opt_state
    current = opt_state.hyperparams["learning_rate"]
    hyperparams = dict(opt_state.hyperparams, learning_rate=jnp.full(jnp.shape(current), value, jnp.float32))
    return state.replace(opt_state=opt_state._replace(hyperparams=hyperparams))


class _SequentialStepper:
    """``sequential``: the jitted single-model step once per model, the K states kept apart."""

    def __init__(self, step_fn: Callable, state: TrainState, specs: Sequence[ModelSpec], options: jax.Array | None):
        self._step_fn, self._options, self.local_specs = step_fn, options, list(specs)
        self._models = unstack(state, len(specs))

    def advance(self, batches: Sequence[Mapping[str, np.ndarray]]) -> dict[str, jax.Array]:
        """One step of every model on its batch; the [K] metrics."""
        outputs = [self._step_fn(model, batch, None if self._options is None else self._options[k])
                   for k, (model, batch) in enumerate(zip(self._models, batches))]
        self._models = [model for model, _ in outputs]
        return stack([metrics for _, metrics in outputs])

    def set_learning_rate(self, value: float) -> None:
        """Every model's adjustable learning rate (`with_learning_rate`) from the next step on."""
        self._models = [with_learning_rate(model, value) for model in self._models]

    def state(self) -> TrainState:
        """The K models' stacked state."""
        return stack(self._models)


class _StackedStepper:
    """``vmap`` / ``unroll`` on one device: one jitted step of the stacked state."""

    def __init__(self, step_fn: Callable, state: TrainState, specs: Sequence[ModelSpec], options: jax.Array | None,
                 fields: Sequence[str]):
        self._step_fn, self._options, self._fields, self.local_specs = step_fn, options, fields, list(specs)
        self._state = state

    def advance(self, batches: Sequence[Mapping[str, np.ndarray]]) -> dict[str, jax.Array]:
        batch = {name: np.stack([b[name] for b in batches]) for name in self._fields}
        self._state, metrics = self._step_fn(self._state, batch, self._options)
        return metrics

    def set_learning_rate(self, value: float) -> None:
        self._state = with_learning_rate(self._state, value)

    def state(self) -> TrainState:
        return self._state


class _ShardedStepper:
    """``vmap`` / ``unroll`` over a device mesh: the model axis padded to a multiple of the devices and sharded;
    this process steps its own rows (`mesh_lib.local_rows`), a padding row repeating the last model."""

    def __init__(self, step_fn: Callable, state: TrainState, specs: Sequence[ModelSpec], options: jax.Array | None,
                 fields: Sequence[str], mesh: Mesh):
        self._step_fn, self._fields, self._mesh, self._count = step_fn, fields, mesh, len(specs)
        self._padded = mesh_lib.padded_count(len(specs), mesh)
        self._options = None if options is None else mesh_lib.shard(mesh_lib.pad(options, self._padded),
                                                                    self._padded, mesh)
        self._state = mesh_lib.shard(mesh_lib.pad(state, self._padded), self._padded, mesh)
        self.local_specs = [specs[min(row, len(specs) - 1)] for row in mesh_lib.local_rows(self._padded, mesh)]

    def advance(self, batches: Sequence[Mapping[str, np.ndarray]]) -> dict[str, jax.Array]:
        batch = {name: np.stack([b[name] for b in batches]) for name in self._fields}
        self._state, metrics = self._step_fn(self._state, mesh_lib.shard(batch, self._padded, self._mesh),
                                             self._options)
        return mesh_lib.unshard(metrics, self._count, self._mesh)

    def set_learning_rate(self, value: float) -> None:
        self._state = mesh_lib.shard(mesh_lib.pad(with_learning_rate(self.state(), value), self._padded),
                                     self._padded, self._mesh)

    def state(self) -> TrainState:
        return mesh_lib.unshard(self._state, self._count, self._mesh)


def make_stepper(mode: str, step_fn: Callable, state: TrainState, specs: Sequence[ModelSpec],
                  options: jax.Array | None, fields: Sequence[str], mesh: Mesh | None):
    """The stepper of `mode` (one of `SWEEP_MODES`) starting from the K models' stacked `state`.

    Each has ``local_specs`` (the models whose batches this process draws, in row order), ``advance(batches)`` (one
    step; returns the K models' {name: [K]} metrics), ``set_learning_rate(value)`` (an adjustable learning rate, for
    the steps after it) and ``state()`` (the K models' stacked `TrainState`, on one device).
    """
    if mode == "sequential":
        return _SequentialStepper(step_fn, state, specs, options)
    if mesh is not None:
        return _ShardedStepper(step_fn, state, specs, options, fields, mesh)
    return _StackedStepper(step_fn, state, specs, options, fields)
