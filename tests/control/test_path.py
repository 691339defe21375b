"""The plan's parametrisation: the speed limit holds for any raw plan, and `raw_for` inverts it."""

import jax.numpy as jnp
import numpy as np

from pushjax.control import path


def test_no_increment_exceeds_the_limit_whatever_the_raw_plan():
    raw = np.random.default_rng(0).normal(scale=100.0, size=(50, 2))
    steps = np.asarray(path.increments(jnp.asarray(raw), 0.004))
    assert np.linalg.norm(steps, axis=-1).max() < 0.004
    np.testing.assert_allclose(steps / np.linalg.norm(steps, axis=-1, keepdims=True),
                               raw / np.linalg.norm(raw, axis=-1, keepdims=True), rtol=1e-5)


def test_raw_for_inverts_the_increments_and_clips_at_095_of_the_limit():
    steps = jnp.array([[0.001, -0.002], [0.0, 0.0], [0.01, 0.0]])
    got = np.asarray(path.increments(path.raw_for(steps, 0.004), 0.004))
    np.testing.assert_allclose(got[:2], steps[:2], atol=1e-9)
    np.testing.assert_allclose(got[2], [0.95 * 0.004, 0.0], rtol=1e-5)


def test_pusher_path_starts_at_the_pusher_and_sums_the_steps():
    raw = jnp.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    positions = np.asarray(path.pusher_path(jnp.array([0.1, 0.2]), raw, 0.004))
    assert positions.shape == (4, 2)
    np.testing.assert_allclose(positions[0], [0.1, 0.2])
    np.testing.assert_allclose(positions[-1], positions[0] + np.asarray(path.increments(raw, 0.004)).sum(0), atol=1e-7)


def test_shifted_moves_the_rest_to_the_front_and_repeats_the_last_step():
    raw = jnp.arange(10.0).reshape(5, 2)
    np.testing.assert_array_equal(path.shifted(raw, 2), [[4, 5], [6, 7], [8, 9], [8, 9], [8, 9]])
