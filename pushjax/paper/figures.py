"""Matplotlib figures (PNG) of the ``results`` of `pushjax.paper.runner.run`, like the paper's."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import matplotlib.colors
import matplotlib.pyplot as plt
import numpy as np

from pushjax.paper import reference, tables

PANELS = (("trans_percent", "translation error [% of zero]"), ("rot_percent", "rotation error [% of zero]"))
MODEL_ORDER = ("zero", "physics", "neural", "neural_dyn", "hybrid", "simple", "error", "error_grad", "error_norm")
MODEL_COLOURS = dict(zip(MODEL_ORDER, plt.get_cmap("tab10").colors))
"""One colour per model, the same in every figure."""
_LINE_STYLES = ("-", "--", ":", "-.")
_MARKERS = ("o", "s", "^", "D", "v")
_HATCHES = ("", "//", "..", "xx", "\\\\")


def _series(rows: Sequence[Mapping], series_keys: Sequence[str]) -> dict[str, list[Mapping]]:
    series: dict[str, list[Mapping]] = {}
    for row in rows:
        label = ", ".join(str(row[key]) for key in series_keys if row.get(key) is not None)
        series.setdefault(label, []).append(row)
    return series


def _variant_index(series: Mapping[str, list[Mapping]]) -> dict[str, int]:
    """series label -> index of its non-model keys (e.g. its training split) among the series of its model."""
    seen: dict[str, int] = {}
    index = {}
    for label, members in series.items():
        model = members[0]["model"]
        index[label] = seen.get(model, 0)
        seen[model] = index[label] + 1
    return index


def _colour(model: str):
    """The model's colour; a model at the paper's widths (``<variant>_wide``) has its variant's."""
    return MODEL_COLOURS.get(model.removesuffix("_wide"), "0.3")


def _log_ticks(values) -> tuple[list[float], list[str]]:
    """Tick positions and compact labels (2.5k, 190k) for a log axis, one tick where values lie within 5 % of each
    other (our 190 080 examples beside the paper's 190 000)."""
    ticks = []
    for value in sorted(values):
        if not ticks or value > ticks[-1] * 1.05:
            ticks.append(value)
    return ticks, [f"{value / 1000:.3g}k" if value >= 1000 else f"{value:g}" for value in ticks]


def _value(row, metric):
    value = row.get(metric)
    return np.nan if value is None else value


def _finish(figure, axes, path) -> Path:
    """One legend for all panels, outside the data, and the PNG."""
    handles, labels = axes[0].get_legend_handles_labels()
    figure.tight_layout()
    figure.legend(handles, labels, loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small", frameon=False)
    figure.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(figure)
    return Path(path)


def line_figure(rows: Sequence[Mapping], x: Callable[[Mapping], float], x_label: str,
                series_keys: Sequence[str], path: str | os.PathLike, log_x: bool = False,
                paper_points: Mapping[str, Sequence[tuple[float, Mapping[str, float]]]] | None = None) -> Path:
    """Trans. and rot. errors (± s.e.) against ``x(row)``, a line per distinct `series_keys`.

    The colour says the model (`MODEL_COLOURS`), the line style and marker the other series keys. Rows where
    ``x(row)`` is None (baselines without a training size) are drawn as horizontal lines. `paper_points`: model ->
    [(x, {metric: value})], the paper's values, drawn as hollow diamonds in the model's colour.
    """
    series = _series(rows, series_keys)
    variant = _variant_index(series)
    figure, axes = plt.subplots(1, len(PANELS), figsize=(11, 4))
    for axis, (metric, label) in zip(axes, PANELS):
        xs_seen = set()
        for name, members in series.items():
            colour, k = _colour(members[0]["model"]), variant[name]
            style = _LINE_STYLES[k % len(_LINE_STYLES)]
            points = sorted((x(row), _value(row, metric), _value(row, f"{metric}_se")) for row in members
                            if x(row) is not None)
            if points:
                xs, ys, ses = map(np.asarray, zip(*points))
                xs_seen.update(xs.tolist())
                wide = members[0]["model"].endswith("_wide")
                axis.errorbar(xs, ys, yerr=np.nan_to_num(ses), marker="*" if wide else _MARKERS[k % len(_MARKERS)],
                              markersize=11 if wide else 6, linestyle=style, color=colour, capsize=3, label=name)
            else:
                axis.axhline(_value(members[0], metric), linestyle="--", color=colour, linewidth=1.2, label=name)
        for model, points in (paper_points or {}).items():
            points = [(px, values[metric]) for px, values in points if metric in values]
            if points:
                xs, ys = map(np.asarray, zip(*points))
                xs_seen.update(xs.tolist())
                axis.plot(xs, ys, linestyle="none", marker="D", markerfacecolor="none", markersize=8,
                          color=_colour(model), label=f"{model} (paper)")
        axis.set_xlabel(x_label)
        axis.set_ylabel(label)
        if log_x:
            axis.set_xscale("log")
            axis.set_xticks(*_log_ticks(xs_seen))
            axis.minorticks_off()
        axis.grid(alpha=0.3)
    return _finish(figure, axes, path)


def bar_figure(rows: Sequence[Mapping], group_key: str, series_keys: Sequence[str],
               path: str | os.PathLike) -> Path:
    """Grouped bars of trans. and rot. errors (± s.e.): a group per value of `group_key`, a bar per series.

    The colour says the model (`MODEL_COLOURS`), the hatching the other series keys.
    """
    groups = sorted({row[group_key] for row in rows}, key=tables._sort_key)
    series = _series(rows, series_keys)
    variant = _variant_index(series)
    width = 0.8 / max(len(series), 1)
    figure, axes = plt.subplots(1, len(PANELS), figsize=(11, 4))
    for axis, (metric, label) in zip(axes, PANELS):
        for k, (name, members) in enumerate(series.items()):
            by_group = {row[group_key]: row for row in members}
            values = [_value(by_group[g], metric) if g in by_group else np.nan for g in groups]
            errors = [_value(by_group[g], f"{metric}_se") if g in by_group else np.nan for g in groups]
            axis.bar(np.arange(len(groups)) + k * width, values, width, yerr=np.nan_to_num(errors), label=name,
                     color=_colour(members[0]["model"]), hatch=_HATCHES[variant[name] % len(_HATCHES)],
                     edgecolor="white", linewidth=0.5)
        axis.set_xticks(np.arange(len(groups)) + 0.4 - width / 2, [str(g) for g in groups], rotation=30)
        axis.set_xlabel(group_key.replace("_", " "))
        axis.set_ylabel(label)
        axis.grid(alpha=0.3, axis="y")
    return _finish(figure, axes, path)


def _curve_means(curves: Sequence[Mapping]) -> dict[tuple, tuple[np.ndarray, np.ndarray]]:
    """(model, train_split, train_size, l_scale, split) -> (steps [T], score [T] averaged over seeds)."""
    by_step: dict[tuple, dict[int, list[float]]] = {}
    for row in curves:
        key = (row["model"], row["train_split"], row["train_size"], row["l_scale"], row["split"])
        by_step.setdefault(key, {}).setdefault(row["step"], []).append(
            (row["trans_percent"] + row["rot_percent"]) / 2.0)
    return {key: (np.asarray(sorted(steps)), np.asarray([np.mean(steps[step]) for step in sorted(steps)]))
            for key, steps in by_step.items()}


def _curve_label(train_split: str, size: int, l_scale: float, split: str, several: Mapping[str, bool]) -> str:
    parts = ([train_split] if several["train_split"] else []) + [f"{size:,} examples"]
    parts += [f"l x{l_scale:g}"] if several["l_scale"] else []
    return ", ".join(parts + [split])


def curves_figure(curves: Sequence[Mapping], path: str | os.PathLike) -> Path:
    """Learning curves: a panel per model, the score (mean of trans. and rot. % of zero, mean over seeds) on the
    model's own training examples (dashed) and on the validation split (solid) against steps, a line per training
    set (training split, size and l scale; darker: later in that order, i.e. larger), each named in the legend
    by what varies among them."""
    means = _curve_means(curves)
    models = sorted({key[0] for key in means}, key=lambda m: (MODEL_ORDER.index(m) if m in MODEL_ORDER else len(MODEL_ORDER), m))
    several = {"train_split": len({key[1] for key in means}) > 1, "l_scale": len({key[3] for key in means}) > 1}
    columns = min(4, len(models))
    rows = -(-len(models) // columns)
    figure, axes = plt.subplots(rows, columns, figsize=(3.2 * columns, 2.8 * rows), squeeze=False, sharex=True)
    for axis, model in zip(axes.flat, models):
        training_sets = sorted({key[1:4] for key in means if key[0] == model},
                               key=lambda key: (str(key[0]), key[1] or 0, key[2] or 0.0))
        for (name, train_split, size, l_scale, split), (steps, scores) in sorted(
                means.items(), key=lambda item: str(item[0])):
            if name != model:
                continue
            shade = 0.45 + 0.55 * (training_sets.index((train_split, size, l_scale)) + 1) / len(training_sets)
            colour = tuple(shade * c + (1 - shade) for c in matplotlib.colors.to_rgb(_colour(model)))
            axis.plot(steps, scores, linestyle="--" if split == "train" else "-", color=colour,
                      label=_curve_label(train_split, size, l_scale, split, several))
        axis.set_title(model, fontsize="medium")
        axis.set_xlabel("training step")
        axis.set_ylabel("score [% of zero]")
        axis.set_ylim(bottom=0, top=min(150, axis.get_ylim()[1]))
        axis.grid(alpha=0.3)
        axis.legend(fontsize="x-small", frameon=False)
    for axis in list(axes.flat)[len(models):]:
        axis.set_visible(False)
    figure.tight_layout()
    figure.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(figure)
    return Path(path)


def _velocity(row):
    digits = "".join(ch for ch in row["test_split"] if ch.isdigit())
    return float(digits) if digits else None


def paper_table1_points() -> dict[str, list[tuple[float, dict[str, float]]]]:
    """model -> [(size, {"trans_percent", "rot_percent"})] of the paper's Table 1 (2 500 and 190 000 examples);
    {} without the paper's tables."""
    table = reference.tables().get("table1_data_efficiency", {})
    points: dict[str, list] = {}
    for size in ("2500", "190000"):
        for model, cell in table.get(size, {}).items():
            values = {metric: cell[key][0] for metric, key in (("trans_percent", "trans"), ("rot_percent", "rot"))
                      if key in cell}
            points.setdefault(model, []).append((float(size), values))
    return points


def plot(results: Mapping, workdir: str | os.PathLike) -> list[Path]:
    """The figures of one experiment (chosen by ``results["name"]``), written to `workdir` as PNG."""
    name, rows, workdir = results["name"], tables.aggregate(results["rows"]), Path(workdir)
    size = lambda row: row["train_size"]  # noqa: E731
    curves = [curves_figure(results["curves"], workdir / "learning_curves.png")] if results.get("curves") else []
    if name == "data_efficiency_full":
        return [line_figure(rows, size, "training examples", ["model"], workdir / "fig5_data_efficiency.png",
                            log_x=True, paper_points=paper_table1_points()), *curves]
    if name == "data_efficiency":
        return [line_figure(rows, size, "training examples", ["model"], workdir / "fig5_data_efficiency.png",
                            log_x=True), *curves]
    if name == "error_variants":
        unscaled = [row for row in rows if row["l_scale"] == 1.0 and row["model"] != "physics"]
        return [
            line_figure(unscaled, size, "training examples", ["model"], workdir / "table4_error_variants.png",
                        log_x=True),
            bar_figure(rows, "l_scale", ["model", "train_size"], workdir / "table5_wrong_l.png"),
        ]
    if name in ("velocities", "error_velocities"):
        trained = [row for row in rows if row["kind"] == "trained"]
        baselines = [{**row, "train_split": "baseline"} for row in rows if row["kind"] == "baseline"]
        file = "fig6_velocities.png" if name == "velocities" else "fig9_error_variants_velocities.png"
        return [line_figure([*trained, *baselines], _velocity, "test push velocity [mm/s]",
                            ["model", "train_split"], workdir / file)]
    if name == "objects":
        return [bar_figure(rows, "test_split", ["model", "train_split"], workdir / "fig7_objects.png")]
    return [bar_figure(rows, "test_split", ["model", "train_size"], workdir / f"{name}.png")]
