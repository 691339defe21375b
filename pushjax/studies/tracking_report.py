"""The report of a tracking run (:mod:`pushjax.studies.tracking`): its markdown tables and the figure of the pusher
friction over time, written by :func:`pushjax.studies.tracking.write`."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

__all__ = ["figure", "table"]


def table(results: dict) -> str:
    """Markdown of a run's results (:func:`pushjax.studies.tracking.run`): every estimate's errors, NEES and mu, the
    noise, the perception's readings (if any), and every push's final mu."""
    lines = [("| estimate | position RMSE (mm) | yaw RMSE (deg) | NEES in 95 % band | median NEES | mu: mean abs log "
              "error, prior → final | mu: posterior std / prior std |"), "|---|---:|---:|---:|---:|---:|---:|"]
    for name, entry in results["summary"].items():
        band = f"{entry['nees_in_95_band']:.2f}" if "nees_in_95_band" in entry else ""
        nees = f"{entry['nees_median']:.2f}" if "nees_median" in entry else ""
        mu = (f"{entry['mu_prior_abs_log_error']:.2f} → {entry['mu_final_abs_log_error']:.2f}"
              if "mu_final_abs_log_error" in entry else "")
        spread = f"{entry['mu_final_std_log_over_prior']:.2f}" if "mu_final_std_log_over_prior" in entry else ""
        yaw = f"{entry['yaw_rmse_deg']:.3f}" if "yaw_rmse_deg" in entry else "–"
        lines.append(f"| {name} | {entry['position_rmse_mm']:.3f} | {yaw} | {band} | {nees} | {mu} | {spread} |")
    lines += _noise_table(results)
    lines += _perception_lines(results)
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


_NOISE_ROWS = (
    ("process x per sqrt(s) (mm)", "process_std", 0, 1e3, True),
    ("process y per sqrt(s) (mm)", "process_std", 1, 1e3, True),
    ("process yaw per sqrt(s) (deg)", "process_std", 2, math.degrees(1.0), True),
    ("process log mu per sqrt(s)", "process_std", 3, 1.0, True),
    ("process log l per sqrt(s)", "process_std", 4, 1.0, True),
    ("measurement x (mm)", "measurement_std", 0, 1e3, False),
    ("measurement y (mm)", "measurement_std", 1, 1e3, False),
    ("measurement yaw (deg)", "measurement_std", 2, math.degrees(1.0), False),
)
"""The rows of the noise table: label, key of :func:`pushjax.filter.noise.standard_deviations`, index, unit factor,
per step converted to per sqrt(s)."""


def _noise_table(results: dict) -> list[str]:
    """The hand-set noise standard deviations beside the learned ones (if any) and the learning's loss curve."""
    columns = [name for name in ("hand_set", "learned") if name in results["noise"]]
    lines = ["", "| noise (standard deviation) | " + " | ".join(name.replace("_", "-") for name in columns) + " |",
             "|---|" + "---:|" * len(columns)]
    for label, key, index, unit, per_step in _NOISE_ROWS:
        factor = unit * (math.sqrt(results["rate_hz"]) if per_step else 1.0)
        cells = [f"{factor * results['noise'][name][key][index]:.4g}" for name in columns]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    if "noise_learning" in results:
        learning = results["noise_learning"]
        curve = learning["loss_curve"]
        marks = sorted({round(fraction * (len(curve) - 1)) for fraction in (0, 0.25, 0.5, 0.75, 1)})
        seed = f" (seed {results['training_seed']})" if "training_seed" in results else ""
        lines += ["", f"ekf_learned: noise learned on {learning['training_pushes']} training pushes{seed} in "
                  f"{learning['steps']} Adam steps ({learning['seconds_with_compile']:.0f} s with compilation), the "
                  f"latents' prior kept ({', '.join(f'{v:g}' for v in results['prior_std'][3:])} for log mu, log l); "
                  "loss (pose NLL, nats per step) at step " + ", ".join(f"{k}: {curve[k]:.4f}" for k in marks) + "."]
    return lines


def _perception_lines(results: dict) -> list[str]:
    """What the perception rows rest on: the model, its rate and its noise (and where that was estimated)."""
    if "perception" not in results:
        return []
    info = results["perception"]
    std = ", ".join(f"{1e3 * value:.2f}" for value in info["std"])
    return ["", f"perception: {info['model']} at {info['rate_hz']:g} Hz; the position row `perception` is its readings "
            f"of the centre of mass against the truth (no yaw); reading noise (x, y) {std} mm, "
            f"{info['noise_estimated_on']}."
            + (f" {info['scenes']} scenes rendered and located in {info['seconds_with_compile']:.1f} s with compilation."
               if "scenes" in info else "")]


def figure(results: dict, path: Path, pushes: int = 4) -> None:
    """The first filter's pusher friction over time (± 2 standard deviations) against the true one, on the first
    `pushes` pushes."""
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
