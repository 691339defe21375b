"""The gradient planner improves a plan through the differentiable rollout and returns the best plan's true cost."""

import jax
import pytest

from pushjax.control import gradient
from tests.control import planning


def test_adam_through_the_rollout_lowers_the_cost_of_a_straight_push():
    config = gradient.GradientConfig(iterations=25, learning_rate=0.1)
    plan = jax.jit(gradient.plan, static_argnames=("weights", "config"))
    raw, value = plan(planning.MODEL, planning.POSE, planning.GOAL, planning.START, planning.STRAIGHT, planning.LIMIT,
                      planning.WEIGHTS, config)
    before = planning.cost_of(planning.STRAIGHT)
    assert float(value) == pytest.approx(planning.cost_of(raw), rel=1e-5)
    assert float(value) < 0.5 * before  # turning the object needs an off-centre push, which the gradient finds
