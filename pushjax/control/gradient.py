"""Planning by gradient descent through the differentiable rollout: Adam (optax) on the plan's raw parameters.

The cost (:func:`pushjax.control.cost.plan_cost`) is differentiated with ``jax.value_and_grad`` through the
``lax.scan`` rollout, the contact annotated again at every step; the iterations are a ``lax.scan`` too, so one
plan is one compiled call. The best plan seen (not the last iterate) is returned: the cost is piecewise smooth
(contact features and stick/slip modes switch), so an Adam step may go up.
"""

from __future__ import annotations

import flax.struct
import jax
import jax.numpy as jnp
import optax

from pushjax.control import cost as cost_lib
from pushjax.control.model import PlanningModel

__all__ = ["GradientConfig", "plan"]


@flax.struct.dataclass
class GradientConfig:
    """Static settings of the gradient planner.

    Attributes:
      iterations: Adam steps per plan.
      learning_rate: Adam's step size, in units of the raw plan (one unit is about 0.7 of the largest step).
    """

    iterations: int = flax.struct.field(pytree_node=False, default=30)
    learning_rate: float = flax.struct.field(pytree_node=False, default=0.1)


def plan(model: PlanningModel, pose, goal, start, raw, limit, weights: cost_lib.CostWeights, config: GradientConfig,
         key=None):
    """The best plan found by Adam from the initial plan `raw` [H, 2].

    Args:
      model: the :class:`~pushjax.control.model.PlanningModel`.
      pose: [3] object pose now (x m, y m, yaw rad).
      goal: [3] goal pose.
      start: [2] pusher position now, world, m.
      raw: [H, 2] initial plan (:mod:`pushjax.control.path`).
      limit: [] largest pusher increment per step, m.
      weights: the cost's :class:`~pushjax.control.cost.CostWeights`.
      config: the :class:`GradientConfig`.
      key: unused (the sampling planner's signature).

    Returns:
      ([H, 2] the best plan, [] its cost).
    """
    del key
    optimizer = optax.adam(config.learning_rate)

    def objective(candidate):
        return cost_lib.plan_cost(model, pose, goal, start, candidate, limit, weights)[0]

    value_and_grad = jax.value_and_grad(objective)

    def body(carry, _):
        candidate, opt_state, best, best_cost = carry
        value, gradient = value_and_grad(candidate)
        better = value < best_cost
        best = jnp.where(better, candidate, best)
        best_cost = jnp.where(better, value, best_cost)
        updates, opt_state = optimizer.update(gradient, opt_state, candidate)
        return (optax.apply_updates(candidate, updates), opt_state, best, best_cost), value

    initial = (raw, optimizer.init(raw), raw, jnp.asarray(jnp.inf, raw.dtype))
    (last, _, best, best_cost), _ = jax.lax.scan(body, initial, None, length=config.iterations)
    last_cost = objective(last)
    return jnp.where(last_cost < best_cost, last, best), jnp.minimum(last_cost, best_cost)
