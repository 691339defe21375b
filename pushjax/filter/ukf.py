"""Unscented Kalman filter over the pose and the latent parameters (:mod:`pushjax.filter.models`).

Predict: the scaled unscented transform (van der Merwe; ``alpha = 1``, ``beta = 2``, ``kappa = 0``: 2n + 1 sigma
points at ``mean ± sqrt(n) columns of chol(P)``, non-negative mean weights) through the rollout step, vmapped over
the sigma points, plus the process noise. The unscented transform sees the contact mode change within the belief's
spread (e.g. a lower ``mu`` that slips where the mean sticks), which the EKF's Jacobian does not. Update: the
measurement is linear in the state, so the unscented update is the Kalman update
(:func:`~pushjax.filter.models.update_linear`), skipped for a dropped (NaN) sample; a second stream of position
readings (:class:`~pushjax.filter.models.PositionSensor`) updates linearised, as in the EKF.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from pushjax.filter import models

__all__ = ["filter_push", "filter_pushes", "predict", "sigma_points"]

ALPHA, BETA, KAPPA = 1.0, 2.0, 0.0
_JITTER = 1e-12
"""Added to the covariance's diagonal before the Cholesky factorisation (relative to its largest entry)."""


def sigma_points(mean, cov):
    """([2n + 1, n] points, [2n + 1] mean weights, [2n + 1] covariance weights)."""
    n = mean.shape[-1]
    lam = ALPHA ** 2 * (n + KAPPA) - n
    scale = jnp.max(jnp.diag(cov))
    root = jnp.linalg.cholesky((n + lam) * (cov + _JITTER * scale * jnp.eye(n, dtype=cov.dtype)))
    points = jnp.concatenate([mean[None], mean + root.T, mean - root.T])
    weight = jnp.full(2 * n + 1, 1.0 / (2 * (n + lam)), cov.dtype)
    mean_weights = weight.at[0].set(lam / (n + lam))
    cov_weights = weight.at[0].set(lam / (n + lam) + 1 - ALPHA ** 2 + BETA)
    return points, mean_weights, cov_weights


def predict(system: models.System, mean, cov, pusher, increment):
    """(mean [5], cov [5, 5]) one step ahead."""
    points, mean_weights, cov_weights = sigma_points(mean, cov)
    moved = jax.vmap(models.transition, in_axes=(None, 0, None, None))(system, points, pusher, increment)
    new_mean = mean_weights @ moved
    deviation = moved - new_mean
    new_cov = (cov_weights[:, None] * deviation).T @ deviation + models.process_cov(system, cov.dtype)
    return new_mean, 0.5 * (new_cov + new_cov.T)


@jax.jit
def filter_push(system: models.System, mean, cov, pusher_path, measurements, sensor: models.PositionSensor | None = None,
                positions=None) -> models.Track:
    """Filters one push; arguments and result as :func:`pushjax.filter.ekf.filter_push`."""
    return models.gaussian_filter(predict, system, mean, cov, pusher_path, measurements, sensor, positions)


@jax.jit
def filter_pushes(system: models.System, mean, cov, pusher_paths, measurements,
                  sensor: models.PositionSensor | None = None, positions=None) -> models.Track:
    """:func:`filter_push` over a batch of pushes of one object (leading axis N on all but `system` and `sensor`)."""
    return jax.vmap(filter_push, in_axes=(None, 0, 0, 0, 0, None, 0))(system, mean, cov, pusher_paths, measurements,
                                                                       sensor, positions)
