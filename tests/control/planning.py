"""A small planning problem shared by the planner tests: rect1 at the origin, the pusher behind its -x side, a goal
2 cm ahead and turned by 0.2 rad, which a straight push along +x does not reach."""

import jax.numpy as jnp

from pushjax.control import cost, model, path

HORIZON = 8
LIMIT = 0.004
WEIGHTS = cost.CostWeights()
MODEL = model.make_model("rect1")
POSE = jnp.zeros(3)
GOAL = jnp.array([0.02, 0.0, 0.2])
START = jnp.array([-0.045 - 0.0048 - 0.002, 0.0])
STRAIGHT = path.raw_for(jnp.tile(jnp.array([0.8 * LIMIT, 0.0]), (HORIZON, 1)), LIMIT)


def cost_of(raw):
    return float(cost.plan_cost(MODEL, POSE, GOAL, START, raw, LIMIT, WEIGHTS)[0])
