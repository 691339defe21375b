"""Markdown tables laid out like the paper's, from the ``results`` of `pushjax.paper.runner.run`.

Cells are the mean over seeds ± the standard error of `pushjax.paper.statistics` (a bootstrap over the test
split's push sequences combined with the spread over seeds). Translation and rotation errors are percentages of
the ``zero`` baseline's.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from pushjax.paper import reference, statistics

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


PaperCell = Callable[[Mapping, object], "str | None"]
"""(aggregated row, column value or None) -> the paper's value of that cell (`pushjax.paper.reference`), or None."""


def pivot_table(rows: Sequence[Mapping], row_keys: Sequence[str], column_key: str,
                metrics: Sequence[str] = ("trans_percent", "rot_percent"), paper: PaperCell | None = None) -> str:
    """A table with a row per distinct `row_keys` and a column per value of `column_key`.

    Each cell shows `metrics` separated by `` / ``. Rows whose `column_key` is null (the baselines' training
    size) fill every column. With `paper`, each column is followed by the paper's values of its cells (when the
    paper has any).
    """
    columns = sorted({row[column_key] for row in rows if row.get(column_key) is not None}, key=_sort_key)
    if not columns:
        columns = [None]
    cells: dict[tuple, dict] = {}
    for row in rows:
        label = tuple(_row_label(row, row_keys))
        for column in columns if row.get(column_key) is None else [row[column_key]]:
            cells.setdefault(label, {})[column] = " / ".join(format_value(row, metric) for metric in metrics)
            if paper is not None and (value := paper(row, column)) is not None:
                cells[label][("paper", column)] = value
    with_paper = {column for values in cells.values() for key in values if isinstance(key, tuple)
                  for column in [key[1]]}
    keys = [key for column in columns for key in ([column, ("paper", column)] if column in with_paper else [column])]
    header = [*row_keys, *("paper" if isinstance(key, tuple) else f"{column_key}={key}" for key in keys)]
    body = [[*label, *(values.get(key, "") for key in keys)] for label, values in cells.items()]
    return f"{' / '.join(METRIC_LABELS.get(m, m) for m in metrics)}\n\n" + _markdown(header, body)


def metrics_table(rows: Sequence[Mapping], row_keys: Sequence[str], metrics: Sequence[str],
                  paper: PaperCell | None = None) -> str:
    """A table with a row per row of `rows` and a column per metric; with `paper` (when it has any value) a last
    column of the paper's values of the same metrics."""
    body = [[*_row_label(row, row_keys), *(format_value(row, m) for m in metrics)] for row in rows]
    header = [*row_keys, *(METRIC_LABELS.get(metric, metric) for metric in metrics)]
    paper_values = [None if paper is None else paper(row, None) for row in rows]
    if any(value is not None for value in paper_values):
        header.append("paper")
        body = [cells + [value or ""] for cells, value in zip(body, paper_values)]
    return _markdown(header, body)


def _sort_key(value):
    if isinstance(value, (int, float)):
        return (0, value, "")
    digits = "".join(ch for ch in str(value) if ch.isdigit())
    return (1, int(digits) if digits else math.inf, str(value))


def _largest_size(rows):
    sizes = [row["train_size"] for row in rows if row.get("train_size") is not None]
    return max(sizes) if sizes else None


_STATISTICS_NOTE = ("Mean over seeds ± standard error: a bootstrap over the test split's push sequences combined with "
                    "the spread over seeds (`pushjax.paper.statistics`).\n\n")


def _paper_cells(name: str, sizes: Sequence[int], metrics: Sequence[str], size_from_column: bool = False,
                 l_from_column: bool = False) -> PaperCell:
    """The `PaperCell` of experiment `name`'s table whose columns are training sizes or ``l`` factors."""
    def paper(row: Mapping, column) -> str | None:
        size = column if size_from_column else row.get("train_size")
        l_scale = column if l_from_column else row.get("l_scale", 1.0)
        return reference.cell(name, row["model"], reference.size_role(size, sizes), metrics, l_scale)
    return paper


def _paper_notes(name: str) -> str:
    notes = reference.notes(name)
    return "\n**The paper says:**\n" + "".join(f"\n- {note}" for note in notes) + "\n" if notes else ""


def curves_table(curves: Sequence[Mapping], train_size: int) -> str:
    """How far each model trained at `train_size` is from flat: its score (mean of trans. and rot. % of zero, mean
    over seeds) on its training examples and on validation, at the first checkpoint after the start, at the end,
    and the change over the last fifth of the steps (negative: still improving)."""
    by_key: dict[tuple, dict[int, list[float]]] = {}
    for row in curves:
        if row["train_size"] == train_size and row.get("l_scale", 1.0) == 1.0:
            by_key.setdefault((row["model"], row["train_split"], row["split"]), {}).setdefault(row["step"], []).append(
                (row["trans_percent"] + row["rot_percent"]) / 2.0)
    body = []
    for (model, train_split, split), by_step in by_key.items():
        steps = sorted(by_step)
        score = {step: sum(values) / len(values) for step, values in by_step.items()}
        first = steps[1] if len(steps) > 1 else steps[0]
        fifth = min(steps, key=lambda step: abs(step - 0.8 * steps[-1]))
        body.append([model, train_split, split, f"{first:,}: {score[first]:.1f}", f"{steps[-1]:,}: {score[steps[-1]]:.1f}",
                     f"{score[steps[-1]] - score[fifth]:+.1f}"])
    header = ["model", "train_split", "curve on", "first checkpoint (step: score)", "end (step: score)",
              "change over the last fifth"]
    return _markdown(header, body)


def markdown(results: Mapping) -> str:
    """The paper-style tables of one experiment's results (layout chosen by ``results["name"]``), each with the
    paper's values beside ours where the paper gives them (`pushjax.paper.reference`)."""
    name, rows = results["name"], aggregate(results["rows"])
    config = results["config"]
    testbed = config.get("testbed", "ideal")  # results written before testbed profiles existed are ideal's
    trained = [row for row in rows if row["kind"] == "trained"]
    sizes = sorted({row["train_size"] for row in trained})
    grown = config.get("test_dataset", {}).get("min_test_sequences")
    title = (f"# {name} ({config['experiment']} dataset, {config['scale']} scale, {testbed} testbed, "
             f"seeds {config['seeds']}" + (f"; test splits grown to at least {grown} sequences" if grown else "")
             + ")\n\n" + _STATISTICS_NOTE)
    if reference.tables():
        title += (f"A *paper* column gives the paper's value of the cell to its left, where the paper has one; "
                  f"our largest training size ({max(sizes, default='–')}) stands for the paper's largest.\n\n")
    overall = ("trans_percent", "rot_percent", "pos_mm")
    errors = ("trans_percent", "rot_percent")
    if name in ("data_efficiency", "data_efficiency_full"):
        largest = [row for row in trained if row["train_size"] == _largest_size(trained)]
        return title + "\n\n".join([
            "## Table 1: errors by training-set size\n\n"
            + pivot_table(rows, ["model"], "train_size", paper=_paper_cells(name, sizes, errors, size_from_column=True)),
            f"## Table 2: state errors at {_largest_size(trained)} training examples\n\n"
            + metrics_table(largest, ["model"], STATE_METRICS, paper=_paper_cells(name, sizes, STATE_METRICS)),
            *([f"## Learning curves at {_largest_size(trained)} training examples\n\n"
               + curves_table(results["curves"], _largest_size(trained))] if results.get("curves") else []),
            *([convergence_table([row for row in results["rows"] if row["kind"] == "trained"],
                                 results["config"].get("criterion"))]
              if any("converged" in row for row in trained) else []),
            *([widths] if (widths := widths_table(results["rows"])) else []),
        ]) + "\n"
    if name in ("velocities", "error_velocities", "objects"):
        figure = {"velocities": "Fig. 6", "error_velocities": "Fig. 9", "objects": "Fig. 7"}[name]
        return title + f"## {figure}: errors per test set\n\n" + pivot_table(
            rows, ["model", "train_split", "train_size"], "test_split") + "\n" + _paper_notes(name)
    if name == "error_variants":
        unscaled = [row for row in rows if row["l_scale"] == 1.0]
        scaled = [row for row in rows if row["model"] in ("physics", "hybrid", "error")]
        return title + "\n\n".join([
            "## Table 4: error-term variants by training-set size\n\n"
            + pivot_table([r for r in unscaled if r["model"] != "physics"], ["model"], "train_size",
                          paper=_paper_cells(name, sizes, errors, size_from_column=True)),
            "## Table 5: wrong limit-surface ratio l (factor of the true value)\n\n"
            + pivot_table(scaled, ["model", "train_size"], "l_scale",
                          paper=_paper_cells(name, sizes, errors, l_from_column=True)),
        ]) + "\n"
    heading = {"new_pushes": "Table 3: new pushes", "viewpoint": "Sec. V: free camera with point clouds",
               "visualize": "Errors on the repeated push (Figs. 7-8)"}
    return title + f"## {heading.get(name, name)}\n\n" + metrics_table(
        rows, ["model", "train_size", "test_split"], overall, paper=_paper_cells(name, sizes, overall)) + "\n"


def convergence_table(trained: Sequence[Mapping], criterion: Mapping | None) -> str:
    """Per model and size: how many seeds met the convergence criterion and the steps they took (issue 30), from the
    `trained` rows of each seed (not merged over seeds)."""
    rule = ""
    if criterion:
        rule = (f" The criterion: the best validation score of the last {criterion['window']} evaluations (one every "
                f"{criterion['eval_every']} steps) not better by more than {criterion['min_improvement']:.0%} than the "
                f"best before them; \"budget\": the constant-rate budget ended first.")
    sizes = sorted({row["train_size"] for row in trained})
    models = list(dict.fromkeys(row["model"] for row in trained))
    lines = ["## Convergence: criterion met per model\n", "Seeds that met the criterion / seeds, and the mean steps "
             "(constant rate + decay)." + rule, "", "| model | " + " | ".join(map(str, sizes)) + " |",
             "|---|" + "---:|" * len(sizes)]
    for model in models:
        cells = []
        for size in sizes:
            members = [row for row in trained if row["model"] == model and row["train_size"] == size]
            if not members:
                cells.append("")
                continue
            met = sum(bool(row.get("converged")) for row in members)
            steps = np.mean([row["steps"] for row in members])
            cells.append(f"{met}/{len(members)} met, {steps:,.0f} steps")
        lines.append(f"| {model} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def widths_table(rows: Sequence[Mapping]) -> str:
    """Issue 30's check of the head's widths: for each ``<variant>_wide`` model (the paper's widths, one seed), its
    difference from the variant at our widths with the same seed and size, and neural − hybrid at both widths and its
    change, paired over the test sequences; beside them neural − hybrid at our widths over all its seeds. Empty
    without wide rows."""
    trained = [row for row in rows if row.get("kind") == "trained"]
    wide = {row["model"].removesuffix("_wide"): row for row in trained if row["model"].endswith("_wide")}
    if not wide:
        return ""
    size, seed = (next(iter(wide.values()))[key] for key in ("train_size", "seed"))
    narrow = {row["model"]: row for row in trained
              if row["train_size"] == size and row["seed"] == seed and row["model"] in wide}

    def one(row, metric):
        return statistics.estimate([row], metric)

    def seeds_of(model, metric):
        return statistics.estimate([row for row in trained if row["model"] == model and row["train_size"] == size],
                                   metric)

    comparisons = []
    for variant in wide:
        if variant in narrow:
            comparisons.append((f"{variant}_wide − {variant}",
                                lambda metric, v=variant: statistics.difference(one(wide[v], metric),
                                                                                one(narrow[v], metric))))
    if {"neural", "hybrid"} <= wide.keys() & narrow.keys():
        def gap(models, metric):
            return statistics.difference(one(models["neural"], metric), one(models["hybrid"], metric))
        comparisons += [
            (f"neural − hybrid, our widths (seed {seed})", lambda metric: gap(narrow, metric)),
            (f"neural − hybrid, the paper's widths (seed {seed})", lambda metric: gap(wide, metric)),
            ("change of neural − hybrid (paper's − ours)",
             lambda metric: statistics.difference(gap(wide, metric), gap(narrow, metric))),
            ("neural − hybrid, our widths (all seeds)",
             lambda metric: statistics.difference(seeds_of("neural", metric), seeds_of("hybrid", metric))),
        ]
    metrics = ("trans_percent", "rot_percent", statistics.SCORE)
    body = [[label] + [str(compare(metric)) for metric in metrics] for label, compare in comparisons]
    return (f"## The paper's widths at {size} training examples\n\nDifferences in % of zero, ± the standard error "
            f"paired over the test sequences (one seed each: the seeds' spread is only in the last row); score: the "
            f"mean of translation and rotation.\n\n" + _markdown(["comparison", "trans. [%]", "rot. [%]", "score"], body))


def write(results: Mapping, workdir: str | os.PathLike) -> Path:
    """Writes `markdown` to ``<workdir>/results.md`` and returns the path."""
    path = Path(workdir) / "results.md"
    path.write_text(markdown(results))
    return path
