"""Extended Kalman filter over the pose and the latent parameters (:mod:`pushjax.filter.models`).

Predict: the mean goes through the rollout step (:func:`~pushjax.filter.models.transition`), the covariance
through its Jacobian, ``jax.jacfwd`` of the step with respect to the state (exact derivatives of the step, one-sided
where the contact mode changes): ``P <- F P F^T + Q``. Update: the Kalman update with the pose measurement, skipped
for a dropped (NaN) sample; optionally a second stream, a position sensor's readings
(:class:`~pushjax.filter.models.PositionSensor`, e.g. a perception network's), linearised, missing readings skipped. Jit-compiled; ``jax.vmap`` it over pushes (with :func:`filter_pushes`).
"""

from __future__ import annotations

import jax

from pushjax.filter import models

__all__ = ["filter_push", "filter_pushes", "predict"]


def predict(system: models.System, mean, cov, pusher, increment):
    """(mean [5], cov [5, 5]) one step ahead."""
    jacobian = jax.jacfwd(models.transition, argnums=1)(system, mean, pusher, increment)
    new_cov = jacobian @ cov @ jacobian.T + models.process_cov(system, cov.dtype)
    return models.transition(system, mean, pusher, increment), 0.5 * (new_cov + new_cov.T)


@jax.jit
def filter_push(system: models.System, mean, cov, pusher_path, measurements, sensor: models.PositionSensor | None = None,
                positions=None) -> models.Track:
    """Filters one push.

    Args:
      system: the :class:`~pushjax.filter.models.System`.
      mean: [5] prior mean of the state at the first measurement.
      cov: [5, 5] prior covariance.
      pusher_path: [T + 1, 2] pusher centre at the measurement times, world, m.
      measurements: [T + 1, 3] measured poses (x m, y m, yaw rad); NaN rows are dropped samples.
      sensor: the second observation model, a :class:`~pushjax.filter.models.PositionSensor`, or None (pose only).
      positions: [T + 1, 2] its readings (world x m, y m), NaN rows where it has none; with `sensor` only.

    Returns:
      The :class:`~pushjax.filter.models.Track` [T + 1] (``observed``: the pose stream's samples).
    """
    return models.gaussian_filter(predict, system, mean, cov, pusher_path, measurements, sensor, positions)


@jax.jit
def filter_pushes(system: models.System, mean, cov, pusher_paths, measurements,
                  sensor: models.PositionSensor | None = None, positions=None) -> models.Track:
    """:func:`filter_push` over a batch of pushes of one object: mean [N, 5], cov [N, 5, 5], pusher_paths
    [N, T + 1, 2], measurements [N, T + 1, 3], positions [N, T + 1, 2] (one `sensor` for all)."""
    return jax.vmap(filter_push, in_axes=(None, 0, 0, 0, 0, None, 0))(system, mean, cov, pusher_paths, measurements,
                                                                       sensor, positions)
