"""Training one model until a convergence criterion on its validation score is met (issue 30).

The published runs train for a fixed number of steps with a cosine decay, whose end makes every learning curve look
flat. `train_until_converged` instead trains one model at a constant learning rate and scores it on a fixed
validation set every `Criterion.eval_every` steps; the score is the findings' (`pushjax.paper.statistics.SCORE`):
the mean of the translation and rotation errors in % of the ``zero`` baseline.

**The criterion** (fixed before the run it judges): the constant phase ends at the first evaluation at which the
best score of the last `Criterion.window` evaluations is not better than the best score before them by more than
`Criterion.min_improvement` (relative), i.e. the validation score has stopped improving for ``window *
eval_every`` steps; the model is then *converged*. When the budget of constant steps (`Criterion.budget`, growing
with the training-set size) ends first, the model is *not converged*. Either way a short cosine decay of the
learning rate to `Criterion.final_lr_fraction` of it follows (`Criterion.decay_steps`: a tenth of the constant
phase, at least `Criterion.min_decay_steps`), and the model after the decay is the one evaluated.

**A fixed budget** (`Criterion.stop_on_plateau` False, e.g. `PAPER_SCHEDULE`): the validation score is recorded every
`Criterion.eval_every` steps and used for nothing; the constant phase lasts the whole budget, with no decay when
`decay_fraction` and `min_decay_steps` are 0. Such a model can be continued to a larger budget from its saved state:
a call with the same `resume_dir` and a criterion with a larger budget reopens the constant phase where it ended.

One model per call: the unit of work of a resumable run whose finished models are recorded as they finish
(`pushjax.paper.full_run`). With a `resume_dir` the model's training state, its scores and the criterion's progress
are saved every `Criterion.eval_every` steps (constant phase and decay), and a call with the same folder continues
from the last save: the batches depend only on the model's spec and the step, so a resumed model ends with the same
parameters, scores and verdict as an uninterrupted one.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import optax

from pushjax.models import ModelConfig, PushModel
from pushjax.train.batching import Examples, ModelSpec, batch_indices, gather, model_fields
from pushjax.train.checkpoint import Checkpointer
from pushjax.train.configs import TrainConfig
from pushjax.train.evaluate import error_metrics, predict
from pushjax.train.metrics_log import TensorBoardLog
from pushjax.train.train_state import TrainState, create_train_state, make_train_step


@dataclasses.dataclass(frozen=True)
class Criterion:
    """When a model's constant-rate phase ends, and how long it may last.

    Attributes:
      eval_every: steps between validation scores.
      stop_on_plateau: whether the criterion ends the constant phase (False: a fixed budget; the scores are recorded
        only).
      window: evaluations without a relative improvement of more than `min_improvement` that end the phase.
      min_improvement: relative improvement of the best validation score that counts (0.01: 1 %).
      base_steps: the budget of constant-rate steps at size 0 ...
      steps_per_example: ... plus this many per training example (`budget`).
      max_steps: the budget's cap.
      decay_fraction: the decay lasts this fraction of the constant phase ...
      min_decay_steps: ... and at least this many steps.
      final_lr_fraction: the learning rate at the end of the decay, as a fraction of the constant one.
    """

    eval_every: int = 1_000
    stop_on_plateau: bool = True
    window: int = 5
    min_improvement: float = 0.01
    base_steps: int = 10_000
    steps_per_example: float = 0.25
    max_steps: int = 60_000
    decay_fraction: float = 0.1
    min_decay_steps: int = 1_000
    final_lr_fraction: float = 0.01

    def __post_init__(self):
        for name in ("eval_every", "window", "base_steps", "max_steps"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name}: expected a positive integer, got {getattr(self, name)}")
        if self.min_decay_steps < 0:
            raise ValueError(f"min_decay_steps: expected a non-negative integer, got {self.min_decay_steps}")
        for name in ("min_improvement", "decay_fraction", "final_lr_fraction"):
            if not 0.0 <= getattr(self, name) < 1.0:
                raise ValueError(f"{name}: expected a fraction in [0, 1), got {getattr(self, name)}")

    def budget(self, size: int) -> int:
        """The most constant-rate steps a model on `size` training examples takes (a multiple of `eval_every`)."""
        steps = min(self.max_steps, self.base_steps + self.steps_per_example * size)
        return max(self.eval_every, int(math.ceil(steps / self.eval_every)) * self.eval_every)

    def plateaued(self, scores: Sequence[float]) -> bool:
        """Whether validation `scores` (one per evaluation, lower is better) have stopped improving."""
        if not self.stop_on_plateau or len(scores) <= self.window:
            return False
        before, recent = min(scores[:-self.window]), min(scores[-self.window:])
        return recent > before * (1.0 - self.min_improvement)

    def decay_steps(self, constant_steps: int) -> int:
        return max(self.min_decay_steps, int(round(self.decay_fraction * constant_steps)))


CRITERION = Criterion()
"""The criterion of the ``data_efficiency_full`` run, fixed before it."""

PAPER_STEPS = 75_000
PAPER_LEARNING_RATE = 1e-4
PAPER_BATCH_SIZE = 32
PAPER_SCHEDULE = Criterion(stop_on_plateau=False, base_steps=PAPER_STEPS, steps_per_example=0.0,
                           max_steps=PAPER_STEPS, decay_fraction=0.0, min_decay_steps=0)
"""The paper's training (``paper_tables.json``'s ``training``: Adam at a constant `PAPER_LEARNING_RATE`, batch
`PAPER_BATCH_SIZE`, `PAPER_STEPS` steps, no early stop), scored every 1 000 steps; `fixed_budget` gives it another
length."""


def fixed_budget(steps: int) -> Criterion:
    """`PAPER_SCHEDULE` with `steps` constant-rate steps (rounded up to a multiple of its ``eval_every``)."""
    if steps < 1:
        raise ValueError(f"steps: expected a positive integer, got {steps}")
    return dataclasses.replace(PAPER_SCHEDULE, base_steps=steps, max_steps=steps)


@dataclasses.dataclass(frozen=True)
class ConvergedModel:
    """Outcome of `train_until_converged`.

    Attributes:
      model: the Flax module.
      state: the trained `TrainState` (after the decay).
      converged: whether the criterion ended the constant phase (False: its budget did).
      constant_steps: steps at the constant learning rate.
      decay_steps: steps of the decay.
      validation: [(step, trans_percent, rot_percent)] every validation evaluation (its score: their mean), the one
        after the decay last.
      seconds: wall time of the training and its validation scores (of every call, when resumed).
      steps_per_second: training steps per second (validation excluded).
    """

    model: PushModel
    state: TrainState
    converged: bool
    constant_steps: int
    decay_steps: int
    validation: list[tuple[int, float, float]]
    seconds: float
    steps_per_second: float

    @property
    def steps(self) -> int:
        return self.constant_steps + self.decay_steps


def validation_errors(model: PushModel, state: TrainState, examples: Examples, batch_size: int) -> tuple[float, float]:
    """The translation and rotation errors in % of zero of `state` on `examples`; their mean is the score."""
    metrics = error_metrics(predict(model, state, examples, batch_size), examples)
    return float(metrics["trans_percent"]), float(metrics["rot_percent"])


def _with_learning_rate(state: TrainState, value: float) -> TrainState:
    opt_state = state.opt_state
    hyperparams = dict(opt_state.hyperparams, learning_rate=jnp.asarray(value, jnp.float32))
    return state.replace(opt_state=opt_state._replace(hyperparams=hyperparams))


@functools.lru_cache(maxsize=16)
def _compiled_step(model_config: ModelConfig, physics: Callable | None, learning_rate: float, weight_decay: float):
    """(model, optimiser, jitted train step) of `train_until_converged`: cached, so that the models of a run that
    share an architecture (e.g. one variant at several training-set sizes) compile their step once."""
    model = PushModel(model_config) if physics is None else PushModel(model_config, physics)
    optimizer = optax.inject_hyperparams(optax.adam)(learning_rate=learning_rate)
    return model, optimizer, jax.jit(make_train_step(model, optimizer, weight_decay))


def resumed_step(resume_dir: str | os.PathLike | None) -> int:
    """The step at which `train_until_converged` with this `resume_dir` continues (0: nothing saved)."""
    if resume_dir is None or not Path(resume_dir).is_dir():
        return 0
    checkpointer = Checkpointer(resume_dir)
    try:
        return checkpointer.latest_step() or 0
    finally:
        checkpointer.close()


def train_until_converged(
    train_config: TrainConfig, examples: Examples, spec: ModelSpec, validation: Examples,
    criterion: Criterion = CRITERION, *, physics: Callable | None = None,
    log: Callable[[str], None] | None = None, tensorboard: TensorBoardLog | None = None,
    resume_dir: str | os.PathLike | None = None,
) -> ConvergedModel:
    """Trains one model (`train_config.model`, the subset and seed of `spec`) by `criterion`.

    Args:
      train_config: model, learning rate (the constant one), batch size, weight decay, evaluation batch size; its
        `num_steps` and `schedule` are not used (the criterion sets them).
      examples: the training split, {field: [N, ...]}.
      spec: the model's training subset and seed (its batches as in `pushjax.train.sweep`).
      validation: the examples of the validation score.
      criterion: the convergence criterion and budget.
      physics: replaces `PushModel.physics`.
      log: called with a line after every validation score.
      tensorboard: a log of this one model (`pushjax.train.metrics_log.TensorBoardLog`, its first step
        `resumed_step(resume_dir)`) that gets every validation score (``validation/trans_percent``,
        ``validation/rot_percent``, ``validation/score``), the training loss and the steps per second of the constant
        phase, or None.
      resume_dir: a folder for the training state every `Criterion.eval_every` steps, from which a later call with the
        same arguments continues (None: not saved). The caller removes it once the model is kept elsewhere.
    """
    model, optimizer, step_fn = _compiled_step(train_config.model, physics, train_config.learning_rate,
                                               train_config.weight_decay)
    fields = model_fields(train_config.model)
    size = len(spec.train_indices)

    def batch_at(step):
        return gather(examples, batch_indices(spec, step, train_config.batch_size), fields)

    state = create_train_state(model, optimizer, batch_at(0), spec.seed)
    state = _with_learning_rate(state, train_config.learning_rate)
    budget = criterion.budget(size)
    step = 0
    progress = {"scores": [], "validation": [], "converged": False, "constant_steps": None, "train_seconds": 0.0,
                "seconds": 0.0}
    checkpointer = None if resume_dir is None else Checkpointer(resume_dir, max_to_keep=1)
    if checkpointer is not None and (restored := checkpointer.restore_latest(state)) is not None:
        step, state, progress = restored
        if not criterion.stop_on_plateau and progress["constant_steps"] is not None \
                and progress["constant_steps"] < budget and step == progress["constant_steps"]:
            progress = {**progress, "constant_steps": None}  # a fixed budget continued to a larger one
    scores: list[float] = list(progress["scores"])
    history: list[tuple[int, float, float]] = [tuple(point) for point in progress["validation"]]
    converged, constant_steps = bool(progress["converged"]), progress["constant_steps"]
    started, train_seconds = time.monotonic(), float(progress["train_seconds"])
    metrics = None

    def score_now(label: str, scalars: dict[str, float]) -> float:
        trans, rot = validation_errors(model, state, validation, train_config.eval_batch_size)
        score = (trans + rot) / 2.0
        history.append((step, trans, rot))
        if tensorboard is not None:
            scalars = {**scalars, "validation/trans_percent": trans, "validation/rot_percent": rot,
                       "validation/score": score}
            tensorboard.append(step, {tag: np.array([value]) for tag, value in scalars.items()})
        if log is not None:
            log(f"{spec.name}: step {step} ({label}) validation score {score:.2f}")
        return score

    def save():
        if checkpointer is not None:
            checkpointer.save(step, state, {
                "scores": scores, "validation": history, "converged": converged, "constant_steps": constant_steps,
                "train_seconds": train_seconds, "seconds": progress["seconds"] + time.monotonic() - started})

    try:
        while constant_steps is None:
            chunk = time.monotonic()
            for _ in range(criterion.eval_every):
                state, metrics = step_fn(state, batch_at(step))
                step += 1
            jax.block_until_ready(state.params)
            train_seconds += time.monotonic() - chunk
            scores.append(score_now("constant", {"loss": float(metrics["loss"]), "steps_per_second":
                                                 criterion.eval_every / (time.monotonic() - chunk)}))
            converged = criterion.plateaued(scores)
            if converged or step >= budget:
                constant_steps = step
            save()
        decay_steps = criterion.decay_steps(constant_steps)
        lr = train_config.learning_rate
        while step < constant_steps + decay_steps:
            chunk = time.monotonic()
            for _ in range(min(criterion.eval_every, constant_steps + decay_steps - step)):
                progress_fraction = (step - constant_steps + 1) / decay_steps
                cosine = 0.5 * (1.0 + math.cos(math.pi * progress_fraction))
                state = _with_learning_rate(state, lr * (criterion.final_lr_fraction
                                                         + (1 - criterion.final_lr_fraction) * cosine))
                state, metrics = step_fn(state, batch_at(step))
                step += 1
            jax.block_until_ready(state.params)
            train_seconds += time.monotonic() - chunk
            save()
    finally:
        if checkpointer is not None:
            checkpointer.close()
    if decay_steps or not history or history[-1][0] != step:
        score_now("after the decay", {"loss": float(metrics["loss"])} if metrics is not None else {})
    return ConvergedModel(model, state, converged, constant_steps, decay_steps, history,
                          progress["seconds"] + time.monotonic() - started,
                          step / train_seconds if train_seconds > 0 else float("nan"))
