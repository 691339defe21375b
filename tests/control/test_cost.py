"""The plan cost: zero at the goal, orientation wrapped, the parts weighted as documented; `plan_cost` costs the
model's rollout."""

import math

import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.control import cost, model, path

WEIGHTS = cost.CostWeights()


def test_wrap_and_pose_error():
    np.testing.assert_allclose(cost.wrap(jnp.array([3 * math.pi / 2, -3 * math.pi / 2, 0.1])),
                               [-math.pi / 2, math.pi / 2, 0.1], atol=1e-6)
    position, yaw = cost.pose_error(jnp.array([0.03, 0.04, math.pi - 0.05]), jnp.array([0.0, 0.0, -math.pi + 0.05]))
    assert float(position) == pytest.approx(0.05)
    assert float(yaw) == pytest.approx(-0.1, abs=1e-6)  # across +-pi, not 2 pi - 0.1


def test_trajectory_cost_parts():
    goal = jnp.array([0.01, 0.0, 0.1])
    at_goal = jnp.tile(goal, (4, 1))
    zero_steps = jnp.zeros((3, 2))
    value, metrics = cost.trajectory_cost(at_goal, zero_steps, goal, 0.004, WEIGHTS)
    assert float(value) == 0.0 and set(metrics) == {"terminal", "running", "effort"}
    poses = at_goal.at[-1, 0].add(WEIGHTS.position_scale).at[-1, 2].add(WEIGHTS.yaw_scale)
    steps = jnp.full((3, 2), 0.004 / math.sqrt(2))
    value, metrics = cost.trajectory_cost(poses, steps, goal, 0.004, WEIGHTS)
    assert float(metrics["terminal"]) == pytest.approx(2.0, rel=1e-4)
    assert float(metrics["running"]) == pytest.approx(2.0 / 3, rel=1e-4)
    assert float(metrics["effort"]) == pytest.approx(1.0, rel=1e-5)
    expected = 2.0 + WEIGHTS.running_weight * 2.0 / 3 + WEIGHTS.effort_weight
    assert float(value) == pytest.approx(expected, rel=1e-4)


def test_plan_cost_is_the_cost_of_the_models_rollout():
    push_model = model.make_model("rect1")
    pose, goal = jnp.zeros(3), jnp.array([0.02, 0.0, 0.0])
    start = jnp.array([-0.06, 0.0])
    raw = path.raw_for(jnp.tile(jnp.array([0.0038, 0.0]), (6, 1)), 0.004)
    value, _ = cost.plan_cost(push_model, pose, goal, start, raw, 0.004, WEIGHTS)
    positions = path.pusher_path(start, raw, 0.004)
    poses = model.predict(push_model, pose, positions).poses
    expected, _ = cost.trajectory_cost(poses, jnp.diff(positions, axis=0), goal, 0.004, WEIGHTS)
    assert float(value) == pytest.approx(float(expected))
    assert float(poses[-1, 0]) > 0.005  # the push reached the object and moved it towards the goal
