"""The EKF's noise learned through the differentiable filter (pushjax.filter.noise) on a tiny problem: two testbed
pushes of rect1 at 5 Hz (the smoke scale's training pushes), measured by the realistic motion capture or by one with
three times its noise; and two pushes of the same size whose pusher stands still at the end."""

import functools

import jax
import numpy as np
import pytest

from pushjax.filter import metrics, models, noise
from pushjax.filter.observations import TrackedPush
from pushjax.geometry.objects import PUSHER_RADIUS, get_object
from pushjax.sim.testbed import REALISTIC
from pushjax.studies import tracking

RATE_HZ = 5.0
HAND_SET_MEASUREMENT_STD = np.array([REALISTIC.tracking_noise_xy, REALISTIC.tracking_noise_xy,
                                     REALISTIC.tracking_noise_yaw])
"""The measurement noise learning starts from: the realistic testbed's motion capture."""


@functools.cache
def _pushes(noise_scale: float) -> tuple[TrackedPush, ...]:
    """Two pushes of rect1 measured with `noise_scale` times the realistic testbed's motion-capture noise."""
    testbed = REALISTIC.with_overrides(f"tracking_noise_xy={noise_scale * REALISTIC.tracking_noise_xy};"
                                       f"tracking_noise_yaw={noise_scale * REALISTIC.tracking_noise_yaw}")
    return tuple(tracking.simulate_pushes(["rect1"], 2, seed=1, testbed=testbed, rate_hz=RATE_HZ))


def _problem(noise_scale: float):
    """(starting noise, latent prior std, systems, batches) of :func:`_pushes`."""
    groups = tracking.batches_by_object(_pushes(noise_scale))
    return (tracking.hand_set_noise(RATE_HZ, HAND_SET_MEASUREMENT_STD), np.asarray(tracking.LATENT_PRIOR_STD),
            tuple(system for system, _, _ in groups), tuple(batch for _, _, batch in groups))


def test_the_gradient_is_finite_and_reaches_every_parameter():
    starting, latent_prior_std, systems, batches = _problem(1.0)
    (value, metrics), gradient = noise.loss_and_gradient(starting, latent_prior_std, systems, batches)
    assert np.isfinite(value) and int(metrics["steps"]) == sum(len(push.pusher) for push in _pushes(1.0))
    for name, leaf in zip(("process", "measurement"), jax.tree_util.tree_leaves(gradient), strict=True):
        leaf = np.asarray(leaf)
        assert np.all(np.isfinite(leaf)) and np.all(leaf != 0), (name, leaf)


def test_the_loss_decreases():
    starting, latent_prior_std, systems, batches = _problem(1.0)
    _, curve = noise.learn(starting, latent_prior_std, systems, batches, steps=10)
    assert curve.shape == (11,) and np.all(np.isfinite(curve))
    assert curve[-1] < curve[0] - 0.1, curve


@pytest.mark.parametrize("noise_scale", [3.0, 1.0])
def test_the_learned_measurement_noise_moves_to_the_true_one(noise_scale):
    # From the realistic motion capture's noise, on pushes measured with `noise_scale` times it: three times
    # (learned close to 3, from 1) or the same (learned close to 1: nothing to correct).
    learned, curve = tracking.learn_noise(_pushes(noise_scale), RATE_HZ, HAND_SET_MEASUREMENT_STD, steps=60)
    ratio = np.exp(np.asarray(learned.log_measurement_std)) / HAND_SET_MEASUREMENT_STD
    assert np.all(np.abs(np.log(ratio / noise_scale)) < np.log(1.4)), ratio
    assert curve[-1] < curve[0], curve


def test_make_params_and_learn_name_bad_values():
    with pytest.raises(ValueError, match="measurement_std"):
        noise.make_params((1e-4,) * 5, (1e-4, 0.0, 1e-3))
    with pytest.raises(ValueError, match="process_std"):
        noise.make_params((1e-4,) * 4, (1e-4,) * 3)
    with pytest.raises(ValueError, match="steps"):
        noise.learn(*_problem(1.0), steps=-1)


def _normal_push_ending_still(moving: int = 12, still: int = 3, step: float = 2e-3) -> np.ndarray:
    """[moving + still + 1, 2] a pusher path into the middle of rect1's side 0 along its normal, `moving` steps of
    `step` m, then standing still for `still` steps moving by float noise (1e-16 m), as the testbed's pusher does."""
    surface, normal = get_object("rect1").side_point(0, 0.5)
    start = surface - normal * (PUSHER_RADIUS + 5e-4)
    moving_path = start + np.arange(moving + 1)[:, None] * step * normal
    jitter = 1e-16 * np.array([[1.0, 0.0], [0.0, -1.0], [1.0, 1.0]])[:still]
    return np.concatenate([moving_path, moving_path[-1] + jitter])


def test_a_pusher_standing_still_up_to_float_noise_keeps_the_gradient_finite():
    # Two pushes of the tests' size (16 samples at 5 Hz) along rect1's normal through its middle, by the analytical
    # rollout: in contact, a pusher moving by float noise once made the derivative of the EKF's Jacobian NaN
    # (pushjax.geometry.outline_jax now treats a motion under 1 fm as none).
    system = models.make_system("rect1", mu=0.25)
    path = _normal_push_ending_still()
    truth = np.asarray(metrics.simulate(system, np.zeros((1, 5)), path[None]), np.float64)[0]
    pushes = [TrackedPush(name=f"normal_{k}", obj="rect1", pusher=path,
                                   measurements=metrics.measure(truth, HAND_SET_MEASUREMENT_STD, 0.0, seed=k),
                                   truth=truth, mu_nominal=0.25, mu_true=0.25) for k in range(2)]
    ((system, _, batch),) = tracking.batches_by_object(pushes)
    assert np.all(batch.pusher == path) and np.any(np.diff(batch.pusher[:, -4:], axis=1) != 0.0)
    starting, latent_prior_std = _problem(1.0)[:2]
    _, gradient = noise.loss_and_gradient(starting, latent_prior_std, (system,), (batch,))
    assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree_util.tree_leaves(gradient))
