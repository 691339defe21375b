"""Matplotlib figures (PNG) of the ``results`` of `pushjax.experiments.runner.run`, like the paper's."""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pushjax.experiments import tables  # noqa: E402

PANELS = (("trans_percent", "translation error [% of zero]"), ("rot_percent", "rotation error [% of zero]"))


def _series(rows: Sequence[Mapping], series_keys: Sequence[str]) -> dict[str, list[Mapping]]:
    series: dict[str, list[Mapping]] = {}
    for row in rows:
        label = ", ".join(str(row[key]) for key in series_keys if row.get(key) is not None)
        series.setdefault(label, []).append(row)
    return series


def _value(row, metric):
    value = row.get(metric)
    return np.nan if value is None else value


def line_figure(rows: Sequence[Mapping], x: Callable[[Mapping], float], x_label: str,
                series_keys: Sequence[str], path: str | os.PathLike, log_x: bool = False) -> Path:
    """Trans. and rot. errors (± s.e.) against ``x(row)``, a line per distinct `series_keys`.

    Rows where ``x(row)`` is None (baselines without a training size) are drawn as horizontal dashed lines.
    """
    figure, axes = plt.subplots(1, len(PANELS), figsize=(11, 4))
    for axis, (metric, label) in zip(axes, PANELS):
        baseline_styles = itertools.cycle(("--", ":", "-."))
        for name, members in _series(rows, series_keys).items():
            points = sorted((x(row), _value(row, metric), _value(row, f"{metric}_se")) for row in members
                            if x(row) is not None)
            if points:
                xs, ys, ses = map(np.asarray, zip(*points))
                axis.errorbar(xs, ys, yerr=np.nan_to_num(ses), marker="o", capsize=3, label=name)
            else:
                axis.axhline(_value(members[0], metric), linestyle=next(baseline_styles), color="k", label=name)
        axis.set_xlabel(x_label)
        axis.set_ylabel(label)
        if log_x:
            axis.set_xscale("log")
        axis.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return Path(path)


def bar_figure(rows: Sequence[Mapping], group_key: str, series_keys: Sequence[str],
               path: str | os.PathLike) -> Path:
    """Grouped bars of trans. and rot. errors (± s.e.): a group per value of `group_key`, a bar per series."""
    groups = sorted({row[group_key] for row in rows}, key=tables._sort_key)
    series = _series(rows, series_keys)
    width = 0.8 / max(len(series), 1)
    figure, axes = plt.subplots(1, len(PANELS), figsize=(11, 4))
    for axis, (metric, label) in zip(axes, PANELS):
        for k, (name, members) in enumerate(series.items()):
            by_group = {row[group_key]: row for row in members}
            values = [_value(by_group[g], metric) if g in by_group else np.nan for g in groups]
            errors = [_value(by_group[g], f"{metric}_se") if g in by_group else np.nan for g in groups]
            axis.bar(np.arange(len(groups)) + k * width, values, width, yerr=np.nan_to_num(errors), label=name)
        axis.set_xticks(np.arange(len(groups)) + 0.4 - width / 2, [str(g) for g in groups], rotation=30)
        axis.set_ylabel(label)
    axes[0].legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return Path(path)


def _velocity(row):
    digits = "".join(ch for ch in row["test_split"] if ch.isdigit())
    return float(digits) if digits else None


def plot(results: Mapping, workdir: str | os.PathLike) -> list[Path]:
    """The figures of one experiment (chosen by ``results["name"]``), written to `workdir` as PNG."""
    name, rows, workdir = results["name"], tables.aggregate(results["rows"]), Path(workdir)
    size = lambda row: row["train_size"]  # noqa: E731
    if name == "data_efficiency":
        return [line_figure(rows, size, "training examples", ["model"], workdir / "fig5_data_efficiency.png",
                            log_x=True)]
    if name == "error_variants":
        unscaled = [row for row in rows if row["l_scale"] == 1.0 and row["model"] != "physics"]
        return [
            line_figure(unscaled, size, "training examples", ["model"], workdir / "fig9_error_variants.png",
                        log_x=True),
            bar_figure(rows, "l_scale", ["model", "train_size"], workdir / "table5_wrong_l.png"),
        ]
    if name == "velocities":
        trained = [row for row in rows if row["kind"] == "trained"]
        baselines = [{**row, "train_split": "baseline"} for row in rows if row["kind"] == "baseline"]
        return [line_figure([*trained, *baselines], _velocity, "test push velocity [mm/s]",
                            ["model", "train_split"], workdir / "fig6_velocities.png")]
    if name == "objects":
        return [bar_figure(rows, "test_split", ["model", "train_split"], workdir / "fig7_objects.png")]
    return [bar_figure(rows, "test_split", ["model", "train_size"], workdir / f"{name}.png")]
