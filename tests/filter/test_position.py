"""The second observation model: a position reading of a point on the object (a perception network's centre of
mass), its Kalman update against NumPy's, a missing reading skipped."""

import numpy as np
import pytest

from pushjax.filter import models
from pushjax.geometry.objects import get_object


def _numpy_update(offset, std, mean, cov, position):
    """The EKF update with h(x) = x[:2] + R(x[2]) offset, linearised at `mean`, in float64 NumPy (standard form)."""
    cos, sin = np.cos(mean[2]), np.sin(mean[2])
    predicted = mean[:2] + np.array([cos * offset[0] - sin * offset[1], sin * offset[0] + cos * offset[1]])
    h = np.zeros((2, 5))
    h[:, :2] = np.eye(2)
    h[:, 2] = [-sin * offset[0] - cos * offset[1], cos * offset[0] - sin * offset[1]]
    s = h @ cov @ h.T + np.diag(np.square(std))
    gain = cov @ h.T @ np.linalg.inv(s)
    return mean + gain @ (position - predicted), (np.eye(5) - gain @ h) @ cov


def test_position_update_is_the_kalman_update_and_skips_a_missing_reading():
    sensor = models.make_position_sensor("tri2", std=(2e-3, 3e-3))
    offset = np.asarray(get_object("tri2").centroid, np.float64)
    assert np.linalg.norm(offset) > 0.005  # tri2's centre of mass is away from its tracked frame: h turns with yaw
    rng = np.random.default_rng(0)
    root = rng.normal(size=(5, 5)) * np.array([3e-3, 3e-3, 0.05, 0.3, 0.2])
    cov = root @ root.T + np.diag([1e-6, 1e-6, 1e-4, 1e-2, 1e-2])
    mean = np.array([0.01, -0.02, 0.7, 0.1, -0.05])
    position = np.asarray(models.observe_position(sensor, np.float32(mean)), np.float64) + np.array([4e-3, -2e-3])
    expected_mean, expected_cov = _numpy_update(offset, (2e-3, 3e-3), mean, cov, position)
    new_mean, new_cov = models.update_position(sensor, *(np.float32(x) for x in (mean, cov, position)))
    np.testing.assert_allclose(new_mean, expected_mean, rtol=0, atol=1e-5)
    np.testing.assert_allclose(new_cov, expected_cov, rtol=1e-3, atol=1e-5 * np.abs(cov).max())
    assert np.abs(np.asarray(new_mean) - mean).max() > 1e-3  # the reading moved the belief
    assert np.linalg.det(np.asarray(new_cov)[:3, :3]) < np.linalg.det(cov[:3, :3])
    # A missing reading (NaN in either coordinate) leaves the belief exactly as it was.
    for missing in (np.array([np.nan, np.nan]), np.array([0.0, np.nan])):
        kept_mean, kept_cov = models.update_position(sensor, mean.astype(np.float32), cov.astype(np.float32), missing)
        np.testing.assert_array_equal(kept_mean, mean.astype(np.float32))
        np.testing.assert_array_equal(kept_cov, cov.astype(np.float32))
    with pytest.raises(ValueError, match="std: expected 2 positive values"):
        models.make_position_sensor("tri2", std=(1e-3, 0.0))
