"""Training: losses, one model's train state and step, the one trainer of K models (a fixed number of steps or a
convergence criterion), checkpoints, the metrics log, evaluation and training configs.

Modules:
  batching: each model's training subset and seed (`ModelSpec`), its batch order and in-memory batches.
  train_state: `TrainState`, the optimiser and the pure single-model train step.
  sweep_trainer: `sweep`, the one trainer: K models together (vmapped, unrolled or sequential), for a fixed number
    of steps or by a `convergence.Criterion`, resumable.
  steppers: the sweep's jitted train step and one stepper per mode.
  convergence: the stopping rules of one model: the convergence criterion and the paper's fixed budget.
  stopping: the trend rule on a validation curve (and its continuation rule).
  mesh: the sweep's model axis split over a mesh of devices (K/D models per device).
  distributed: several processes (hosts) joined to train one sweep.
  checkpoint: orbax checkpoints of a (stacked) train state.
  metrics_log: the sweep's ``metrics.csv`` and TensorBoard event files.
  predictor: `load_model`, a trained model from its checkpoint, predicting from depth images or point clouds.
  curves: learning curves (training and validation error against steps), the sweep's ``curves.csv``.
  losses, evaluate, configs: the training losses, evaluation in the paper's units, configs.
"""

from pushjax.train import (
    batching,
    checkpoint,
    configs,
    convergence,
    curves,
    distributed,
    evaluate,
    losses,
    mesh,
    metrics_log,
    predictor,
    steppers,
    sweep_trainer,
    train_state,
)
from pushjax.train.batching import (
    EVALUATION_FIELDS,
    MODEL_INPUT_FIELDS,
    ModelSpec,
    batch_indices,
    examples_from_source,
    gather,
    model_fields,
    subset_specs,
)
from pushjax.train.configs import TrainConfig, get_config
from pushjax.train.predictor import Prediction, Predictor, load_model, save_model
from pushjax.train.train_state import TrainState, create_train_state, make_optimizer, make_train_step
from pushjax.train.steppers import SWEEP_MODES
from pushjax.train.sweep_trainer import Phases, SweepResult, describe_specs, resumed_step, sweep

__all__ = [
    "batching",
    "checkpoint",
    "configs",
    "convergence",
    "curves",
    "distributed",
    "evaluate",
    "losses",
    "mesh",
    "metrics_log",
    "predictor",
    "steppers",
    "sweep_trainer",
    "train_state",
    "EVALUATION_FIELDS",
    "MODEL_INPUT_FIELDS",
    "SWEEP_MODES",
    "ModelSpec",
    "Phases",
    "Prediction",
    "Predictor",
    "SweepResult",
    "TrainConfig",
    "TrainState",
    "batch_indices",
    "create_train_state",
    "describe_specs",
    "examples_from_source",
    "gather",
    "get_config",
    "load_model",
    "save_model",
    "make_optimizer",
    "make_train_step",
    "model_fields",
    "resumed_step",
    "subset_specs",
    "sweep",
]
