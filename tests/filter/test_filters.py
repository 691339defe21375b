"""The filters on pushes simulated by the analytical rollout with known parameters, measured with noise and dropped
samples: tracking beats the raw measurements, NEES inside its chi-square band, mu identified only where it slips."""

import functools

import jax
import numpy as np
import pytest

from pushjax import planar
from pushjax.filter import ekf, metrics, models, particle, ukf
from pushjax.geometry.objects import PUSHER_RADIUS, get_object

MU_NOMINAL = 0.3
MEASUREMENT_STD = (1e-3, 1e-3, np.radians(1.0))
PRIOR_STD = np.array([1e-3, 1e-3, np.radians(1.0), 0.5, 0.3])
SLIPPING, STICKING = [0, 1], [2, 3]
"""Pushes 0, 1 go in at 35-40° off the normal with mu 0.15 (they slip); 2, 3 along the normal (they stick)."""
TRUE_LOG_MU = np.log(np.array([0.15, 0.15, 0.6, 0.6]) / MU_NOMINAL)
TRUE_LOG_L = 0.1


def _path(side, point, angle_deg, steps=20, distance=0.05):
    obj = get_object("rect1")
    surface_point, normal = obj.side_point(side, point)
    direction = planar.rotation_matrix(np.deg2rad(angle_deg)) @ normal
    start = surface_point - direction * (PUSHER_RADIUS / (direction @ normal) + 5e-4)
    return start + np.linspace(0.0, 1.0, steps + 1)[:, None] * distance * direction


@functools.cache
def _scenario():
    system = models.make_system("rect1", mu=MU_NOMINAL, process_std=(1e-4, 1e-4, 1e-3, 1e-3, 1e-3),
                                measurement_std=MEASUREMENT_STD)
    paths = np.stack([_path(0, 0.3, 35.0), _path(1, 0.6, -40.0), _path(2, 0.5, 0.0), _path(3, 0.5, 0.0)])
    true_state = np.stack([np.zeros(4), np.zeros(4), np.zeros(4), TRUE_LOG_MU, np.full(4, TRUE_LOG_L)], axis=-1)
    truth = np.asarray(metrics.simulate(system, true_state, paths))
    measurements = metrics.measure(truth, MEASUREMENT_STD, drop_rate=0.1, seed=0)
    mean = np.concatenate([measurements[:, 0], np.zeros((4, 2))], axis=-1)
    cov = np.broadcast_to(np.diag(PRIOR_STD ** 2), (4, 5, 5))
    return system, paths, truth, measurements, mean, cov


@functools.cache
def _track(name):
    system, paths, _, measurements, mean, cov = _scenario()
    if name == "particle":
        keys = jax.random.split(jax.random.key(0), len(paths))
        track = particle.filter_pushes(system, keys, mean, cov, paths, measurements, count=512)
    else:
        track = {"ekf": ekf, "ukf": ukf}[name].filter_pushes(system, mean, cov, paths, measurements)
    return jax.tree_util.tree_map(np.asarray, track)


FILTERS = ["ekf", "ukf", "particle"]


def test_the_scenario_has_what_the_tests_need():
    _, _, truth, measurements, _, _ = _scenario()
    motion = np.abs(truth[:, -1] - truth[:, 0])
    assert np.all(motion[:, :2].max(-1) > 0.02)  # every push moves the object
    assert np.all(motion[SLIPPING, 2] > 0.2)  # the slipping pushes turn it
    assert 0.05 < np.mean(np.isnan(measurements[..., 0])) < 0.2


@pytest.mark.parametrize("name", FILTERS)
def test_tracking_beats_the_raw_measurements(name):
    _, _, truth, measurements, _, _ = _scenario()
    track = _track(name)
    assert np.all(np.isfinite(track.mean)) and np.all(np.isfinite(track.cov))
    raw_position, raw_yaw = metrics.rmse(measurements, truth)
    position, yaw = metrics.rmse(track.mean[..., :3], truth)
    assert position < 0.7 * raw_position and yaw < 0.8 * raw_yaw, (position, raw_position, yaw, raw_yaw)


@pytest.mark.parametrize("name", FILTERS)
def test_nees_lies_mostly_in_its_95_percent_band(name):
    _, _, truth, _, _, _ = _scenario()
    track = _track(name)
    low, high = metrics.chi2_band(3)
    nees = metrics.nees(track.mean, track.cov, truth)
    assert np.mean((nees > low) & (nees < high)) > 0.75


@pytest.mark.parametrize("name", FILTERS)
def test_mu_converges_where_the_contact_slips_and_stays_open_where_it_sticks(name):
    track = _track(name)
    log_mu, std = track.mean[:, -1, 3], np.sqrt(track.cov[:, -1, 3, 3])
    # Slipping: from 0.69 (1.4 prior standard deviations) off to within 0.35 of the truth, with a narrow posterior.
    assert np.all(np.abs(log_mu[SLIPPING] - TRUE_LOG_MU[SLIPPING]) < 0.35), log_mu
    assert np.all(std[SLIPPING] < 0.5 * PRIOR_STD[3]), std
    # Sticking along the normal: mu does not show in the motion at all, the posterior stays at the prior's width
    # (the Kalman filters' linearisation keeps it exactly; the particle set's spread drifts by sampling noise).
    assert np.all(std[STICKING] > (0.6 if name == "particle" else 0.95) * PRIOR_STD[3]), std


def test_a_dropped_sample_is_skipped_not_read_as_zero():
    system, paths, truth, measurements, mean, cov = _scenario()
    push, k = 0, 10
    dropped, zero = measurements.copy(), measurements.copy()
    dropped[push, k] = np.nan
    zero[push, k] = 0.0
    with_nan = jax.tree_util.tree_map(np.asarray, ekf.filter_pushes(system, mean, cov, paths, dropped))
    with_zero = jax.tree_util.tree_map(np.asarray, ekf.filter_pushes(system, mean, cov, paths, zero))
    assert not with_nan.observed[push, k] and with_zero.observed[push, k]
    # Skipped: the belief at k is the prediction from k - 1.
    predicted_mean, predicted_cov = jax.jit(ekf.predict)(system, with_nan.mean[push, k - 1], with_nan.cov[push, k - 1],
                                                paths[push, k - 1], paths[push, k] - paths[push, k - 1])
    np.testing.assert_allclose(with_nan.mean[push, k], predicted_mean, rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(with_nan.cov[push, k], predicted_cov, rtol=1e-4, atol=1e-12)
    # A zero would have been read as a pose at the origin and moved the estimate.
    position_nan, _ = metrics.pose_errors(with_nan.mean[push, k, :3], truth[push, k])
    assert position_nan < 1e-3
    assert np.linalg.norm(with_zero.mean[push, k, :2] - with_nan.mean[push, k, :2]) > 5e-4


def test_make_system_names_bad_arguments():
    with pytest.raises(ValueError, match="process_std"):
        models.make_system("rect1", process_std=(1e-4,) * 3)
    with pytest.raises(ValueError, match="measurement_std"):
        models.make_system("rect1", measurement_std=(0.0, 1e-3, 1e-3))
    with pytest.raises(ValueError, match="mu, l"):
        models.make_system("rect1", mu=-1.0)


def test_the_ekf_tracks_with_the_exact_limit_surface_and_identifies_mu_where_it_slips():
    system = models.make_system("rect1", mu=MU_NOMINAL, process_std=(1e-4, 1e-4, 1e-3, 1e-3, 1e-3),
                                measurement_std=MEASUREMENT_STD, effects=("limit_surface",),
                                params={"limit_surface": {"rim": 1.0, "feet": 0.0}})
    assert system.support is not None
    paths = np.stack([_path(0, 0.3, 35.0), _path(1, 0.6, -40.0)])
    true_state = np.stack([np.zeros(2), np.zeros(2), np.zeros(2), TRUE_LOG_MU[SLIPPING], np.zeros(2)], axis=-1)
    truth = np.asarray(metrics.simulate(system, true_state, paths))
    measurements = metrics.measure(truth, MEASUREMENT_STD, drop_rate=0.1, seed=1)
    mean = np.concatenate([measurements[:, 0], np.zeros((2, 2))], axis=-1)
    track = ekf.filter_pushes(system, mean, np.broadcast_to(np.diag(PRIOR_STD ** 2), (2, 5, 5)), paths, measurements)
    position, _ = metrics.rmse(np.asarray(track.mean[..., :3]), truth)
    assert position < 0.7 * metrics.rmse(measurements, truth)[0]
    assert np.all(np.abs(np.asarray(track.mean[:, -1, 3]) - TRUE_LOG_MU[SLIPPING]) < 0.35), track.mean[:, -1, 3]
