"""`TrainConfig`: everything a training run needs besides the data (the scale modules beside it fill it in)."""

from __future__ import annotations

import dataclasses

from pushjax.models import ModelConfig
from pushjax.train import train_state


@dataclasses.dataclass(frozen=True)
class TrainConfig:
    """Everything a training run needs besides the data.

    Attributes:
      model: the architecture (its `variant` is usually overridden per run).
      learning_rate: Adam step size (the initial one with a decaying schedule).
      schedule: the learning-rate schedule (`pushjax.train.train_state.SCHEDULES`): ``"constant"`` (the paper's) or
        ``"cosine"`` (decayed over `num_steps`, so resuming a sweep with another `num_steps` changes the rest of its
        schedule).
      batch_size: examples per step and model.
      num_steps: optimisation steps per model.
      weight_decay: lambda of the 0.5 * |w|^2 kernel penalty.
      log_every: steps between metric rows in the log (and progress-bar updates).
      checkpoint_every: steps between checkpoints (the last step is always saved).
      eval_batch_size: examples per evaluation batch.
      curve_examples: examples per model and split of the learning curves (`pushjax.train.curves`).
    """

    model: ModelConfig
    learning_rate: float = 1e-4
    schedule: str = "constant"
    batch_size: int = 32
    num_steps: int = 75_000
    weight_decay: float = 1e-3
    log_every: int = 100
    checkpoint_every: int = 5_000
    eval_batch_size: int = 256
    curve_examples: int = 1024

    def __post_init__(self):
        for name in ("batch_size", "num_steps", "log_every", "checkpoint_every", "eval_batch_size",
                     "curve_examples"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name}: expected a positive integer, got {getattr(self, name)}")
        if self.learning_rate <= 0:
            raise ValueError(f"learning_rate: expected > 0, got {self.learning_rate}")
        if self.weight_decay < 0:
            raise ValueError(f"weight_decay: expected >= 0, got {self.weight_decay}")
        if self.schedule not in train_state.SCHEDULES:
            raise ValueError(f"schedule: expected one of {', '.join(train_state.SCHEDULES)}, got {self.schedule!r}")

    def with_variant(self, variant: str, view: str | None = None) -> "TrainConfig":
        """This config with the model's variant (and optionally view) replaced."""
        model = dataclasses.replace(self.model, variant=variant, view=view or self.model.view)
        return dataclasses.replace(self, model=model)
