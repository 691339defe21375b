"""One model's optimisation: its train state, the paper's optimiser, and the pure train step.

The one trainer (`pushjax.train.sweep_trainer.sweep`) jits, vmaps or unrolls `make_train_step` over the
models of a sweep.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import jax
import jax.numpy as jnp
import optax
from flax import struct

from pushjax.models import PushModel
from pushjax.train import losses
from pushjax.train.batching import Batch


@struct.dataclass
class TrainState:
    """Optimisation state of one model (or of K models, every leaf with a leading model axis).

    Attributes:
      step: [] int32 number of steps taken ([K] for K models).
      params: Flax `params` collection.
      batch_stats: Flax `batch_stats` collection (running batch-norm statistics; {} when none).
      opt_state: optax state.
    """

    step: jax.Array
    params: Any
    batch_stats: Any
    opt_state: Any


SCHEDULES = ("constant", "cosine")
"""Learning-rate schedules of `make_optimizer`."""


def make_optimizer(learning_rate: float, schedule: str = "constant", num_steps: int | None = None,
                   adjustable: bool = False) -> optax.GradientTransformation:
    """Adam with step size `learning_rate` (> 0): constant (the paper's) or decayed.

    Args:
      learning_rate: the (initial) step size.
      schedule: ``"constant"``, or ``"cosine"``: a cosine decay from `learning_rate` to 1 % of it over `num_steps`
        (after which it stays there).
      num_steps: the decay's length in steps (``"cosine"`` only).
      adjustable: the step size a hyperparameter of the optimiser's state (``opt_state.hyperparams
        ["learning_rate"]``, `optax.inject_hyperparams`), which the trainer sets step by step (a
        `pushjax.train.convergence.Criterion`'s decay); ``"constant"`` only.
    """
    if adjustable:
        if schedule != "constant":
            raise ValueError(f"schedule: an adjustable learning rate starts constant, got {schedule!r}")
        return optax.inject_hyperparams(optax.adam)(learning_rate=learning_rate)
    if schedule == "constant":
        return optax.adam(learning_rate)
    if schedule == "cosine":
        if not num_steps or num_steps < 1:
            raise ValueError(f"num_steps: the cosine schedule needs a positive number of steps, got {num_steps}")
        return optax.adam(optax.cosine_decay_schedule(learning_rate, num_steps, alpha=0.01))
    raise ValueError(f"schedule: expected one of {', '.join(SCHEDULES)}, got {schedule!r}")


def create_train_state(
    model: PushModel, optimizer: optax.GradientTransformation, example_batch: Batch, seed: int
) -> TrainState:
    """A freshly initialised state at step 0.

    Args:
      model: the model.
      optimizer: the optax transformation.
      example_batch: {field: [B, ...] array} with the model's fields (`model_fields`; only shapes
        and dtypes matter).
      seed: initialisation seed; the parameters are drawn from ``jax.random.key(seed)``.
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

    One gradient step on the loss of `losses.loss_for(model.config.variant, model.config.view)`,
    which returns ``(loss, metrics)``. Not jitted: jit it, or vmap and then jit it for a sweep.

    Args:
      model: the model.
      optimizer: the optax transformation.
      weight_decay: weight of the loss's penalty on the kernel weights (paper: 0.001).

    The returned ``train_step`` takes:
      state: one model's `TrainState`.
      batch: {field: [B, ...] array} with the model's fields (`model_fields`).
      error_options: None (use the variant's) or the [2] error-term flags of `PushModel.__call__`.
    and returns the state after the step (``step`` advanced by 1) and the loss's metrics before the
    update ({name: [] array}: ``loss`` and its terms, see `pushjax.train.losses`).
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
