"""A constant-velocity Kalman filter over the pose: the baseline that knows nothing about pushing.

State [6]: pose (x m, y m, yaw rad) and its rate (m/s, m/s, rad/s). Process: constant velocity with white
acceleration noise of spectral densities ``acceleration_psd`` (per axis: (m/s^2)^2 s, (m/s^2)^2 s, (rad/s^2)^2 s);
observation: the pose with the system's measurement noise, skipped for a dropped (NaN) sample, yaw wrapped.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from pushjax.filter import models

__all__ = ["filter_push", "filter_pushes"]


@jax.jit
def filter_push(measurement_std, acceleration_psd, dt, mean, cov, measurements) -> models.Track:
    """Filters one push: mean [6] and cov [6, 6] prior at the first measurement; measurements [T + 1, 3] at steps
    of `dt` s. Returns a :class:`~pushjax.filter.models.Track` whose mean / cov are [T + 1, 6] / [T + 1, 6, 6]."""
    dtype = cov.dtype
    eye = jnp.eye(3, dtype=dtype)
    transition = jnp.block([[eye, dt * eye], [jnp.zeros_like(eye), eye]])
    q = jnp.diag(jnp.asarray(acceleration_psd, dtype))
    process = jnp.block([[q * dt ** 3 / 3, q * dt ** 2 / 2], [q * dt ** 2 / 2, q * dt]])
    h = jnp.eye(3, 6, dtype=dtype)
    r = jnp.diag(jnp.asarray(measurement_std, dtype) ** 2)

    def update(mean, cov, measurement):
        s = h @ cov @ h.T + r
        gain = jnp.linalg.solve(s, h @ cov).T
        new_mean = mean + gain @ models.innovation(measurement, mean[:3])
        factor = jnp.eye(6, dtype=dtype) - gain @ h
        new_cov = factor @ cov @ factor.T + gain @ r @ gain.T
        present = models.observed(measurement)
        return jnp.where(present, new_mean, mean), jnp.where(present, 0.5 * (new_cov + new_cov.T), cov)

    mean, cov = update(mean, cov, measurements[0])

    def body(belief, measurement):
        mean, cov = belief
        belief = update(transition @ mean, transition @ cov @ transition.T + process, measurement)
        return belief, belief

    _, (means, covs) = jax.lax.scan(body, (mean, cov), measurements[1:])
    return models.Track(mean=jnp.concatenate([mean[None], means]), cov=jnp.concatenate([cov[None], covs]),
                        observed=jax.vmap(models.observed)(measurements))


@jax.jit
def filter_pushes(measurement_std, acceleration_psd, dt, mean, cov, measurements) -> models.Track:
    """:func:`filter_push` over a batch of pushes (leading axis N on mean, cov and measurements)."""
    return jax.vmap(filter_push, in_axes=(None, None, None, 0, 0, 0))(measurement_std, acceleration_psd, dt, mean,
                                                                       cov, measurements)
