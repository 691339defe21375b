"""The controller closed on the MuJoCo testbed: a near goal reached under the realistic profile, the same seed giving
the same run; waypoints resampled at the speed limit."""

import math

import numpy as np
import pytest

from pushjax.control import closed_loop, goals, model, push_to_goal
from pushjax.sim.testbed import REALISTIC

CONFIG = push_to_goal.SCALES["smoke"]["controller"]
"""The smoke run's controller (a short horizon: its programs compile faster, once for both)."""


def test_waypoint_targets_keep_the_step_and_the_multiple():
    targets = closed_loop.waypoint_targets([0.0, 0.0], [[0.01, 0.0], [0.01, 0.003]], 0.001, 25)
    assert len(targets) % 25 == 0
    np.testing.assert_allclose(targets[-1], [0.01, 0.003])
    steps = np.linalg.norm(np.diff(np.concatenate([[[0.0, 0.0]], targets]), axis=0), axis=1)
    assert steps.max() <= 0.001 * (1 + 1e-9)
    np.testing.assert_allclose(targets[9], [0.01, 0.0])  # the corner is a target


@pytest.fixture(scope="module")
def episodes():
    push_model = model.make_model("rect1")
    loop = closed_loop.LoopConfig(max_time=20.0)
    assert loop.testbed == REALISTIC  # the default profile
    return [closed_loop.run_episode(push_model, CONFIG, "rect1", (0.0, 0.0, 0.0), (0.05, 0.02, 0.3), seed=1,
                                    loop=loop) for _ in range(2)]


def test_a_near_goal_is_reached_on_the_realistic_testbed(episodes):
    result = episodes[0]
    assert result.stop == "reached", (result.position_error, result.yaw_error)
    assert goals.succeeded(result.position_error, result.yaw_error)
    assert result.repositions >= 1 and result.plans >= 3
    # the speed limit holds on the simulated pusher (its servo follows the commands closely)
    speeds = np.linalg.norm(np.diff(result.pusher[:, 1:], axis=0), axis=1) / np.diff(result.pusher[:, 0])
    assert speeds.max() < 1.1 * CONFIG.speed_limit
    assert result.path_length > math.hypot(0.05, 0.02)


def test_the_same_seed_gives_the_same_run(episodes):
    first, second = episodes
    np.testing.assert_array_equal(first.poses, second.poses)
    np.testing.assert_array_equal(first.estimates, second.estimates)
