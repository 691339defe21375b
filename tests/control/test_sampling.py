"""The cross-entropy planner lowers the cost, returns the best sample's true cost, and is reproducible per key."""

import jax
import numpy as np
import pytest

from pushjax.control import sampling
from tests.control import planning

PLAN = jax.jit(sampling.plan, static_argnames=("weights", "config"))
CONFIG = sampling.SamplingConfig(iterations=4, samples=48, elites=6)


def _plan(key):
    return PLAN(planning.MODEL, planning.POSE, planning.GOAL, planning.START, planning.STRAIGHT, planning.LIMIT,
                planning.WEIGHTS, CONFIG, key)


def test_sampling_lowers_the_cost_and_is_reproducible():
    raw, value = _plan(jax.random.key(0))
    assert float(value) == pytest.approx(planning.cost_of(raw), rel=1e-5)
    assert float(value) < 0.5 * planning.cost_of(planning.STRAIGHT)
    again, _ = _plan(jax.random.key(0))
    other, _ = _plan(jax.random.key(1))
    np.testing.assert_array_equal(raw, again)
    assert np.abs(np.asarray(raw) - np.asarray(other)).max() > 0


def test_elites_must_fit_the_samples():
    with pytest.raises(ValueError, match="elites"):
        sampling.plan(planning.MODEL, planning.POSE, planning.GOAL, planning.START, planning.STRAIGHT, planning.LIMIT,
                      planning.WEIGHTS, sampling.SamplingConfig(samples=4, elites=5), jax.random.key(0))
