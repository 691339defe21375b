"""When a model's training ends: a convergence criterion on its validation score, or a fixed budget (issue 30).

The published runs train for a fixed number of steps with a cosine decay, whose end makes every learning curve look
flat. A `Criterion` instead is a stopping rule of the one trainer (`pushjax.train.sweep_trainer.sweep`, its
``criterion``): the model trains at a constant learning rate and is scored on a fixed validation set every
`Criterion.eval_every` steps; the score is the findings' (`pushjax.paper.statistics.SCORE`): the mean of the
translation and rotation errors in % of the ``zero`` baseline (`pushjax.train.evaluate.validation_errors`).

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
the trainer with the same work directory and a criterion with a larger budget reopens the constant phase where it
ended.

This module holds the rules only (no JAX); the trainer saves the criterion's progress with the training state every
`Criterion.eval_every` steps, so a resumed model ends with the same parameters, scores and verdict as an
uninterrupted one.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence


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

    def decayed_learning_rate(self, learning_rate: float, step: int, constant_steps: int) -> float:
        """The learning rate of the decay's step from `step` to ``step + 1`` after `constant_steps` at
        `learning_rate`: a cosine from it to `final_lr_fraction` of it, reached at the decay's last step."""
        fraction = (step - constant_steps + 1) / self.decay_steps(constant_steps)
        cosine = 0.5 * (1.0 + math.cos(math.pi * fraction))
        return learning_rate * (self.final_lr_fraction + (1 - self.final_lr_fraction) * cosine)


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
