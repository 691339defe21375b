"""The controller closed on the MuJoCo testbed: a near goal reached under the realistic profile, the same seed giving
the same run; waypoints resampled at the speed limit; the state from a trained hybrid's perception of the depth
image instead of motion capture."""

import dataclasses
import math
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest

from pushjax import planar
from pushjax.control import goals, model, mpc
from pushjax.data import configs as data_configs
from pushjax.filter import models
from pushjax.geometry.objects import get_object
from pushjax.sensing import perception
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import REALISTIC
from pushjax.studies import episode, push_to_goal

CONFIG = push_to_goal.SCALES["smoke"].controller
"""The smoke run's controller (a short horizon: its programs compile faster, once for both)."""


def test_waypoint_targets_keep_the_step_and_the_multiple():
    targets = episode.waypoint_targets([0.0, 0.0], [[0.01, 0.0], [0.01, 0.003]], 0.001, 25)
    assert len(targets) % 25 == 0
    np.testing.assert_allclose(targets[-1], [0.01, 0.003])
    steps = np.linalg.norm(np.diff(np.concatenate([[[0.0, 0.0]], targets]), axis=0), axis=1)
    assert steps.max() <= 0.001 * (1 + 1e-9)
    np.testing.assert_allclose(targets[9], [0.01, 0.0])  # the corner is a target


@pytest.fixture(scope="module")
def episodes():
    planning_model = model.make_model("rect1")
    setup = episode.EpisodeConfig(max_time=20.0)
    assert setup.testbed == REALISTIC  # the default profile
    task = goals.Goal("rect1", 0, (0.0, 0.0, 0.0), (0.05, 0.02, 0.3))
    return [episode.run_episode(mpc, planning_model, CONFIG, task, seed=1, setup=setup) for _ in range(2)]


def test_a_near_goal_is_reached_on_the_realistic_testbed(episodes):
    result = episodes[0]
    assert result.stop == "reached", (result.position_error, result.yaw_error)
    assert goals.succeeded(result.position_error, result.yaw_error)
    assert result.repositions >= 1 and result.plans >= 3
    # the speed limit holds on the simulated pusher (its servo follows the commands closely)
    speeds = np.linalg.norm(np.diff(result.pusher[:, 1:], axis=0), axis=1) / np.diff(result.pusher[:, 0])
    assert speeds.max() < 1.1 * CONFIG.speed_limit
    assert result.path_length > math.hypot(0.05, 0.02)


class _Recording:
    """The MPC controller, recording the pusher friction of the model each plan is made with."""

    def __init__(self):
        self.mu = []

    def init(self, config, key):
        return mpc.init(config, key)

    def replan(self, config, planning_model, state, pose, pusher, goal):
        self.mu.append(float(planning_model.mu))
        return mpc.replan(config, planning_model, state, pose, pusher, goal)


def test_the_filters_friction_is_planned_with_when_asked():
    # A low pusher friction in the world: the EKF's latent friction moves from the model's 0.25, and each plan is made
    # with what it infers by then; without the setting every plan uses the model's own.
    task = goals.Goal("rect1", 0, (0.0, 0.0, 0.0), (0.05, 0.02, 0.3))
    setup = episode.EpisodeConfig(max_time=6.0, effects=Effects(pusher_friction=0.1))
    plain, filtered = _Recording(), _Recording()
    episode.run_episode(plain, model.make_model("rect1"), CONFIG, task, seed=1, setup=setup)
    episode.run_episode(filtered, model.make_model("rect1"), CONFIG, task, seed=1,
                        setup=dataclasses.replace(setup, filtered_friction=True))
    assert plain.mu == pytest.approx([0.25] * len(plain.mu)) and len(plain.mu) >= 5
    assert filtered.mu[0] == pytest.approx(0.25) and len(set(filtered.mu)) > 3
    assert filtered.mu[-1] < 0.2  # towards the world's 0.1


def test_the_same_seed_gives_the_same_run(episodes):
    first, second = episodes
    np.testing.assert_array_equal(first.poses, second.poses)
    np.testing.assert_array_equal(first.estimates, second.estimates)
    # The whole episode at 250 Hz, as a push file holds it: every stream from the first sample to the last pose.
    recording = first.recording
    samples = round(first.time / 0.004)
    np.testing.assert_allclose(recording.tip_pose[:, 0], np.arange(1, samples + 1) * 0.004)
    assert len(recording.ft_wrench) == len(recording.true_object_pose) == samples
    assert 0.9 * samples < len(recording.object_pose) <= samples  # motion capture drops a few
    np.testing.assert_array_equal(recording.true_object_pose[-1], first.poses[-1])
    np.testing.assert_array_equal(recording.object_pose, second.recording.object_pose)


PERCEPTION_MODEL = Path(__file__).resolve().parents[2] / "results" / "track_perception" / "model"
"""The committed hybrid (``experiments.data_efficiency_full``'s, cpu_full data) that ``tests/studies/test_track.py``
also reads: a real trained network, read only."""


@pytest.fixture(scope="module")
def perceived():
    """A short episode twice with the state from the hybrid's perception of the rendered depth image alone (no motion
    capture), a reading every other control period, the noise of RESULTS.md's perception readings (0.5 mm)."""
    sensor = perception.load(PERCEPTION_MODEL, data_configs.get_config("data_efficiency", "cpu_full"))
    source = episode.PositionSource(sensor.locate, (5e-4, 5e-4), every=2, description=sensor.description)
    task = goals.Goal("rect1", 0, (0.0, 0.0, 0.0), (0.08, 0.0, 0.0))
    return [episode.run_episode(mpc, model.make_model("rect1"), CONFIG, task, seed=2,
                                setup=episode.EpisodeConfig(max_time=3.0),
                                sensors=episode.Sensors(motion_capture=False, position=source)) for _ in range(2)]


def test_perception_alone_gives_the_episode_its_state_and_the_same_seed_the_same_run(perceived):
    first, second = perceived
    np.testing.assert_array_equal(first.readings, second.readings)
    np.testing.assert_array_equal(first.estimates, second.estimates)
    np.testing.assert_array_equal(first.poses, second.poses)
    # a reading every other control period (0.2 s), of the true scene's centre of mass
    np.testing.assert_allclose(np.diff(first.readings[:, 0]), 2 * CONFIG.period, atol=1e-6)
    truth = {round(t / CONFIG.period): pose for t, *pose in first.poses}
    shape = get_object("rect1")
    errors = [np.hypot(*(reading - planar.centre_of_mass(shape.centroid, truth[round(t / CONFIG.period)])))
              for t, *reading in first.readings]
    assert len(errors) >= 10 and np.max(errors) < 0.003, errors
    # the filtered poses the plans start from follow the true pose though no motion capture is read
    assert first.plans >= 5 and np.ptp(first.estimates[:, 0]) > 0.005
    wrong = [np.hypot(*(estimate[:2] - truth[round(t / CONFIG.period)][:2]))
             for t, estimate in zip(first.estimate_times, first.estimates)]
    assert np.max(wrong) < 0.003, wrong


def test_the_episode_without_motion_capture_needs_a_position_source():
    with pytest.raises(ValueError, match="position source"):
        episode.Sensors(motion_capture=False)
    with pytest.raises(ValueError, match="every"):
        episode.PositionSource(lambda obj, poses, pushers: poses[:, :2], (5e-4, 5e-4), every=0)
    with pytest.raises(ValueError, match="std"):
        episode.PositionSource(lambda obj, poses, pushers: poses[:, :2], (5e-4, 0.0))


def test_the_gate_skips_a_reading_far_from_the_prediction():
    sensor = models.make_position_sensor("tri2", (5e-4, 5e-4))
    mean = jnp.array([0.1, 0.0, 0.3, 0.0, 0.0], jnp.float32)
    cov = jnp.diag(jnp.array([1e-3, 1e-3, 0.02, 0.3, 0.3], jnp.float32) ** 2)
    centre = jnp.asarray(planar.centre_of_mass(get_object("tri2").centroid, np.asarray(mean[:3])), jnp.float32)
    near, far = centre + jnp.array([1e-3, -1e-3]), centre + jnp.array([0.03, 0.0])  # far: 30 standard deviations off
    for reading, expected in ((near, True), (far, False)):
        new_mean, new_cov, used = episode.position_update(sensor, mean, cov, reading, 13.8)
        assert bool(used) == expected
        reference = models.update_position(sensor, mean, cov, reading) if expected else (mean, cov)
        np.testing.assert_allclose(new_mean, reference[0], rtol=1e-5, atol=1e-7)
        np.testing.assert_allclose(new_cov, reference[1], rtol=1e-5, atol=1e-10)
    with pytest.raises(ValueError, match="gate"):
        episode.PositionSource(lambda obj, poses, pushers: poses[:, :2], (5e-4, 5e-4), gate=0.0)
