"""Planning by sampling: the cross-entropy method over plans, every sample's rollout in one ``jax.vmap``.

Each iteration draws ``samples`` plans from a Gaussian around the current mean (the first sample is the mean
itself), predicts them all at once, and refits the mean and the standard deviation to the ``elites`` cheapest.
The best plan seen is returned. The plan's parametrisation (:mod:`pushjax.control.path`) keeps every sample
within the speed limit.
"""

from __future__ import annotations

import flax.struct
import jax
import jax.numpy as jnp

from pushjax.control import cost as cost_lib
from pushjax.control.model import PlanningModel

__all__ = ["SamplingConfig", "plan"]


@flax.struct.dataclass
class SamplingConfig:
    """Static settings of the cross-entropy planner.

    Attributes:
      iterations: refits per plan.
      samples: plans drawn per iteration.
      elites: the cheapest plans the Gaussian is refitted to.
      initial_std: standard deviation of the first iteration, raw plan units.
      min_std: floor of the standard deviation.
    """

    iterations: int = flax.struct.field(pytree_node=False, default=4)
    samples: int = flax.struct.field(pytree_node=False, default=64)
    elites: int = flax.struct.field(pytree_node=False, default=8)
    initial_std: float = flax.struct.field(pytree_node=False, default=0.7)
    min_std: float = flax.struct.field(pytree_node=False, default=0.05)


def plan(model: PlanningModel, pose, goal, start, raw, limit, weights: cost_lib.CostWeights, config: SamplingConfig,
         key):
    """The cheapest plan the cross-entropy method finds around the initial plan `raw` [H, 2].

    Arguments as :func:`pushjax.control.gradient.plan`; `key` is the sampling's PRNG key.

    Returns:
      ([H, 2] the best plan, [] its cost).
    """
    if not 0 < config.elites <= config.samples:
        raise ValueError(f"elites: expected 1 to samples = {config.samples}, got {config.elites}")
    costs_of = jax.vmap(lambda candidate: cost_lib.plan_cost(model, pose, goal, start, candidate, limit, weights)[0])

    def body(carry, iteration_key):
        mean, std, best, best_cost = carry
        noise = jax.random.normal(iteration_key, (config.samples, *mean.shape), mean.dtype).at[0].set(0.0)
        candidates = mean + std * noise
        costs = costs_of(candidates)
        order = jnp.argsort(costs)
        elites = candidates[order[:config.elites]]
        better = costs[order[0]] < best_cost
        best = jnp.where(better, candidates[order[0]], best)
        best_cost = jnp.where(better, costs[order[0]], best_cost)
        std = jnp.maximum(jnp.std(elites, axis=0), config.min_std)
        return (jnp.mean(elites, axis=0), std, best, best_cost), None

    initial = (raw, jnp.full_like(raw, config.initial_std), raw, jnp.asarray(jnp.inf, raw.dtype))
    (_, _, best, best_cost), _ = jax.lax.scan(body, initial, jax.random.split(key, config.iterations))
    return best, best_cost
