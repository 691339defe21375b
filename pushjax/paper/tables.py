"""Markdown tables laid out like the paper's, from the ``results`` of `pushjax.paper.runner.run`.

Cells are the mean over seeds ± the standard error of `pushjax.paper.statistics` (a bootstrap over the test
split's push sequences combined with the spread over seeds). Translation and rotation errors are percentages of
the ``zero`` baseline's.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from pushjax.paper import statistics

GROUP_KEYS = ("model", "kind", "train_split", "test_split", "train_size", "l_scale")
METRIC_LABELS = {
    "trans_percent": "trans. [%]", "rot_percent": "rot. [%]", "pos_mm": "pos. [mm]",
    "contact_mm": "contact [mm]", "normal_deg": "normal [°]", "s": "s error",
    "push_velocity_deg": "v_p [°]",
}
STATE_METRICS = ("pos_mm", "contact_mm", "normal_deg", "s", "push_velocity_deg")
_UNCERTAIN = ("trans_percent", "rot_percent", *STATE_METRICS)
"""Metrics given with a standard error (and its parts ``_se_sequences``, ``_se_seeds``)."""


def group(rows: Sequence[Mapping]) -> dict[tuple, list[Mapping]]:
    """Rows by cell: `GROUP_KEYS` values -> the cell's rows (one per seed)."""
    groups: dict[tuple, list[Mapping]] = {}
    for row in rows:
        groups.setdefault(tuple(row.get(key) for key in GROUP_KEYS), []).append(row)
    return groups


def aggregate(rows: Sequence[Mapping]) -> list[dict]:
    """Rows merged over seeds: one per `GROUP_KEYS`, ``seeds`` listed, every numeric metric the mean over seeds
    (None when a seed lacks it); `_UNCERTAIN` metrics also with ``_se``, ``_se_sequences`` and ``_se_seeds``."""
    merged = []
    for key, members in group(rows).items():
        row = dict(zip(GROUP_KEYS, key))
        row["seeds"] = [member.get("seed") for member in members]
        metrics = [name for name, value in members[0].items()
                   if name not in GROUP_KEYS and name != "seed" and "_se" not in name
                   and (value is None or isinstance(value, (int, float)))]
        for name in metrics:
            estimate = statistics.estimate(members, name)
            row[name] = None if estimate is None else estimate.value
            if name in _UNCERTAIN:
                for part in ("se", "se_sequences", "se_seeds"):
                    row[f"{name}_{part}"] = None if estimate is None else getattr(estimate, part)
        merged.append(row)
    return merged


def format_value(row: Mapping, metric: str) -> str:
    """``mean ± se`` (or ``mean``, or ``–`` when undefined), one decimal."""
    value, se = row.get(metric), row.get(f"{metric}_se")
    if value is None:
        return "–"
    return f"{value:.1f} ± {se:.1f}" if se is not None else f"{value:.1f}"


def _row_label(row: Mapping, row_keys: Sequence[str]) -> list[str]:
    return ["" if row.get(key) is None else str(row[key]) for key in row_keys]


def _markdown(header: Sequence[str], body: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cells) + " |" for cells in body]
    return "\n".join(lines)


def pivot_table(rows: Sequence[Mapping], row_keys: Sequence[str], column_key: str,
                metrics: Sequence[str] = ("trans_percent", "rot_percent")) -> str:
    """A table with a row per distinct `row_keys` and a column per value of `column_key`.

    Each cell shows `metrics` separated by `` / ``. Rows whose `column_key` is null (the baselines' training
    size) fill every column.
    """
    columns = sorted({row[column_key] for row in rows if row.get(column_key) is not None}, key=_sort_key)
    if not columns:
        columns = [None]
    cells: dict[tuple, dict] = {}
    for row in rows:
        label = tuple(_row_label(row, row_keys))
        for column in columns if row.get(column_key) is None else [row[column_key]]:
            cells.setdefault(label, {})[column] = " / ".join(format_value(row, metric) for metric in metrics)
    header = [*row_keys, *(f"{column_key}={column}" for column in columns)]
    body = [[*label, *(values.get(column, "") for column in columns)] for label, values in cells.items()]
    return f"{' / '.join(METRIC_LABELS.get(m, m) for m in metrics)}\n\n" + _markdown(header, body)


def metrics_table(rows: Sequence[Mapping], row_keys: Sequence[str], metrics: Sequence[str]) -> str:
    """A table with a row per row of `rows` and a column per metric."""
    header = [*row_keys, *(METRIC_LABELS.get(metric, metric) for metric in metrics)]
    return _markdown(header, [[*_row_label(row, row_keys), *(format_value(row, m) for m in metrics)]
                              for row in rows])


def _sort_key(value):
    if isinstance(value, (int, float)):
        return (0, value, "")
    digits = "".join(ch for ch in str(value) if ch.isdigit())
    return (1, int(digits) if digits else math.inf, str(value))


def _largest_size(rows):
    sizes = [row["train_size"] for row in rows if row.get("train_size") is not None]
    return max(sizes) if sizes else None


def markdown(results: Mapping) -> str:
    """The paper-style tables of one experiment's results (layout chosen by ``results["name"]``)."""
    name, rows = results["name"], aggregate(results["rows"])
    config = results["config"]
    testbed = config.get("testbed", "ideal")  # results written before testbed profiles existed are ideal's
    title = (f"# {name} ({config['experiment']} dataset, {config['scale']} scale, {testbed} testbed, "
             f"seeds {config['seeds']})\n\n")
    trained = [row for row in rows if row["kind"] == "trained"]
    overall = ("trans_percent", "rot_percent", "pos_mm")
    if name == "data_efficiency":
        largest = [row for row in trained if row["train_size"] == _largest_size(trained)]
        return title + "\n\n".join([
            "## Table 1: errors by training-set size\n\n" + pivot_table(rows, ["model"], "train_size"),
            f"## Table 2: state errors at {_largest_size(trained)} training examples\n\n"
            + metrics_table(largest, ["model"], STATE_METRICS),
        ]) + "\n"
    if name in ("velocities", "error_velocities", "objects"):
        figure = {"velocities": "Fig. 6", "error_velocities": "Fig. 9", "objects": "Fig. 7"}[name]
        return title + f"## {figure}: errors per test set\n\n" + pivot_table(
            rows, ["model", "train_split", "train_size"], "test_split") + "\n"
    if name == "error_variants":
        unscaled = [row for row in rows if row["l_scale"] == 1.0]
        scaled = [row for row in rows if row["model"] in ("physics", "hybrid", "error")]
        return title + "\n\n".join([
            "## Table 4: error-term variants by training-set size\n\n"
            + pivot_table([r for r in unscaled if r["model"] != "physics"], ["model"], "train_size"),
            "## Table 5: wrong limit-surface ratio l (factor of the true value)\n\n"
            + pivot_table(scaled, ["model", "train_size"], "l_scale"),
        ]) + "\n"
    heading = {"new_pushes": "Table 3: new pushes", "viewpoint": "Sec. V: free camera with point clouds",
               "visualize": "Errors on the repeated push (Figs. 7-8)"}
    return title + f"## {heading.get(name, name)}\n\n" + metrics_table(
        rows, ["model", "train_size", "test_split"], overall) + "\n"


def write(results: Mapping, workdir: str | os.PathLike) -> Path:
    """Writes `markdown` to ``<workdir>/results.md`` and returns the path."""
    path = Path(workdir) / "results.md"
    path.write_text(markdown(results))
    return path
