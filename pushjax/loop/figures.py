"""The loop report's figures: the residual against the candidate variables and the variables' strengths.

Drawn on :class:`matplotlib.figure.Figure` objects, not through pyplot's global state (a caller's threads and open
figures are left alone)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from pushjax.loop import diagnose as diagnose_lib
from pushjax.loop.windows import CATEGORICAL, VARIABLES, Examples


def residual_figure(path: Path, examples: Examples, prediction: np.ndarray, title: str,
                    variables: list[str]) -> None:
    """Median residual per bin of each variable: along and across the push (mm) and rotation (deg)."""
    residual = examples.target - np.asarray(prediction, np.float64)
    motion = np.asarray(examples.inputs.pusher_motion, np.float64)
    angle = np.arctan2(motion[:, 1], motion[:, 0])
    along = 1e3 * (np.cos(angle) * residual[:, 0] + np.sin(angle) * residual[:, 1])
    across = 1e3 * (-np.sin(angle) * residual[:, 0] + np.cos(angle) * residual[:, 1])
    rotation = np.degrees(residual[:, 2])
    columns = min(len(variables), 4)
    rows = max(1, math.ceil(len(variables) / max(columns, 1)))
    figure = Figure(figsize=(4 * max(columns, 1), 3 * rows))
    axes = figure.subplots(rows, max(columns, 1), squeeze=False)
    for axis in axes.flat[len(variables):]:
        axis.set_visible(False)
    for axis, name in zip(axes.flat, variables):
        values = examples.variables[name]
        labels, assign = diagnose_lib.assign_bins(values, VARIABLES[name])
        bins = assign(values)
        present = np.unique(bins)
        if VARIABLES[name] == CATEGORICAL:
            ticks = [str(labels[b]) for b in present]
        else:
            ticks = [f"{np.median(np.asarray(values, np.float64)[bins == b]):.3g}" for b in present]
        x = np.arange(len(present))
        for series, label in ((along, "along push, mm"), (across, "across push, mm"), (rotation, "rotation, deg")):
            axis.plot(x, [np.median(series[bins == b]) for b in present], marker="o", label=label)
        axis.axhline(0.0, color="black", linewidth=0.5)
        axis.set_xticks(x, ticks, rotation=45, fontsize=7)
        axis.set_title(name, fontsize=9)
    axes.flat[0].legend(fontsize=7)
    figure.suptitle(title)
    figure.tight_layout()
    figure.savefig(path, dpi=80)


def strength_figure(path: Path, before: list, after: list) -> None:
    """Bar chart of each variable's strength before and after the fix."""
    names = [d.variable for d in before]
    after_by_name = {d.variable: d.strength for d in after}
    y = np.arange(len(names))
    figure = Figure(figsize=(7, 0.4 * len(names) + 1.2))
    axis = figure.subplots()
    axis.barh(y - 0.2, [d.strength for d in before], height=0.4, label="plain model")
    axis.barh(y + 0.2, [after_by_name[name] for name in names], height=0.4, label="after the fix")
    axis.set_yticks(y, names, fontsize=8)
    axis.invert_yaxis()
    axis.axvline(0.0, color="black", linewidth=0.5)
    axis.set_xlabel("share of the error a correction for the variable removes")
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=80)
