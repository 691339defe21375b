"""The one trainer: K models of one architecture trained together, for a fixed number of steps or by a
convergence criterion, resumable from checkpoints.

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

When training ends is its stopping rule: by default `TrainConfig.num_steps` steps under the config's schedule;
with a ``criterion`` (`pushjax.train.convergence.Criterion`, one model) a constant learning rate, the model scored
on a validation set every `Criterion.eval_every` steps until the criterion or its budget ends the constant phase,
then the criterion's decay of the learning rate (`pushjax.paper.full_run`'s models: the convergence criterion, or the
paper's fixed budget of 75 000 steps, continued to a larger one from the kept state). The criterion's progress (its
scores, the phase, the training time) is saved with every checkpoint.

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
parameters (and, with a criterion, the same scores and verdict), and a model trained alone draws the same batches
as inside a sweep.

Work directory layout: ``checkpoints/<step>/`` (orbax, `pushjax.train.checkpoint`: the stacked
`TrainState` and metadata: the models' identity and, under `MODEL_CONFIG_KEY` and `MODEL_VARIANTS_KEY`, their
`ModelConfig` and variants, which `pushjax.train.predictor.load_model` rebuilds them from; with a criterion, its
progress under ``progress``) ``metrics.csv`` (one row per logged step and
model: step, model, name, loss and the loss's metrics in mm / degrees; `pushjax.train.metrics_log`) and
``tensorboard/<model name>/train`` (the same scalars and steps per second, the training config as hparams, and
with a criterion the validation scores).
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
import tqdm

from pushjax.models import ERROR_OPTIONS, ModelConfig, PushModel
from pushjax.train import distributed, mesh as mesh_lib
from pushjax.train.batching import Examples, ModelSpec, batch_indices, gather, model_fields
from pushjax.train.checkpoint import Checkpointer
from pushjax.train.configs import TrainConfig
from pushjax.train.convergence import Criterion
from pushjax.train.evaluate import evaluate, validation_errors
from pushjax.train.metrics_log import TENSORBOARD_DIR, MetricsLog, TensorBoardLog, flat_hparams
from pushjax.train.steppers import (
    SWEEP_MODES, compiled_step, error_options, make_stepper, stack, with_learning_rate,
)
from pushjax.train.train_state import TrainState, create_train_state, make_optimizer

MODEL_CONFIG_KEY = "model_config"
"""The checkpoint metadata's key of the models' `ModelConfig` (as `dataclasses.asdict`)."""
MODEL_VARIANTS_KEY = "model_variants"
"""The checkpoint metadata's key of each model's variant (they differ in a sweep that mixes the error variants)."""
CHECKPOINTS = "checkpoints"
"""The work directory's folder of checkpoints."""


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


class WorkdirConflictError(ValueError):
    """A sweep's work directory that holds a checkpoint of other models; the message (``workdir: ...``) names it."""


@dataclasses.dataclass(frozen=True)
class Phases:
    """How a model trained under a `pushjax.train.convergence.Criterion` (`sweep`'s ``criterion``).

    Attributes:
      converged: whether the criterion ended the constant phase (False: its budget did).
      constant_steps: steps at the constant learning rate.
      decay_steps: steps of the decay.
      validation: [(step, trans_percent, rot_percent)] every validation evaluation (its score: their mean), the one
        after the decay last.
      seconds: wall time of the training and its validation scores (of every call, when resumed).
      steps_per_second: training steps per second (validation excluded; of every call).
    """

    converged: bool
    constant_steps: int
    decay_steps: int
    validation: list[tuple[int, float, float]]
    seconds: float
    steps_per_second: float

    @property
    def steps(self) -> int:
        return self.constant_steps + self.decay_steps


@dataclasses.dataclass(frozen=True)
class SweepResult:
    """Outcome of `sweep`.

    Attributes:
      model: the Flax module (shared by all models).
      specs: the K models.
      state: `TrainState` whose leaves have a leading axis of size K.
      final_metrics: {name: [K]} metrics of the last step taken in this call ({} when it took none,
        e.g. when resuming a finished sweep).
      phases: with a criterion, how the model trained; None for a fixed number of steps.
    """

    model: PushModel
    specs: list[ModelSpec]
    state: TrainState
    final_metrics: dict[str, np.ndarray]
    phases: Phases | None = None

    @property
    def steps_trained(self) -> np.ndarray:
        """[K] int steps each model has trained, restored ones included (read from `state`)."""
        return np.asarray(self.state.step)

    def model_state(self, index: int) -> TrainState:
        """The state of model `index` (in [0, K); leaves without the model axis)."""
        return jax.tree.map(lambda leaf: leaf[index], self.state)

    def evaluate(self, examples: Examples, batch_size: int = 256) -> list[dict]:
        """`pushjax.train.evaluate.evaluate` of every model on `examples`, in the order of `specs`."""
        return [evaluate(self.model, self.model_state(k), examples, batch_size,
                         None if spec.variant is None else np.asarray(ERROR_OPTIONS[spec.variant], np.float32))
                for k, spec in enumerate(self.specs)]


def describe_specs(variant: str, specs: Sequence[ModelSpec]) -> str:
    """A short label of a sweep's models, e.g. ``hybrid: sizes 200,660 x seeds 0,1 (4 models)``."""
    variants = sorted({spec.variant or variant for spec in specs})
    sizes = sorted({len(spec.train_indices) for spec in specs})
    seeds = sorted({spec.seed for spec in specs})
    return (f"{','.join(variants)}: sizes {','.join(map(str, sizes))} x seeds {','.join(map(str, seeds))} "
            f"({len(specs)} models)")


def _legacy_steps(workdir: Path) -> list[Path]:
    """The step folders of the training state that ``convergence.train_until_converged`` (the criterion's own
    trainer before this one, until 2026-12-01) kept directly in its folder: one model, no model axis, the criterion's
    progress as the whole metadata. Kept readable for the states committed then (`pushjax.paper.full_run`'s
    ``in_training``)."""
    return sorted(path for path in workdir.iterdir() if path.is_dir() and path.name.isdigit()) \
        if workdir.is_dir() else []


def resumed_step(workdir: str | os.PathLike | None) -> int:
    """The step at which `sweep` with this work directory continues (0: nothing saved)."""
    if workdir is None:
        return 0
    workdir = Path(workdir)
    if (workdir / CHECKPOINTS).is_dir():
        checkpointer = Checkpointer(workdir / CHECKPOINTS, read_only=True)
        try:
            if (step := checkpointer.latest_step()) is not None:
                return step
        finally:
            checkpointer.close()
    legacy = _legacy_steps(workdir)
    return int(legacy[-1].name) if legacy else 0


class _Progress:
    """Where a sweep under a `Criterion` stands (saved with each checkpoint under ``progress``): its validation
    scores and history, the phase (``constant_steps`` None while the constant phase lasts) and its times."""

    def __init__(self, criterion: Criterion, size: int, saved: Mapping | None, step: int):
        saved = saved or {"scores": [], "validation": [], "converged": False, "constant_steps": None,
                          "train_seconds": 0.0, "seconds": 0.0}
        self.criterion, self.budget = criterion, criterion.budget(size)
        self.scores: list[float] = list(saved["scores"])
        self.validation: list[tuple[int, float, float]] = [tuple(point) for point in saved["validation"]]
        self.converged, self.constant_steps = bool(saved["converged"]), saved["constant_steps"]
        self.train_seconds, self.earlier_seconds = float(saved["train_seconds"]), float(saved["seconds"])
        if not criterion.stop_on_plateau and self.constant_steps is not None and self.constant_steps < self.budget \
                and step == self.constant_steps:
            self.constant_steps = None  # a fixed budget continued to a larger one

    @property
    def end(self) -> int | None:
        """The last step (None while the constant phase lasts)."""
        return None if self.constant_steps is None else self.constant_steps + self.decay_steps

    @property
    def decay_steps(self) -> int:
        return self.criterion.decay_steps(self.constant_steps)

    def planned_steps(self) -> int:
        """The last step, or while the constant phase lasts the budget's end with its decay."""
        return self.end if self.end is not None else self.budget + self.criterion.decay_steps(self.budget)

    def judge(self, step: int, score: float) -> None:
        """Records the validation score at `step` of the constant phase; ends the phase by the criterion or budget."""
        self.scores.append(score)
        self.converged = self.criterion.plateaued(self.scores)
        if self.converged or step >= self.budget:
            self.constant_steps = step

    def saved(self, seconds: float) -> dict:
        return {"scores": self.scores, "validation": self.validation, "converged": self.converged,
                "constant_steps": self.constant_steps, "train_seconds": self.train_seconds,
                "seconds": self.earlier_seconds + seconds}

    def phases(self, seconds: float, step: int) -> Phases:
        return Phases(self.converged, self.constant_steps, self.decay_steps, self.validation,
                      self.earlier_seconds + seconds,
                      step / self.train_seconds if self.train_seconds > 0 else float("nan"))


class _Files:
    """A sweep's work directory (`sweep`'s layout), or nothing to write when it is None: the checkpoints it resumes
    from and saves, ``metrics.csv`` and the TensorBoard runs (written by process 0)."""

    def __init__(self, workdir: str | os.PathLike | None, metadata: dict, keep: int):
        self.workdir, self._metadata, self._legacy = None if workdir is None else Path(workdir), metadata, []
        self._checkpointer = self._metrics = self.tensorboard = None
        if self.workdir is not None:
            self.workdir.mkdir(parents=True, exist_ok=True)
            self._checkpointer = Checkpointer(self.workdir / CHECKPOINTS, max_to_keep=keep)

    def restore(self, state: TrainState, single_state: TrainState | None) -> tuple[int, TrainState, dict | None]:
        """(step, stacked state, the criterion's saved progress or None) of the newest checkpoint; (0, `state`, None)
        without one. `single_state`: one model's fresh state, to read a `_legacy_steps` state by (None: not read)."""
        if self._checkpointer is None:
            return 0, state, None
        metadata = self._checkpointer.latest_metadata()
        if metadata is not None:
            if metadata.get("identity") != self._metadata["identity"]:
                raise WorkdirConflictError(
                    f"workdir: {self.workdir} holds a checkpoint of different models "
                    f"({metadata.get('identity')}); use a fresh work directory")
            step, state, metadata = self._checkpointer.restore_latest(state)
            progress = metadata.get("progress")
        elif single_state is not None and (legacy := _legacy_steps(self.workdir)):
            checkpointer = Checkpointer(self.workdir, read_only=True)
            try:
                step, single, progress = checkpointer.restore_latest(single_state)
            finally:
                checkpointer.close()
            state, self._legacy = stack([single]), legacy
        else:
            return 0, state, None
        if jax.device_count() == 1:
            # Orbax returns arrays committed to the device, a fresh state's are not, and jax.jit keys its cache
            # on that: uncommitted, a resumed sweep reuses the train step a fresh one compiled in this process.
            state = jax.tree.map(lambda leaf: jnp.asarray(np.asarray(leaf)), state)
        return step, state, progress

    def open_logs(self, start: int, train_config: TrainConfig, specs: Sequence[ModelSpec]) -> None:
        if self.workdir is None or not distributed.is_writer():
            return
        self._metrics = MetricsLog(self.workdir / "metrics.csv", start)
        self.tensorboard = TensorBoardLog(self.workdir / TENSORBOARD_DIR, [spec.name for spec in specs], "train",
                                          start and start + 1)
        config_hparams = flat_hparams(train_config)
        self.tensorboard.write_hparams(
            [{**config_hparams, "seed": spec.seed, "train_size": len(spec.train_indices),
              "variant": spec.variant or train_config.model.variant} for spec in specs], ("loss",))

    def log(self, step: int, metrics: Mapping[str, np.ndarray], steps_per_second: float) -> None:
        """One step's {name: [K]} metrics in ``metrics.csv`` and TensorBoard, with the steps per second."""
        if self._metrics is not None:
            names = self._metadata["identity"]["names"]
            self._metrics.append(step, names, metrics)
            self.tensorboard.append(step, {**metrics, "steps_per_second": np.full(len(names), steps_per_second)})

    def save(self, step: int, state: TrainState, progress: dict | None) -> None:
        if self._checkpointer is not None:
            self._checkpointer.save(step, state, self._metadata if progress is None else
                                    {**self._metadata, "progress": progress})
            for folder in self._legacy:  # the state is kept in this layout from now on
                shutil.rmtree(folder)
            self._legacy = []

    def close(self) -> None:
        for opened in (self._checkpointer, self.tensorboard):
            if opened is not None:
                opened.close()


def _check_arguments(specs: Sequence[ModelSpec], examples: Examples, fields: Sequence[str], mode: str,
                     criterion: Criterion | None, validation: Examples | None) -> None:
    if not specs:
        raise ValueError("specs: expected at least one model")
    if mode not in SWEEP_MODES:
        raise ValueError(f"mode: expected one of {SWEEP_MODES}, got {mode!r}")
    if mode == "sequential" and jax.process_count() > 1:
        raise ValueError(f"mode: 'sequential' trains on one device; with {jax.process_count()} processes use "
                         "'vmap' or 'unroll'")
    if criterion is not None and (len(specs) != 1 or validation is None):
        raise ValueError(f"criterion: judges one model's validation score; got {len(specs)} models and "
                         f"{'no' if validation is None else 'a'} validation set")
    num_examples = len(examples[fields[0]]) if fields[0] in examples else 0
    for spec in specs:
        if spec.train_indices.max(initial=0) >= num_examples or spec.train_indices.min() < 0:
            raise ValueError(f"specs: {spec.name!r} indexes outside the {num_examples} training examples")


def sweep(
    train_config: TrainConfig, examples: Examples, specs: Sequence[ModelSpec],
    workdir: str | os.PathLike | None = None, *, mode: str = "vmap", physics: Callable | None = None,
    progress: bool = True, description: str | None = None,
    step_callback: Callable[[int, Mapping[str, jax.Array]], None] | None = None,
    checkpoint_callback: Callable[[int, TrainState], None] | None = None, criterion: Criterion | None = None,
    validation: Examples | None = None, log: Callable[[str], None] | None = None, keep_checkpoints: int = 2,
) -> SweepResult:
    """Trains K = len(specs) models of `train_config.model` for `train_config.num_steps` steps, or one by `criterion`.

    Args:
      train_config: model, optimiser and schedule (with a criterion the constant learning rate: its `num_steps`,
        `schedule` and `checkpoint_every` are the criterion's).
      examples: the training split, {field: [N, ...] NumPy array} (schema fields; at least `model_fields`).
      specs: the models (subsets and seeds).
      workdir: folder for checkpoints and ``metrics.csv``; when it holds a checkpoint of the same specs, training
        resumes from it (in any mode). A checkpoint already past `train_config.num_steps` is returned as it is, with
        a warning naming the work directory, its step and the requested steps (`SweepResult.steps_trained` says how
        far the models trained). None: no checkpoints, no log.
      mode: one of `SWEEP_MODES` (the module docstring): "vmap" or "unroll": one jitted step for all K models, split
        over all visible devices when there are several (those of all processes); "sequential": the jitted
        single-model step once per model at every step, on one device of one process.
      physics: replaces `PushModel.physics` (default `lynch.predict`).
      progress: show a progress bar with the running loss (mean over models), on process 0.
      description: the progress bar's label; by default the variants, subset sizes and seeds of `specs`.
      step_callback: called after every step with the number of completed steps and that step's metrics
        ({name: [K]} device arrays).
      checkpoint_callback: called with a step and the K models' stacked `TrainState` at that step: before training
        (at step 0, or at the step a resumed sweep restored, unless it is already finished) and after every
        checkpoint, also without a work directory; e.g. the learning curves of `pushjax.train.curves`.
      criterion: the stopping rule of one model (`specs` of one), scored on `validation` every
        `Criterion.eval_every` steps: a constant learning rate until it or its budget ends the phase, then its decay;
        checkpoints at every score and every `Criterion.eval_every` steps of the decay, with its progress. None:
        `train_config.num_steps` steps, checkpoints every `train_config.checkpoint_every` steps and at the last.
      validation: the examples of the criterion's validation score.
      log: with a criterion, called with a line after every validation score.
      keep_checkpoints: newest checkpoints kept in the work directory.

    Returns:
      the `SweepResult`; with a criterion its `Phases`, the model after the decay scored unless its last score is.
    """
    fields = model_fields(train_config.model)
    _check_arguments(specs, examples, fields, mode, criterion, validation)
    model = PushModel(train_config.model) if physics is None else PushModel(train_config.model, physics)
    # The constant schedule does not depend on the number of steps: sweeps of any length share a compiled step.
    decay_steps = train_config.num_steps if train_config.schedule != "constant" and criterion is None else None
    optimizer_settings = (train_config.learning_rate, "constant" if criterion else train_config.schedule, decay_steps,
                          criterion is not None)
    options = error_options(train_config.model, specs)
    mesh = None if mode == "sequential" else mesh_lib.sweep_mesh(len(specs))
    step_fn = compiled_step(train_config.model, physics, optimizer_settings, train_config.weight_decay, mode,
                            options is not None, mesh)
    example_batch = gather(examples, batch_indices(specs[0], 0, train_config.batch_size), fields)
    optimizer = make_optimizer(*optimizer_settings)
    models = [create_train_state(model, optimizer, example_batch, spec.seed) for spec in specs]
    if criterion is not None:
        models = [with_learning_rate(state, train_config.learning_rate) for state in models]
    files = _Files(workdir, model_metadata(train_config.model, specs), keep_checkpoints)
    try:
        start, state, saved = files.restore(stack(models), models[0] if criterion is not None else None)
        if criterion is None and start > train_config.num_steps:
            warnings.warn(f"workdir: {files.workdir} holds a checkpoint at step {start}, past the requested "
                          f"num_steps {train_config.num_steps}; the sweep returns the models as trained for {start} "
                          "steps", stacklevel=2)
        files.open_logs(start, train_config, specs)
        stepper = make_stepper(mode, step_fn, state, specs, options, fields, mesh)
        training = _Training(train_config, examples, specs, model, stepper, files, start, validation, options, log)
        phase = None if criterion is None else _Progress(criterion, len(specs[0].train_indices), saved, start)
        step, metrics = training.run(phase, progress, description, step_callback, checkpoint_callback)
    finally:
        files.close()
    return SweepResult(model, list(specs), stepper.state(), {} if metrics is None else jax.tree.map(np.asarray, metrics),
                       None if phase is None else phase.phases(time.monotonic() - training.started, step))


@dataclasses.dataclass
class _Training:
    """`sweep`'s loop: the steps from `start` to the end of its stopping rule, with their logs and checkpoints."""

    config: TrainConfig
    examples: Examples
    specs: Sequence[ModelSpec]
    model: PushModel
    stepper: Any
    files: _Files
    start: int
    validation: Examples | None
    options: jax.Array | None
    log: Callable[[str], None] | None
    started: float = dataclasses.field(default_factory=time.monotonic)

    def score(self, phase: _Progress, step: int, label: str, scalars: Mapping[str, float]) -> float:
        """The validation score of the criterion's model at `step`, recorded, logged and returned."""
        trans, rot = validation_errors(self.model, jax.tree.map(lambda leaf: leaf[0], self.stepper.state()),
                                       self.validation, self.config.eval_batch_size,
                                       None if self.options is None else np.asarray(self.options[0]))
        value = (trans + rot) / 2.0
        phase.validation.append((step, trans, rot))
        if self.files.tensorboard is not None:
            self.files.tensorboard.append(step, {tag: np.array([scalar]) for tag, scalar in {
                **scalars, "validation/trans_percent": trans, "validation/rot_percent": rot,
                "validation/score": value}.items()})
        if self.log is not None:
            self.log(f"{self.specs[0].name}: step {step} ({label}) validation score {value:.2f}")
        return value

    def save(self, step: int, phase: _Progress | None, callback: Callable | None) -> None:
        snapshot = self.stepper.state()
        self.files.save(step, snapshot, None if phase is None else phase.saved(time.monotonic() - self.started))
        if callback is not None:
            callback(step, snapshot)

    def run(self, phase: _Progress | None, progress: bool, description: str | None, step_callback: Callable | None,
            checkpoint_callback: Callable | None) -> tuple[int, Mapping[str, jax.Array] | None]:
        """Trains to the end of `phase` (None: `TrainConfig.num_steps`); the last step and its metrics."""
        config, stepper, criterion = self.config, self.stepper, None if phase is None else phase.criterion
        end = (lambda: config.num_steps) if phase is None else (lambda: phase.end)
        if checkpoint_callback is not None and (end() is None or self.start < end()):
            checkpoint_callback(self.start, stepper.state())
        fields = model_fields(config.model)
        step, metrics, last_log, chunk_started = self.start, None, (self.start, time.perf_counter()), time.monotonic()
        with tqdm.tqdm(total=end() or phase.planned_steps(), initial=self.start,
                       disable=not progress or not distributed.is_writer(),
                       desc=description or describe_specs(config.model.variant, self.specs)) as bar:
            while end() is None or step < end():
                if phase is not None and phase.end is not None:
                    stepper.set_learning_rate(
                        criterion.decayed_learning_rate(config.learning_rate, step, phase.constant_steps))
                metrics = stepper.advance([gather(self.examples, batch_indices(spec, step, config.batch_size), fields)
                                           for spec in stepper.local_specs])
                step += 1
                bar.update(1)
                if step % config.log_every == 0 or step == end():
                    host_metrics = jax.tree.map(np.asarray, metrics)
                    bar.set_postfix(loss=f"{host_metrics['loss'].mean():.3f}")
                    self.files.log(step, host_metrics, (step - last_log[0]) / (time.perf_counter() - last_log[1]))
                    last_log = (step, time.perf_counter())
                if phase is None and (step % config.checkpoint_every == 0 or step == end()):
                    self.save(step, None, checkpoint_callback)
                elif phase is not None and (step % criterion.eval_every == 0 or step == end()):
                    jax.block_until_ready(stepper.state().params)
                    chunk_seconds = time.monotonic() - chunk_started
                    phase.train_seconds += chunk_seconds
                    if phase.end is None:
                        phase.judge(step, self.score(phase, step, "constant", {
                            "loss": float(metrics["loss"][0]), "steps_per_second": criterion.eval_every / chunk_seconds}))
                        bar.total = phase.planned_steps()
                    self.save(step, phase, checkpoint_callback)
                    chunk_started = time.monotonic()
                if step_callback is not None:
                    step_callback(step, metrics)
        if phase is not None and (phase.decay_steps or not phase.validation or phase.validation[-1][0] != step):
            self.score(phase, step, "after the decay", {} if metrics is None else {"loss": float(metrics["loss"][0])})
        return step, metrics
