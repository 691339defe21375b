"""Tracking pushes of the MuJoCo testbed: the filters against the raw motion capture and a constant-velocity filter,
and the latent pusher friction against the value the testbed drew (``python -m experiments.track``).

Pushes are planned and simulated as ``record_pushes`` does (:func:`pushjax.sim.dataset.plan_pushes`,
:func:`~pushjax.sim.dataset.simulate_job`; MIT grid, one velocity), but kept in memory, because only the simulation
knows the truth: the object's pose before the motion-capture effects and the push's drawn pusher friction
(nominal coefficient times :attr:`pushjax.sim.testbed.PushConditions.pusher_friction`). The filters see what a file
holds: the pusher's path and the tracked object poses at 250 Hz with noise, time-stamp jitter and dropped samples.
They run at ``rate_hz``: every ``250 / rate_hz``-th sample of the 250 Hz clock is a measurement, NaN where the
tracking system dropped it. Pushes of one object are padded to one length (pusher standing still, measurements
missing) and filtered together, ``jax.vmap`` over the pushes; the padding is left out of every score.

The filters' state is the pose with the log scales of the nominal ``mu`` (the file's ``pushjax_pusher_friction``)
and of the uniform-pressure ``l``; the testbed's uneven support pressure has no single true ``l``, so only its
estimate is reported. Noise magnitudes are set by hand once (:data:`PROCESS_STD`, :data:`PRIOR_STD`, the
realistic testbed's tracking noise as measurement noise); learning them through the differentiable filter is not
done here.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from pathlib import Path

import jax
import matplotlib.pyplot as plt
import numpy as np

from pushjax import outputs
from pushjax.filter import constant_velocity, ekf, metrics, models, particle, ukf
from pushjax.sim import dataset
from pushjax.sim.testbed import Testbed

__all__ = ["FILTERS", "SCALES", "TrackedPush", "run", "simulate_pushes", "write"]

FILTERS = ("ekf", "ukf", "particle")
RECORDING_RATE_HZ = 250
SCALES = {
    "smoke": {"objects": ("rect1",), "pushes": 2, "particles": 64, "rate_hz": 5.0},
    "cpu": {"objects": ("rect1", "tri2", "hex"), "pushes": 12, "particles": 256, "rate_hz": 10.0},
}
"""Objects, pushes per object (abs, 20 mm/s), particles and filter rate of each scale."""
PROCESS_STD_PER_S = (3.75e-4, 3.75e-4, 6.25e-3, 3e-2, 3e-2)
"""Process noise of the pushing filters per sqrt(s) (x m, y m, yaw rad, log mu, log l), set by hand once on the
``cpu`` scale's seed-0 pushes (EKF, 10 Hz): of the pose scales 1, 1/2, 1/4, 1/8 and 1/16 of (3 mm, 3 mm, 0.05 rad)
per sqrt(s), 1/8 gave the smallest pose RMSE with the NEES still in its 95 % band at 92 % of the steps (1/16: 84 %,
mean NEES 5.8). Evaluate on other seeds."""
PRIOR_STD = (1.0, 1.0, 1.0, 0.5, 0.3)
"""Prior standard deviations: the pose in units of the measurement noise, log mu and log l (absolute)."""
ACCELERATION_PSD = (1e-4, 1e-4, 1e-1)
"""Constant-velocity filter: white acceleration spectral densities ((m/s^2)^2 s, (m/s^2)^2 s, (rad/s^2)^2 s)."""


@dataclasses.dataclass(frozen=True)
class TrackedPush:
    """One simulated push as the filters see it, plus its truth, on the filter clock [T + 1].

    Attributes:
      name: the file name the push would have.
      obj: object name.
      pusher: [T + 1, 2] pusher centre, m.
      measurements: [T + 1, 3] tracked poses (x m, y m, yaw rad wrapped), NaN rows where dropped.
      truth: [T + 1, 3] true poses (yaw unwrapped).
      mu_nominal: the coefficient the file declares.
      mu_true: the coefficient the push was simulated with.
    """

    name: str
    obj: str
    pusher: np.ndarray
    measurements: np.ndarray
    truth: np.ndarray
    mu_nominal: float
    mu_true: float


def _on_clock(stream: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Rows of [N, 4] stream (t, x, y, yaw) at 250 Hz sample `indices`; NaN rows for samples the stream lacks."""
    out = np.full((len(indices), 3), np.nan)
    sample = np.rint(stream[:, 0] * RECORDING_RATE_HZ).astype(int)
    position = {int(k): row for row, k in enumerate(sample)}
    for row, k in enumerate(indices):
        if int(k) in position:
            out[row] = stream[position[int(k)], 1:]
    return out


def simulate_pushes(objects: Sequence[str], pushes: int, seed: int, testbed: Testbed, rate_hz: float,
                    velocity: float = 20.0) -> list[TrackedPush]:
    """Plans and simulates `pushes` pushes per object on abs at `velocity` mm/s (MIT grid, `seed`), in memory."""
    step = RECORDING_RATE_HZ / rate_hz
    if not (step >= 1 and abs(step - round(step)) < 1e-9):
        raise ValueError(f"rate_hz: expected {RECORDING_RATE_HZ} Hz divided by a whole number, got {rate_hz}")
    step = round(step)
    jobs = dataset.plan_pushes("unused", list(objects), ["abs"], pushes,
                               dataset.RecordingSettings(seed=seed, velocities=(velocity,), testbed=testbed))
    result = []
    for job in jobs:
        recording = dataset.simulate_job(job)
        conditions = dataset.job_conditions(job)
        indices = np.arange(0, len(recording.tip_pose), step)
        mu_nominal = float(job.attributes["pushjax_pusher_friction"])
        result.append(TrackedPush(
            name=job.path.name, obj=job.params.shape, pusher=recording.tip_pose[indices, 1:3],
            measurements=_on_clock(recording.object_pose, indices),
            truth=recording.true_object_pose[indices, 1:],
            mu_nominal=mu_nominal,
            mu_true=mu_nominal * (1.0 if conditions is None else float(conditions.pusher_friction))))
    return result


def _pad(arrays: list[np.ndarray], length: int, fill: str) -> np.ndarray:
    """[N, length, ...]: each array padded at the end by repeating its last row ('edge') or with NaN ('nan')."""
    padded = []
    for array in arrays:
        extra = length - len(array)
        tail = np.repeat(array[-1:], extra, axis=0) if fill == "edge" else np.full((extra,) + array.shape[1:], np.nan)
        padded.append(np.concatenate([array, tail]))
    return np.stack(padded)


def _first_time_within(estimate: np.ndarray, truth: float, valid: int, dt: float, tolerance: float = 0.2):
    """Seconds after which the estimate [T] stays within `tolerance` (relative) of `truth`; None if it never does."""
    inside = np.abs(np.log(estimate[:valid] / truth)) < np.log1p(tolerance)
    if not inside[-1]:
        return None
    outside = np.flatnonzero(~inside)
    return float((outside[-1] + 1) * dt) if len(outside) else 0.0


def run(pushes: list[TrackedPush], filters: Sequence[str], rate_hz: float, particles: int, seed: int,
        measurement_std: Sequence[float]) -> dict:
    """Runs the filters and the constant-velocity baseline on the pushes; returns the results (see :func:`write`)."""
    dt = 1.0 / rate_hz
    measurement_std = np.asarray(measurement_std, np.float64)
    process_std = np.asarray(PROCESS_STD_PER_S) * math.sqrt(dt)
    prior_std = np.concatenate([np.asarray(PRIOR_STD[:3]) * measurement_std, PRIOR_STD[3:]])
    per_push, estimates = [], {name: [] for name in (*filters, "constant_velocity", "raw")}
    truths, valid_masks = [], []
    for obj in sorted({push.obj for push in pushes}):
        group = [push for push in pushes if push.obj == obj]
        length = max(len(push.pusher) for push in group)
        valid = np.stack([np.arange(length) < len(push.pusher) for push in group])
        paths = _pad([push.pusher for push in group], length, "edge")
        measured = _pad([push.measurements for push in group], length, "nan")
        truth = _pad([push.truth for push in group], length, "edge")
        nominal = np.array([push.mu_nominal for push in group])
        if np.ptp(nominal) > 0:
            raise ValueError(f"{obj}: the pushes declare different nominal mu {sorted(set(nominal))}")
        system = models.make_system(obj, mu=float(nominal[0]), process_std=process_std,
                                    measurement_std=measurement_std)
        count = len(group)
        mean = np.concatenate([measured[:, 0], np.zeros((count, 2))], axis=-1)
        cov = np.broadcast_to(np.diag(prior_std ** 2), (count, 5, 5))
        tracks, seconds = {}, {}
        for name in filters:
            start = time.perf_counter()
            if name == "particle":
                keys = jax.random.split(jax.random.key(seed), count)
                track = particle.filter_pushes(system, keys, mean, cov, paths, measured, count=particles)
            else:
                track = {"ekf": ekf, "ukf": ukf}[name].filter_pushes(system, mean, cov, paths, measured)
            tracks[name] = jax.tree_util.tree_map(np.asarray, jax.block_until_ready(track))
            seconds[name] = time.perf_counter() - start
        cv_mean = np.concatenate([measured[:, 0], np.zeros((count, 3))], axis=-1)
        cv_cov = np.broadcast_to(np.diag(np.concatenate([measurement_std, [0.05, 0.05, 0.5]]) ** 2), (count, 6, 6))
        cv = constant_velocity.filter_pushes(measurement_std, ACCELERATION_PSD, dt, cv_mean, cv_cov, measured)
        tracks["constant_velocity"] = jax.tree_util.tree_map(np.asarray, cv)
        for k, push in enumerate(group):
            row = {"name": push.name, "object": obj, "steps": int(valid[k].sum()) - 1,
                   "dropped": int(np.isnan(push.measurements[:, 0]).sum()), "mu_nominal": push.mu_nominal,
                   "mu_true": push.mu_true, "filters": {}}
            for name in filters:
                track = tracks[name]
                mu = push.mu_nominal * np.exp(track.mean[k, :, 3])
                row["filters"][name] = {
                    "mu": mu[valid[k]].tolist(), "mu_std_log": np.sqrt(track.cov[k, :, 3, 3])[valid[k]].tolist(),
                    "l_scale": float(np.exp(track.mean[k, valid[k].sum() - 1, 4])),
                    "mu_within_20_percent_after_s": _first_time_within(mu, push.mu_true, int(valid[k].sum()), dt)}
            per_push.append(row)
        for name in (*filters, "constant_velocity"):
            estimates[name].append(tracks[name].mean[..., :3])
        estimates["raw"].append(measured)
        truths.append(truth)
        valid_masks.append(valid)
        for name in filters:
            estimates.setdefault(f"{name}_cov", []).append(tracks[name].cov)
            estimates.setdefault(f"{name}_seconds", []).append(seconds[name])
        estimates.setdefault("constant_velocity_cov", []).append(tracks["constant_velocity"].cov)

    truth = np.concatenate([t.reshape(-1, 3) for t in truths])
    valid = np.concatenate([v.reshape(-1) for v in valid_masks])
    low, high = metrics.chi2_band(3)
    summary = {}
    for name in (*filters, "constant_velocity", "raw"):
        estimate = np.concatenate([e.reshape(-1, 3) for e in estimates[name]])[valid]
        position, yaw = metrics.rmse(estimate, truth[valid])
        entry = {"position_rmse_mm": 1e3 * position, "yaw_rmse_deg": math.degrees(yaw)}
        if name != "raw":
            size = 6 if name == "constant_velocity" else 5
            cov = np.concatenate([c.reshape(-1, size, size) for c in estimates[f"{name}_cov"]])[valid]
            full = np.concatenate([e.reshape(-1, 3) for e in estimates[name]])[valid]
            padded = np.concatenate([full, np.zeros((len(full), size - 3))], axis=-1)
            nees = metrics.nees(padded, cov, truth[valid])
            entry["nees_mean"] = float(np.mean(nees))
            entry["nees_median"] = float(np.median(nees))
            entry["nees_in_95_band"] = float(np.mean((nees > low) & (nees < high)))
        if name in filters:
            entry["seconds_with_compile"] = float(sum(estimates[f"{name}_seconds"]))
            errors = [abs(math.log(row["filters"][name]["mu"][-1] / row["mu_true"])) for row in per_push]
            prior_errors = [abs(math.log(row["mu_nominal"] / row["mu_true"])) for row in per_push]
            entry["mu_final_abs_log_error"] = float(np.mean(errors))
            entry["mu_prior_abs_log_error"] = float(np.mean(prior_errors))
            entry["mu_final_std_log_over_prior"] = float(np.mean(
                [row["filters"][name]["mu_std_log"][-1] / PRIOR_STD[3] for row in per_push]))
        summary[name] = entry
    return {"summary": summary, "pushes": per_push, "nees_band_95": [low, high], "rate_hz": rate_hz,
            "filters": list(filters), "particles": particles, "measurement_std": measurement_std.tolist(),
            "process_std_per_step": process_std.tolist(), "prior_std": prior_std.tolist()}


def _table(results: dict) -> str:
    lines = [("| estimate | position RMSE (mm) | yaw RMSE (deg) | NEES in 95 % band | median NEES | mu: mean abs log "
              "error, prior → final | mu: posterior std / prior std |"), "|---|---:|---:|---:|---:|---:|---:|"]
    for name, entry in results["summary"].items():
        band = f"{entry['nees_in_95_band']:.2f}" if "nees_in_95_band" in entry else ""
        nees = f"{entry['nees_median']:.2f}" if "nees_median" in entry else ""
        mu = (f"{entry['mu_prior_abs_log_error']:.2f} → {entry['mu_final_abs_log_error']:.2f}"
              if "mu_final_abs_log_error" in entry else "")
        spread = f"{entry['mu_final_std_log_over_prior']:.2f}" if "mu_final_std_log_over_prior" in entry else ""
        lines.append(f"| {name} | {entry['position_rmse_mm']:.3f} | {entry['yaw_rmse_deg']:.3f} | {band} | {nees} "
                     f"| {mu} | {spread} |")
    header = " | ".join(f"{f}: final mu ± std(log), within 20 % after" for f in results["filters"])
    lines += ["", f"| push | mu true (nominal) | {header} |", "|---|---:|" + "---:|" * len(results["filters"])]
    for row in results["pushes"]:
        cells = []
        for name in results["filters"]:
            entry = row["filters"][name]
            after = entry["mu_within_20_percent_after_s"]
            cells.append(f"{entry['mu'][-1]:.3f} ± {entry['mu_std_log'][-1]:.2f}, "
                         + ("never" if after is None else f"{after:.1f} s"))
        lines.append(f"| {row['object']} {row['name'].split('_a=')[1].removesuffix('.h5')} | {row['mu_true']:.3f} "
                     f"({row['mu_nominal']:.2f}) | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _figure(results: dict, path: Path, pushes: int = 4) -> None:
    name = results["filters"][0]
    rows = results["pushes"][:pushes]
    figure, axes = plt.subplots(1, len(rows), figsize=(3.2 * len(rows), 2.8), squeeze=False)
    for axis, row in zip(axes[0], rows):
        mu = np.asarray(row["filters"][name]["mu"])
        spread = np.asarray(row["filters"][name]["mu_std_log"])
        seconds = np.arange(len(mu)) / results["rate_hz"]
        axis.fill_between(seconds, mu * np.exp(-2 * spread), mu * np.exp(2 * spread), alpha=0.3, label="± 2 std")
        axis.plot(seconds, mu, label=f"{name} estimate")
        axis.axhline(row["mu_true"], color="k", linestyle="--", label="true")
        axis.set_yscale("log")
        axis.set_xlabel("time (s)")
        axis.set_title(f"{row['object']} {row['name'].split('_s=')[1].removesuffix('.h5')}", fontsize=8)
    axes[0][0].set_ylabel("pusher friction mu")
    axes[0][0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)


def write(results: dict, workdir: str | Path) -> list[Path]:
    """Writes ``results.json``, ``results.md`` (the tables) and ``mu_over_time.png`` to `workdir`."""
    return outputs.write_results(workdir, results, _table(results), "mu_over_time.png", _figure)
