"""Losses, the (vmapped) sweep trainer, orbax checkpoints, evaluation and training configs."""

from pushjax.train import checkpoint, configs, evaluate, losses, train
from pushjax.train.configs import TrainConfig, get_config
from pushjax.train.train import (
    ModelSpec,
    SweepResult,
    TrainState,
    batch_indices,
    create_train_state,
    make_train_step,
    subset_specs,
    sweep,
)

__all__ = [
    "checkpoint",
    "configs",
    "evaluate",
    "losses",
    "train",
    "ModelSpec",
    "SweepResult",
    "TrainConfig",
    "TrainState",
    "batch_indices",
    "create_train_state",
    "get_config",
    "make_train_step",
    "subset_specs",
    "sweep",
]
