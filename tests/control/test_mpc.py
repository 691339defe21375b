"""The receding-horizon controller: configuration checks, a reposition when the pusher is away, and the goal reached
with the model as the plant."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.control import cost, model, mpc
from pushjax.studies import push_to_goal

CONFIG = push_to_goal.SCALES["smoke"].controller


@pytest.mark.parametrize("changes, message", [
    ({"planner": "newton"}, "planner"), ({"horizon": 0}, "horizon"), ({"replan_steps": 20}, "replan_steps"),
    ({"speed_limit": 0.0}, "speed_limit"), ({"push_fractions": (0.0,)}, "push_fractions")])
def test_bad_configurations_are_named(changes, message):
    with pytest.raises(ValueError, match=message):
        mpc.ControllerConfig(**changes)


def test_the_goal_is_reached_with_the_model_as_the_plant():
    push_model = model.make_model("rect1")
    goal = jnp.array([0.06, 0.03, 0.5])
    pose, pusher = jnp.zeros(3), jnp.array([-0.1, 0.0])
    state = mpc.init(CONFIG, jax.random.key(0))
    state, command = mpc.replan(CONFIG, push_model, state, pose, pusher, goal)
    assert bool(command.reposition)  # the pusher starts away from the object
    repositions = 0
    for _ in range(60):
        if command.reposition:
            repositions += 1
            pusher = command.waypoints[-1]
        else:
            steps = command.increments[:CONFIG.replan_steps]
            assert float(jnp.linalg.norm(steps, axis=-1).max()) < CONFIG.limit
            path = jnp.concatenate([pusher[None], pusher + jnp.cumsum(steps, axis=0)])
            pose, pusher = model.predict(push_model, pose, path).poses[-1], path[-1]
        position, yaw = cost.pose_error(pose, goal)
        if float(position) < 0.003 and abs(float(yaw)) < np.radians(3):
            break
        state, command = mpc.replan(CONFIG, push_model, state, pose, pusher, goal)
    assert float(position) < 0.003 and abs(float(yaw)) < np.radians(3)
    assert repositions >= 1
