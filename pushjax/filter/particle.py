"""Particle filter (optimal proposal for the pose, systematic resampling) over the pose and the latent parameters.

Each particle is a state (:mod:`pushjax.filter.models`) propagated through the rollout step, ``f(x)``, with Gaussian
process noise ``Q`` (:attr:`~pushjax.filter.models.System.process_std`). Because the pose measurement is linear
with Gaussian noise ``R``, the pose part is drawn from the optimal proposal ``p(pose_k | x_{k-1}, z_k)``: Gaussian
with variance ``(Q^-1 + R^-1)^-1`` about ``f(x)`` moved towards ``z_k`` (yaw innovation wrapped), and the weight
multiplies by ``N(z_k; f(x)_pose, Q + R)``. A bootstrap filter (propose from ``f(x) + noise``, weight by
``N(z_k; pose, R)``) collapses onto a few particles when the motion capture is much more precise than the model,
as on the testbed (0.2 mm against a model error of about that per step). A dropped (NaN) sample leaves the
proposal at ``f(x) + noise`` and the weights unchanged. The particles are resampled (systematic) when the
effective sample size falls below half their number. Resampling alone would let the latents, which have almost no
process noise, collapse onto a few values; a resampled set is therefore regularised with Liu & West's kernel (2001;
discount ``DISCOUNT``): each particle is shrunk towards the mean by ``a = (3 delta - 1) / (2 delta)`` and moved by
Gaussian noise of covariance ``(1 - a^2) P``, which keeps the particles' mean and covariance ``P``. The belief
reported at each step is the weighted mean and covariance of the particles. Needs a PRNG key; jit-compiled, vmapped
over pushes with one key per push.
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp

from pushjax.filter import models

__all__ = ["DISCOUNT", "filter_push", "filter_pushes"]

DISCOUNT = 0.98
"""Liu & West's discount factor delta of the regularisation after resampling."""


def _moments(particles, log_weights):
    weights = jax.nn.softmax(log_weights)
    mean = weights @ particles
    deviation = particles - mean
    cov = (weights[:, None] * deviation).T @ deviation
    return mean, 0.5 * (cov + cov.T)


def _update(system, particles, log_weights, measurement):
    innovations = jax.vmap(models.innovation, in_axes=(None, 0))(measurement, models.observe(particles))
    log_likelihood = -0.5 * jnp.sum((innovations / system.measurement_std) ** 2, axis=-1)
    log_weights = log_weights + jnp.where(models.observed(measurement), log_likelihood, 0.0)
    return log_weights - jax.scipy.special.logsumexp(log_weights)


def _propose(system, key, predicted, log_weights, measurement):
    """Particles drawn from the optimal proposal for the pose (the prediction where the sample is dropped) and the
    latents' random walk, and their weights times ``N(z; predicted pose, Q + R)``."""
    q = system.process_std[:models.POSE_SIZE] ** 2
    r = system.measurement_std ** 2
    present = models.observed(measurement)
    innovations = jax.vmap(models.innovation, in_axes=(None, 0))(measurement, models.observe(predicted))
    pose_mean = predicted[:, :models.POSE_SIZE] + jnp.where(present, q / (q + r), 0.0) * innovations
    pose_std = jnp.sqrt(jnp.where(present, q * r / (q + r), q))
    noise = jax.random.normal(key, predicted.shape, predicted.dtype)
    particles = jnp.concatenate([pose_mean + pose_std * noise[:, :models.POSE_SIZE],
                                 predicted[:, models.POSE_SIZE:]
                                 + system.process_std[models.POSE_SIZE:] * noise[:, models.POSE_SIZE:]], axis=-1)
    log_likelihood = -0.5 * jnp.sum(innovations ** 2 / (q + r), axis=-1)
    log_weights = log_weights + jnp.where(present, log_likelihood, 0.0)
    return particles, log_weights - jax.scipy.special.logsumexp(log_weights)


def _resample(key, particles, log_weights):
    count, size = particles.shape
    weights = jax.nn.softmax(log_weights)
    effective = 1.0 / jnp.sum(weights ** 2)
    position_key, kernel_key = jax.random.split(key)
    positions = (jax.random.uniform(position_key, (), dtype=particles.dtype) + jnp.arange(count)) / count
    indices = jnp.clip(jnp.searchsorted(jnp.cumsum(weights), positions), 0, count - 1)
    mean, cov = _moments(particles, log_weights)
    shrink = (3 * DISCOUNT - 1) / (2 * DISCOUNT)
    root = jnp.linalg.cholesky(cov + (1e-6 * jnp.max(jnp.diag(cov)) + 1e-24) * jnp.eye(size, dtype=cov.dtype))
    noise = jax.random.normal(kernel_key, particles.shape, particles.dtype) @ root.T
    regularised = shrink * particles[indices] + (1 - shrink) * mean + jnp.sqrt(1 - shrink ** 2) * noise
    resample = effective < count / 2
    uniform = jnp.full(count, -jnp.log(count), log_weights.dtype)
    return jnp.where(resample, regularised, particles), jnp.where(resample, uniform, log_weights)


@functools.partial(jax.jit, static_argnames=("count",))
def filter_push(system: models.System, key, mean, cov, pusher_path, measurements, count: int = 256) -> models.Track:
    """Filters one push with `count` particles drawn from the Gaussian prior (mean [5], cov [5, 5]); other
    arguments and the result as :func:`pushjax.filter.ekf.filter_push`."""
    key, draw = jax.random.split(key)
    particles = jax.random.multivariate_normal(draw, mean, cov, (count,), dtype=cov.dtype)
    log_weights = _update(system, particles, jnp.full(count, -jnp.log(count), cov.dtype), measurements[0])
    first = _moments(particles, log_weights)

    def body(carry, inputs):
        particles, log_weights, key = carry
        pusher, increment, measurement = inputs
        key, resample_key, noise_key = jax.random.split(key, 3)
        particles, log_weights = _resample(resample_key, particles, log_weights)
        moved = jax.vmap(models.transition, in_axes=(None, 0, None, None))(system, particles, pusher, increment)
        moved, log_weights = _propose(system, noise_key, moved, log_weights, measurement)
        return (moved, log_weights, key), _moments(moved, log_weights)

    _, (means, covs) = jax.lax.scan(body, (particles, log_weights, key),
                                    (pusher_path[:-1], jnp.diff(pusher_path, axis=0), measurements[1:]))
    return models.Track(mean=jnp.concatenate([first[0][None], means]), cov=jnp.concatenate([first[1][None], covs]),
                        observed=jax.vmap(models.observed)(measurements))


@functools.partial(jax.jit, static_argnames=("count",))
def filter_pushes(system: models.System, keys, mean, cov, pusher_paths, measurements, count: int = 256):
    """:func:`filter_push` over a batch of pushes of one object (leading axis N on all but `system`)."""
    return jax.vmap(filter_push, in_axes=(None, 0, 0, 0, 0, 0, None))(system, keys, mean, cov, pusher_paths,
                                                                       measurements, count)
