"""Scores of a filter's track against the true states: pose errors, RMSE, NEES and its chi-square band; and the
synthetic pushes the tests and ``experiments.track``'s sanity rows use (the analytical rollout with known
parameters, measured with noise and dropped samples)."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import scipy.stats

from pushjax.filter import models
from pushjax.physics import rollout

__all__ = ["chi2_band", "measure", "nees", "pose_errors", "rmse", "simulate"]


def pose_errors(estimate, truth):
    """([...] position error m, [...] yaw error rad wrapped to (-pi, pi]) of poses [..., 3]."""
    estimate, truth = np.asarray(estimate, np.float64), np.asarray(truth, np.float64)
    position = np.hypot(*(estimate[..., :2] - truth[..., :2]).T).T
    yaw = np.angle(np.exp(1j * (estimate[..., 2] - truth[..., 2])))
    return position, yaw


def rmse(estimate, truth):
    """(position RMSE m, yaw RMSE rad) over all finite rows of poses [..., 3]."""
    position, yaw = pose_errors(estimate, truth)
    keep = np.isfinite(position) & np.isfinite(yaw)
    return float(np.sqrt(np.mean(position[keep] ** 2))), float(np.sqrt(np.mean(yaw[keep] ** 2)))


def nees(mean, cov, truth, indices=(0, 1, 2)):
    """[...] normalised estimation error squared of the state components `indices` (yaw wrapped): chi-square with
    ``len(indices)`` degrees of freedom for a consistent filter. `truth` [..., k] holds those components."""
    indices = list(indices)
    mean, cov, truth = (np.asarray(x, np.float64) for x in (mean, cov, truth))
    error = mean[..., indices] - truth
    if 2 in indices:
        position = indices.index(2)
        error[..., position] = np.angle(np.exp(1j * error[..., position]))
    block = cov[..., indices, :][..., :, indices]
    return np.einsum("...i,...i->...", error, np.linalg.solve(block, error[..., None])[..., 0])


def chi2_band(dof: int, level: float = 0.95) -> tuple[float, float]:
    """The two-sided `level` interval of a chi-square variable with `dof` degrees of freedom."""
    return float(scipy.stats.chi2.ppf((1 - level) / 2, dof)), float(scipy.stats.chi2.ppf((1 + level) / 2, dof))


def simulate(system: models.System, true_state, pusher_paths):
    """[N, T + 1, 3] true poses of pushes along `pusher_paths` [N, T + 1, 2] from `true_state` [N, 5] (pose and
    the latents' true log scales), by the analytical rollout of `system`'s model."""

    def one(state, path):
        return rollout.rollout(system.shape, state[:3], path, system.l * jnp.exp(state[4]),
                               system.mu * jnp.exp(state[3]), system.params, effects=system.effects,
                               radius=system.radius, support=system.support).poses

    return jax.jit(jax.vmap(one))(jnp.asarray(true_state, system.l.dtype), jnp.asarray(pusher_paths, system.l.dtype))


def measure(poses, measurement_std, drop_rate: float, seed: int) -> np.ndarray:
    """Motion-capture measurements of poses [..., T + 1, 3]: Gaussian noise (`measurement_std` [3]), yaw wrapped,
    rows dropped (NaN) at `drop_rate`, the first row always kept."""
    rng = np.random.default_rng(seed)
    poses = np.asarray(poses, np.float64)
    measured = poses + np.asarray(measurement_std) * rng.standard_normal(poses.shape)
    measured[..., 2] = np.angle(np.exp(1j * measured[..., 2]))
    dropped = rng.random(poses.shape[:-1]) < drop_rate
    dropped[..., 0] = False
    measured[dropped] = np.nan
    return measured
