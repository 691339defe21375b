"""The sweep trainer: K models of one architecture trained together, resumable from checkpoints.

A sweep trains K models that share one parameter structure (one `ModelConfig`), each on its own
training subset (`ModelSpec.train_indices`) with its own seed, e.g. several random subsets for each
of several training-set sizes (the paper averages over datasets of the same size), optionally mixing
the error-term variants. ``mode="vmap"`` (the default) updates all K models with one jit-compiled step,
the single-model step vmapped over the model axis; ``mode="unroll"`` repeats the single-model step K
times inside the one jitted step; ``mode="sequential"`` calls the jitted single-model step once per
model at every step. On XLA:CPU a vmapped convolution with per-model kernels becomes a slow grouped
convolution, and one model's convolutions already keep both cores busy, so ``sequential`` is the
fastest there (``benchmarks/sweep.py``, ``benchmarks/sweep_breakdown.py``). All modes checkpoint
the same stacked state, so a sweep can resume in another mode.

Devices: with more than one visible device, "vmap" and "unroll" split the model axis over a mesh of
all of them, at most K (`pushjax.train.mesh`): K models on D devices run K/D per device in the one
jitted step, the model axis padded to a multiple of D by repeating the last model. Logs, checkpoints
and the result hold the K models only, on one device, as with a single device, so a sweep resumes on
any number of devices. "sequential" and a single device run as without a mesh.

Processes: after `pushjax.train.distributed.initialize`, every process calls `sweep` with the same
arguments; "vmap" and "unroll" split the model axis over the devices of all processes, each process
draws the batches of its own models only, and every process gets the K models and their metrics
(gathered from all). Process 0 writes ``metrics.csv``; orbax writes each checkpoint once. A sweep
resumes on any number of processes and devices. "sequential" needs one process.

Determinism: model k is initialised from ``jax.random.key(spec.seed)`` and draws its batches in an
order that depends only on its spec and the step (`pushjax.train.batching.batch_indices`), so a sweep
resumed from a checkpoint replays exactly the batches of an uninterrupted run and ends with the same
parameters, and a model trained alone draws the same batches as inside a sweep.

Work directory layout: ``checkpoints/<step>/`` (orbax, `pushjax.train.checkpoint`: the stacked
`TrainState` and metadata: the models' identity and, under `MODEL_CONFIG_KEY` and `MODEL_VARIANTS_KEY`, their `ModelConfig` and variants, which
`pushjax.train.predictor.load_model` rebuilds them from) ``metrics.csv`` (one row per logged step and
model: step, model, name, loss and the loss's metrics in mm / degrees; `pushjax.train.metrics_log`) and
``tensorboard/<model name>/train`` (the same scalars and steps per second, the training config as hparams).
"""

from __future__ import annotations

import dataclasses
import functools
import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
import tqdm
from jax.sharding import Mesh

from pushjax.models import ERROR_OPTIONS, ModelConfig, PushModel
from pushjax.train import distributed, mesh as mesh_lib
from pushjax.train.batching import Examples, ModelSpec, batch_indices, gather, model_fields
from pushjax.train.checkpoint import Checkpointer
from pushjax.train.configs import TrainConfig
from pushjax.train.metrics_log import TENSORBOARD_DIR, MetricsLog, TensorBoardLog, flat_hparams
from pushjax.train.train_state import TrainState, create_train_state, make_optimizer, make_train_step

SWEEP_MODES = ("vmap", "unroll", "sequential")
"""How `sweep` steps its K models (see the module docstring)."""
MODEL_CONFIG_KEY = "model_config"
"""The checkpoint metadata's key of the models' `ModelConfig` (as `dataclasses.asdict`)."""
MODEL_VARIANTS_KEY = "model_variants"
"""The checkpoint metadata's key of each model's variant (they differ in a sweep that mixes the error variants)."""


def model_metadata(model_config: ModelConfig, specs: Sequence[ModelSpec]) -> dict:
    """What a checkpoint of `specs`' models holds beside their parameters: their identity (names, seeds, training
    subsets, variant), their `ModelConfig` and each one's variant, from which `pushjax.train.predictor.load_model`
    rebuilds them."""
    identity = {
        "names": [spec.name for spec in specs],
        "seeds": [spec.seed for spec in specs],
        "subset_sizes": [len(spec.train_indices) for spec in specs],
        "subset_checksums": [int(np.asarray(spec.train_indices, np.int64).sum()) for spec in specs],
        "variant": model_config.variant,
    }
    return {"identity": identity, MODEL_CONFIG_KEY: dataclasses.asdict(model_config),
            MODEL_VARIANTS_KEY: [spec.variant or model_config.variant for spec in specs]}


def _error_options(config: ModelConfig, specs: Sequence[ModelSpec]) -> jax.Array | None:
    """[K, 2] per-model error-term flags, or None when no spec overrides the variant."""
    if all(spec.variant is None for spec in specs):
        return None
    if config.variant not in ERROR_OPTIONS:
        raise ValueError(
            f"specs: per-model variants need an error variant model, got variant {config.variant!r}"
        )
    return jnp.asarray([ERROR_OPTIONS[spec.variant or config.variant] for spec in specs], jnp.float32)


def _stack(trees: Sequence[Any]) -> Any:
    """K pytrees of one structure -> one pytree whose leaves have a leading axis of size K."""
    return jax.tree.map(lambda *leaves: jnp.stack(leaves), *trees)


def _unstack(tree: Any, count: int) -> list[Any]:
    """Inverse of `_stack`: the `count` pytrees along the leading axis."""
    return [jax.tree.map(lambda leaf, k=k: leaf[k], tree) for k in range(count)]


@functools.lru_cache(maxsize=16)
def _compiled_step(
    model_config: ModelConfig, physics: Callable | None, optimizer_settings: tuple[float, str, int],
    weight_decay: float, mode: str, per_model_options: bool, mesh: Mesh | None = None,
):
    """The jitted train step of one model ("sequential") or of K stacked models ("vmap", "unroll").

    Cached, so that repeated runs with the same model and optimiser compile once.

    Args:
      model_config: the models' architecture and variant.
      physics: replaces `PushModel.physics`, or None for the default.
      optimizer_settings: (learning rate, schedule, number of steps or None) of `make_optimizer`.
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
        return _stack([state for state, _ in outputs]), _stack([metrics for _, metrics in outputs])

    return jax.jit(unrolled_step if mesh is None else mesh_lib.map_models(unrolled_step, mesh))


class WorkdirConflictError(ValueError):
    """A sweep's work directory that holds a checkpoint of other models; the message (``workdir: ...``) names it."""


class _SequentialStepper:
    """``sequential``: the jitted single-model step once per model, the K states kept apart."""

    def __init__(self, step_fn: Callable, state: TrainState, specs: Sequence[ModelSpec], options: jax.Array | None):
        self._step_fn, self._options, self.local_specs = step_fn, options, list(specs)
        self._models = _unstack(state, len(specs))

    def advance(self, batches: Sequence[Mapping[str, np.ndarray]]) -> dict[str, jax.Array]:
        """One step of every model on its batch; the [K] metrics."""
        outputs = [self._step_fn(model, batch, None if self._options is None else self._options[k])
                   for k, (model, batch) in enumerate(zip(self._models, batches))]
        self._models = [model for model, _ in outputs]
        return _stack([metrics for _, metrics in outputs])

    def state(self) -> TrainState:
        """The K models' stacked state."""
        return _stack(self._models)


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

    def state(self) -> TrainState:
        return mesh_lib.unshard(self._state, self._count, self._mesh)


def _make_stepper(mode: str, step_fn: Callable, state: TrainState, specs: Sequence[ModelSpec],
                  options: jax.Array | None, fields: Sequence[str], mesh: Mesh | None):
    """The stepper of `mode` (one of `SWEEP_MODES`) starting from the K models' stacked `state`.

    Each has ``local_specs`` (the models whose batches this process draws, in row order), ``advance(batches)`` (one
    step; returns the K models' {name: [K]} metrics) and ``state()`` (the K models' stacked `TrainState`, on one
    device).
    """
    if mode == "sequential":
        return _SequentialStepper(step_fn, state, specs, options)
    if mesh is not None:
        return _ShardedStepper(step_fn, state, specs, options, fields, mesh)
    return _StackedStepper(step_fn, state, specs, options, fields)


@dataclasses.dataclass(frozen=True)
class SweepResult:
    """Outcome of `sweep`.

    Attributes:
      model: the Flax module (shared by all models).
      specs: the K models.
      state: `TrainState` whose leaves have a leading axis of size K.
      final_metrics: {name: [K]} metrics of the last step taken in this call ({} when it took none,
        e.g. when resuming a finished sweep).
    """

    model: PushModel
    specs: list[ModelSpec]
    state: TrainState
    final_metrics: dict[str, np.ndarray]

    @property
    def steps_trained(self) -> np.ndarray:
        """[K] int steps each model has trained, restored ones included (read from `state`)."""
        return np.asarray(self.state.step)

    def model_state(self, index: int) -> TrainState:
        """The state of model `index` (in [0, K); leaves without the model axis)."""
        return jax.tree.map(lambda leaf: leaf[index], self.state)


def describe_specs(variant: str, specs: Sequence[ModelSpec]) -> str:
    """A short label of a sweep's models, e.g. ``hybrid: sizes 200,660 x seeds 0,1 (4 models)``."""
    variants = sorted({spec.variant or variant for spec in specs})
    sizes = sorted({len(spec.train_indices) for spec in specs})
    seeds = sorted({spec.seed for spec in specs})
    return (f"{','.join(variants)}: sizes {','.join(map(str, sizes))} x seeds {','.join(map(str, seeds))} "
            f"({len(specs)} models)")


def sweep(
    train_config: TrainConfig,
    examples: Examples,
    specs: Sequence[ModelSpec],
    workdir: str | os.PathLike | None = None,
    *,
    mode: str = "vmap",
    physics: Callable | None = None,
    progress: bool = True,
    description: str | None = None,
    step_callback: Callable[[int, Mapping[str, jax.Array]], None] | None = None,
    checkpoint_callback: Callable[[int, TrainState], None] | None = None,
) -> SweepResult:
    """Trains K = len(specs) models of `train_config.model` for `train_config.num_steps` steps.

    Args:
      train_config: model, optimiser and schedule.
      examples: the training split, {field: [N, ...] NumPy array} (schema fields; at least
        `model_fields`).
      specs: the models (subsets and seeds).
      workdir: folder for checkpoints and ``metrics.csv``; when it holds a checkpoint of the same
        specs, training resumes from it (in any mode). A checkpoint already past
        `train_config.num_steps` is returned as it is, with a warning naming the work directory, its
        step and the requested steps (`SweepResult.steps_trained` says how far the models trained).
        None: no checkpoints, no log.
      mode: one of `SWEEP_MODES`: "vmap" or "unroll": one jitted step for all K models, split
        over all visible devices when there are several (those of all processes); "sequential": the
        jitted single-model step once per model at every step, on one device of one process (see the
        module docstring).
      physics: replaces `PushModel.physics` (default `lynch.predict`).
      progress: show a progress bar with the running loss (mean over models), on process 0.
      description: the progress bar's label; by default the variants, subset sizes and seeds of `specs`.
      step_callback: called after every step with the number of completed steps and
        that step's metrics ({name: [K]} device arrays).
      checkpoint_callback: called with a step and the K models' stacked `TrainState` at that step: before
        training (at step 0, or at the step a resumed sweep restored, unless it is already finished) and after every
        checkpoint (every
        `train_config.checkpoint_every` steps and the last), also without a work directory; e.g. the
        learning curves of `pushjax.train.curves`.

    Returns:
      the `SweepResult`.
    """
    if not specs:
        raise ValueError("specs: expected at least one model")
    if mode not in SWEEP_MODES:
        raise ValueError(f"mode: expected one of {SWEEP_MODES}, got {mode!r}")
    if mode == "sequential" and jax.process_count() > 1:
        raise ValueError(f"mode: 'sequential' trains on one device; with {jax.process_count()} processes use "
                         "'vmap' or 'unroll'")
    model_config = train_config.model
    model = PushModel(model_config) if physics is None else PushModel(model_config, physics)
    # The constant schedule does not depend on the number of steps: sweeps of any length share a compiled step.
    decay_steps = train_config.num_steps if train_config.schedule != "constant" else None
    optimizer_settings = (train_config.learning_rate, train_config.schedule, decay_steps)
    optimizer = make_optimizer(*optimizer_settings)
    options = _error_options(model_config, specs)
    mesh = None if mode == "sequential" else mesh_lib.sweep_mesh(len(specs))
    step_fn = _compiled_step(
        model_config, physics, optimizer_settings, train_config.weight_decay, mode, options is not None, mesh,
    )
    fields = model_fields(model_config)
    num_examples = len(examples[fields[0]]) if fields[0] in examples else 0
    for spec in specs:
        if spec.train_indices.max(initial=0) >= num_examples or spec.train_indices.min() < 0:
            raise ValueError(f"specs: {spec.name!r} indexes outside the {num_examples} training examples")
    example_batch = gather(examples, batch_indices(specs[0], 0, train_config.batch_size), fields)

    def batch_at(spec, step):
        return gather(examples, batch_indices(spec, step, train_config.batch_size), fields)

    state = _stack([create_train_state(model, optimizer, example_batch, spec.seed) for spec in specs])
    start = 0
    checkpointer = log = tensorboard = None
    names = [spec.name for spec in specs]
    checkpoint_metadata = model_metadata(model_config, specs)
    identity = checkpoint_metadata["identity"]
    if workdir is not None:
        workdir = Path(workdir)
        workdir.mkdir(parents=True, exist_ok=True)
        checkpointer = Checkpointer(workdir / "checkpoints")
        metadata = checkpointer.latest_metadata()
        if metadata is not None:
            if metadata.get("identity") != identity:
                checkpointer.close()
                raise WorkdirConflictError(
                    f"workdir: {workdir} holds a checkpoint of different models "
                    f"({metadata.get('identity')}); use a fresh work directory"
                )
            start, state, _ = checkpointer.restore_latest(state)
            if jax.device_count() == 1:
                # Orbax returns arrays committed to the device, a fresh state's are not, and jax.jit keys its cache
                # on that: uncommitted, a resumed sweep reuses the train step a fresh one compiled in this process.
                state = jax.tree.map(lambda leaf: jnp.asarray(np.asarray(leaf)), state)
            if start > train_config.num_steps:
                warnings.warn(
                    f"workdir: {workdir} holds a checkpoint at step {start}, past the requested num_steps "
                    f"{train_config.num_steps}; the sweep returns the models as trained for {start} steps",
                    stacklevel=2)
        if distributed.is_writer():
            log = MetricsLog(workdir / "metrics.csv", start)
            tensorboard = TensorBoardLog(workdir / TENSORBOARD_DIR, names, "train", start and start + 1)
            config_hparams = flat_hparams(train_config)
            tensorboard.write_hparams(
                [{**config_hparams, "seed": spec.seed, "train_size": len(spec.train_indices),
                  "variant": spec.variant or model_config.variant} for spec in specs], ("loss",))
    stepper = _make_stepper(mode, step_fn, state, specs, options, fields, mesh)
    metrics = None
    try:
        if checkpoint_callback is not None and start < train_config.num_steps:
            checkpoint_callback(start, stepper.state())
        last_log = (start, time.perf_counter())
        with tqdm.tqdm(
            total=train_config.num_steps, initial=start, disable=not progress or not distributed.is_writer(),
            desc=description or describe_specs(model_config.variant, specs),
        ) as bar:
            for step in range(start, train_config.num_steps):
                metrics = stepper.advance([batch_at(spec, step) for spec in stepper.local_specs])
                done = step + 1
                bar.update(1)
                if done % train_config.log_every == 0 or done == train_config.num_steps:
                    host_metrics = jax.tree.map(np.asarray, metrics)
                    bar.set_postfix(loss=f"{host_metrics['loss'].mean():.3f}")
                    if log is not None:
                        log.append(done, names, host_metrics)
                        steps_per_second = (done - last_log[0]) / (time.perf_counter() - last_log[1])
                        tensorboard.append(
                            done, {**host_metrics, "steps_per_second": np.full(len(specs), steps_per_second)})
                    last_log = (done, time.perf_counter())
                if done % train_config.checkpoint_every == 0 or done == train_config.num_steps:
                    snapshot = stepper.state()
                    if checkpointer is not None:
                        checkpointer.save(done, snapshot, checkpoint_metadata)
                    if checkpoint_callback is not None:
                        checkpoint_callback(done, snapshot)
                if step_callback is not None:
                    step_callback(done, metrics)
    finally:
        if checkpointer is not None:
            checkpointer.close()
        if tensorboard is not None:
            tensorboard.close()
    final_metrics = {} if metrics is None else jax.tree.map(np.asarray, metrics)
    return SweepResult(model, list(specs), stepper.state(), final_metrics)
