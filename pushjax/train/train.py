"""Training: train state, one optimisation step, and the sweep trainer of K models.

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

Determinism: model k is initialised from ``jax.random.key(spec.seed)``; its batch at step t is a pure
function of (spec.seed, spec.train_indices, t) (`batch_indices`), so a sweep resumed from a checkpoint
replays exactly the batches of an uninterrupted run and ends with the same parameters, and a model
trained alone draws the same batches as inside a sweep.

Work directory layout: ``checkpoints/<step>/`` (orbax) and ``metrics.csv`` (one row per logged step
and model: step, model, name, loss and the loss's metrics in mm / degrees).
"""

from __future__ import annotations

import csv
import dataclasses
import functools
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
import optax
import tqdm
from flax import struct

from pushjax.data import schema
from pushjax.models.networks import ERROR_OPTIONS, ModelConfig, PushModel
from pushjax.train import losses
from pushjax.train.checkpoint import Checkpointer
from pushjax.train.configs import TrainConfig

Batch = Mapping[str, Any]
Examples = Mapping[str, np.ndarray]

MODEL_INPUT_FIELDS = (
    "pusher_pos", "pusher_pixel", "action", "object_pos", "motion", "contact", "normal",
    "contact_flag", "l", "mu", "camera_intrinsics", "camera_extrinsics",
)
"""Batch fields the models and losses read, besides the image (`ModelConfig.image_field`)."""
SWEEP_MODES = ("vmap", "unroll", "sequential")
_DATA_STREAM = 1
"""Separates the batch-order random stream from other uses of a model's seed."""


@struct.dataclass
class TrainState:
    """Optimisation state of one model (or of K models, every leaf with a leading model axis).

    Attributes:
      step: [] int32 number of steps taken.
      params: Flax `params` collection.
      batch_stats: Flax `batch_stats` collection (running batch-norm statistics; {} when none).
      opt_state: optax state.
    """

    step: jax.Array
    params: Any
    batch_stats: Any
    opt_state: Any


@dataclasses.dataclass(frozen=True, eq=False)
class ModelSpec:
    """One model of a sweep.

    Attributes:
      name: label in logs and results, e.g. ``"size=100/seed=2"``.
      train_indices: [N_k] int indices of its training examples into the training split.
      seed: initialisation and batch-order seed.
      variant: error-term variant (a key of `ERROR_OPTIONS`) to use for this model when the
        sweep's model variant is an error variant, or None for the config's variant.
    """

    name: str
    train_indices: np.ndarray
    seed: int
    variant: str | None = None

    def __post_init__(self):
        indices = np.asarray(self.train_indices)
        if indices.ndim != 1 or indices.size == 0 or not np.issubdtype(indices.dtype, np.integer):
            raise ValueError(f"train_indices of {self.name!r}: expected a non-empty 1-D integer array")
        if self.variant is not None and self.variant not in ERROR_OPTIONS:
            raise ValueError(f"variant of {self.name!r}: expected one of {tuple(ERROR_OPTIONS)} or None")


def subset_specs(
    num_examples: int, sizes: Sequence[int], seeds: Sequence[int], variants: Sequence[str | None] = (None,)
) -> list[ModelSpec]:
    """One `ModelSpec` per (size, seed, variant): a random training subset of `size` examples.

    The subset of (size, seed) is drawn without replacement by ``np.random.default_rng([seed, size])``
    and shared by the variants; the model's seed is `seed`.

    Args:
      num_examples: size of the training split.
      sizes: training-set sizes, each in [1, num_examples].
      seeds: subset (and model) seeds, >= 0.
      variants: error-term variants to mix (see `ModelSpec.variant`).
    """
    specs = []
    for size in sizes:
        if not 1 <= size <= num_examples:
            raise ValueError(f"sizes: expected sizes in [1, {num_examples}], got {size}")
        for seed in seeds:
            if seed < 0:
                raise ValueError(f"seeds: expected seeds >= 0, got {seed}")
            rng = np.random.default_rng([seed, size])
            indices = np.sort(rng.choice(num_examples, size, replace=False))
            for variant in variants:
                name = f"size={size}/seed={seed}" + (f"/{variant}" if variant else "")
                specs.append(ModelSpec(name, indices, seed, variant))
    return specs


@functools.lru_cache(maxsize=64)
def _epoch_permutation(seed: int, epoch: int, size: int) -> np.ndarray:
    return np.random.default_rng([seed, _DATA_STREAM, epoch]).permutation(size)


def batch_indices(spec: ModelSpec, step: int, batch_size: int) -> np.ndarray:
    """[batch_size] training-split indices of `spec`'s batch at `step`.

    The model walks through its subset in epochs, each a fresh permutation drawn from (seed, epoch);
    batch t holds positions t * batch_size ... of that endless sequence.
    """
    size = len(spec.train_indices)
    positions = step * batch_size + np.arange(batch_size)
    epochs = positions // size
    order = np.empty(batch_size, dtype=np.int64)
    for epoch in np.unique(epochs):
        selected = epochs == epoch
        order[selected] = _epoch_permutation(spec.seed, int(epoch), size)[positions[selected] % size]
    return np.asarray(spec.train_indices)[order]


def model_fields(config: ModelConfig) -> tuple[str, ...]:
    """The batch fields a model of `config` and its loss read."""
    return (config.image_field, *MODEL_INPUT_FIELDS)


EVALUATION_FIELDS = ("push_velocity",)
"""Fields evaluation reads besides `model_fields`."""


def gather(examples: Examples, indices: np.ndarray, fields: Sequence[str]) -> dict[str, np.ndarray]:
    """The examples at `indices` ([...] ints) of the chosen `fields`, as a batch."""
    missing = [name for name in fields if name not in examples]
    if missing:
        raise ValueError(f"examples: missing fields {missing}")
    return {name: examples[name][indices] for name in fields}


def examples_from_source(source: Sequence[Mapping[str, Any]], fields: Sequence[str]) -> dict[str, np.ndarray]:
    """All examples of a random-access source (e.g. a `pushjax.data.load` split) as in-memory arrays.

    Args:
      source: ``len`` and ``[i]`` (``__getitems__`` when present) giving dicts of arrays.
      fields: the fields to keep (e.g. `model_fields` plus what evaluation reads).

    Returns:
      {field: [N, ...] array} with the dtypes of `pushjax.data.schema.FIELDS`.
    """
    count = len(source)
    if count == 0:
        raise ValueError("source: expected at least one example")
    read = getattr(source, "__getitems__", None) or (lambda keys: [source[key] for key in keys])
    chunks = {name: [] for name in fields}
    for start in range(0, count, 1024):
        for example in read(list(range(start, min(start + 1024, count)))):
            for name in fields:
                chunks[name].append(example[name])
    return {name: np.asarray(values, dtype=schema.FIELDS[name].dtype) for name, values in chunks.items()}


def make_optimizer(learning_rate: float) -> optax.GradientTransformation:
    """The paper's optimiser: Adam with step size `learning_rate`."""
    return optax.adam(learning_rate)


def create_train_state(
    model: PushModel, optimizer: optax.GradientTransformation, example_batch: Batch, seed: int
) -> TrainState:
    """A freshly initialised state.

    Args:
      model: the model.
      optimizer: the optax transformation.
      example_batch: a batch with the model's fields (only shapes matter).
      seed: initialisation seed.
    """
    variables = model.init(jax.random.key(seed), example_batch, train=False)
    params = variables["params"]
    return TrainState(
        step=jnp.zeros((), jnp.int32),
        params=params,
        batch_stats=variables.get("batch_stats", {}),
        opt_state=optimizer.init(params),
    )


def make_train_step(
    model: PushModel, optimizer: optax.GradientTransformation, weight_decay: float
) -> Callable[[TrainState, Batch, jax.Array | None], tuple[TrainState, dict[str, jax.Array]]]:
    """The pure function ``train_step(state, batch, error_options) -> (state, metrics)``.

    ``error_options`` is None (use the variant's) or the [2] flags of `PushModel.__call__`. Not jitted:
    jit it, or vmap and then jit it for a sweep.
    """
    loss_fn = losses.loss_for(model.config.variant, model.config.view)

    def train_step(state: TrainState, batch: Batch, error_options: jax.Array | None = None):
        def objective(params):
            predictions, updates = model.apply(
                {"params": params, "batch_stats": state.batch_stats}, batch, train=True,
                error_options=error_options, mutable=["batch_stats"],
            )
            loss, metrics = loss_fn(predictions, batch, params, weight_decay)
            return loss, (metrics, updates.get("batch_stats", {}))

        gradients, (metrics, batch_stats) = jax.grad(objective, has_aux=True)(state.params)
        updates, opt_state = optimizer.update(gradients, state.opt_state, state.params)
        new_state = TrainState(
            step=state.step + 1,
            params=optax.apply_updates(state.params, updates),
            batch_stats=batch_stats,
            opt_state=opt_state,
        )
        return new_state, metrics

    return train_step


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
    return jax.tree.map(lambda *leaves: jnp.stack(leaves), *trees)


def _unstack(tree: Any, count: int) -> list[Any]:
    return [jax.tree.map(lambda leaf, k=k: leaf[k], tree) for k in range(count)]


@functools.lru_cache(maxsize=16)
def _compiled_step(
    model_config: ModelConfig, physics: Callable | None, learning_rate: float, weight_decay: float,
    mode: str, per_model_options: bool,
):
    """The jitted train step of one model ("sequential") or of K stacked models ("vmap", "unroll").

    Cached, so that repeated runs with the same model and optimiser compile once.
    """
    model = PushModel(model_config) if physics is None else PushModel(model_config, physics)
    optimizer = make_optimizer(learning_rate)
    train_step = make_train_step(model, optimizer, weight_decay)
    if mode == "sequential":
        return jax.jit(train_step)
    if mode == "vmap":
        return jax.jit(jax.vmap(train_step, in_axes=(0, 0, 0 if per_model_options else None)))

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

    return jax.jit(unrolled_step)


@dataclasses.dataclass(frozen=True)
class SweepResult:
    """Outcome of `sweep`.

    Attributes:
      model: the Flax module (shared by all models).
      specs: the K models.
      state: `TrainState` whose leaves have a leading axis of size K.
      final_metrics: {name: [K]} metrics of the last step.
    """

    model: PushModel
    specs: list[ModelSpec]
    state: TrainState
    final_metrics: dict[str, np.ndarray]

    def model_state(self, index: int) -> TrainState:
        """The state of model `index` (leaves without the model axis)."""
        return jax.tree.map(lambda leaf: leaf[index], self.state)


class _MetricsLog:
    """``metrics.csv`` in the work directory; on resume, rows after the restored step are dropped."""

    def __init__(self, path: Path, resume_step: int):
        self._path = path
        rows = []
        if path.exists() and resume_step > 0:
            with path.open(newline="") as file:
                rows = [row for row in csv.DictReader(file) if int(row["step"]) <= resume_step]
        self._fieldnames = list(rows[0]) if rows else None
        if rows:
            self._write(rows, mode="w")
        elif path.exists():
            path.unlink()

    def _write(self, rows, mode="a"):
        new_file = mode == "w" or not self._path.exists()
        if self._fieldnames is None:
            self._fieldnames = list(rows[0])
        with self._path.open(mode, newline="") as file:
            writer = csv.DictWriter(file, fieldnames=self._fieldnames)
            if new_file:
                writer.writeheader()
            writer.writerows(rows)

    def append(self, step: int, specs: Sequence[ModelSpec], metrics: Mapping[str, np.ndarray]):
        self._write([
            {"step": step, "model": k, "name": spec.name,
             **{name: f"{float(values[k]):.6g}" for name, values in metrics.items()}}
            for k, spec in enumerate(specs)
        ])


def sweep(
    train_config: TrainConfig,
    examples: Examples,
    specs: Sequence[ModelSpec],
    workdir: str | os.PathLike | None = None,
    *,
    mode: str = "vmap",
    physics: Callable | None = None,
    progress: bool = True,
    step_callback: Callable[[int, Mapping[str, jax.Array]], None] | None = None,
) -> SweepResult:
    """Trains K = len(specs) models of `train_config.model` for `train_config.num_steps` steps.

    Args:
      train_config: model, optimiser and schedule.
      examples: the training split as NumPy arrays with a leading example axis (schema fields; at
        least `model_fields`).
      specs: the models (subsets and seeds).
      workdir: folder for checkpoints and ``metrics.csv``; when it holds a checkpoint of the same
        specs, training resumes from it (in any mode). None: no checkpoints, no log.
      mode: "vmap" or "unroll": one jitted step for all K models; "sequential": the jitted single-model step
        once per model at every step (see the module docstring).
      physics: replaces `PushModel.physics` (default `lynch.predict`).
      progress: show a progress bar with the running loss (mean over models).
      step_callback: called after every step with the number of completed steps and
        that step's metrics ({name: [K]} device arrays).

    Returns:
      the `SweepResult`.
    """
    if not specs:
        raise ValueError("specs: expected at least one model")
    if mode not in SWEEP_MODES:
        raise ValueError(f"mode: expected one of {SWEEP_MODES}, got {mode!r}")
    model_config = train_config.model
    model = PushModel(model_config) if physics is None else PushModel(model_config, physics)
    optimizer = make_optimizer(train_config.learning_rate)
    options = _error_options(model_config, specs)
    step_fn = _compiled_step(
        model_config, physics, train_config.learning_rate, train_config.weight_decay, mode,
        options is not None,
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
    checkpointer = log = None
    identity = {
        "names": [spec.name for spec in specs],
        "seeds": [spec.seed for spec in specs],
        "subset_sizes": [len(spec.train_indices) for spec in specs],
        "subset_checksums": [int(np.asarray(spec.train_indices, np.int64).sum()) for spec in specs],
        "variant": model_config.variant,
    }
    if workdir is not None:
        workdir = Path(workdir)
        workdir.mkdir(parents=True, exist_ok=True)
        checkpointer = Checkpointer(workdir / "checkpoints")
        metadata = checkpointer.latest_metadata()
        if metadata is not None:
            if metadata.get("identity") != identity:
                checkpointer.close()
                raise ValueError(
                    f"workdir: {workdir} holds a checkpoint of different models "
                    f"({metadata.get('identity')}); use a fresh work directory"
                )
            start, state, _ = checkpointer.restore_latest(state)
        log = _MetricsLog(workdir / "metrics.csv", start)
    if mode == "sequential":
        def advance(models, batches):
            outputs = [step_fn(models[k], batches[k], None if options is None else options[k])
                       for k in range(len(specs))]
            return [model_state for model_state, _ in outputs], _stack([metrics for _, metrics in outputs])

        models, stacked = _unstack(state, len(specs)), _stack
    else:
        def advance(models, batches):
            return step_fn(models, {name: np.stack([b[name] for b in batches]) for name in fields}, options)

        models, stacked = state, lambda stacked_state: stacked_state

    metrics = None
    with tqdm.tqdm(
        total=train_config.num_steps, initial=start, disable=not progress, desc=f"{len(specs)} models"
    ) as bar:
        for step in range(start, train_config.num_steps):
            models, metrics = advance(models, [batch_at(spec, step) for spec in specs])
            done = step + 1
            bar.update(1)
            if done % train_config.log_every == 0 or done == train_config.num_steps:
                host_metrics = jax.tree.map(np.asarray, metrics)
                bar.set_postfix(loss=f"{host_metrics['loss'].mean():.3f}")
                if log is not None:
                    log.append(done, specs, host_metrics)
            if checkpointer is not None and (
                done % train_config.checkpoint_every == 0 or done == train_config.num_steps
            ):
                checkpointer.save(done, stacked(models), {"identity": identity})
            if step_callback is not None:
                step_callback(done, metrics)
    if checkpointer is not None:
        checkpointer.close()
    final_metrics = {} if metrics is None else jax.tree.map(np.asarray, metrics)
    return SweepResult(model, list(specs), stacked(models), final_metrics)
