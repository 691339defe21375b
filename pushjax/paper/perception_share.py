"""How much of hybrid's error is its perception: the same model on its perceived and on the true state.

``hybrid`` perceives the contact point, the surface normal and the contact indicator from the depth image and feeds
them, with the pusher's motion over the window (``action``), the limit-surface ratio and the friction, to Lynch's
model (`pushjax.models.heads.HybridHead`). Given the annotated state instead, the trained network has nothing left
to do: `true_state_predictions` is what any hybrid with perfect perception predicts. So on the same test sequences

* ``hybrid − hybrid_true_state`` is what its perception costs (the perception's share), and
* ``hybrid_true_state − physics`` is what remains between a perfect hybrid and the ``physics`` baseline, which gets
  the pusher's motion from first contact on (``action_from_contact``) rather than the whole window's.

Both paired over the test split's push sequences (`pushjax.paper.statistics`), over the seeds of every hybrid
recorded at a size in a run's ``models/`` (`pushjax.paper.full_run.records`); the perception's own errors beside the
paper's Table 2.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from pushjax import outputs, train as train_lib
from pushjax.paper import baselines, full_run, reference, runner, statistics
from pushjax.physics import lynch
from pushjax.train import evaluate

TRUE_STATE = "hybrid_true_state"
STATE_METRICS = ("contact_mm", "normal_deg", "pos_mm", "s")
"""The perception's errors (`pushjax.train.evaluate.error_metrics`) reported beside the paper's Table 2."""


def true_state_predictions(examples: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """What a hybrid with perfect perception predicts: Lynch on the annotated contact point (relative to the centre of
    mass, m), normal and contact flag, with the window's pusher motion ``action`` [N, 2] (m), ``l`` and ``mu``.

    Returns {"motion": [N, 3] (m, m, rad)}."""
    motion = np.asarray(examples["motion"])
    predicted = lynch.predict(examples["contact"], examples["normal"], examples["action"], examples["l"],
                              examples["mu"], examples["contact_flag"])
    return {"motion": np.asarray(predicted, motion.dtype)}


def baseline_row(name: str, predictions: Mapping[str, np.ndarray], examples: Mapping[str, np.ndarray]) -> dict:
    """A ``results.json``-style baseline row (per-sequence sums included) of `predictions` on the test split."""
    return runner.finite_or_none({"model": name, "kind": "baseline", "train_split": None, "test_split": "test",
                                  "train_size": None, "seed": None, "l_scale": 1.0, "steps": None,
                                  **evaluate.error_metrics(predictions, examples)})


def _estimates(rows: Sequence[Mapping]) -> dict[str, statistics.Estimate]:
    return {metric: statistics.estimate(rows, metric) for metric in ("trans_percent", "rot_percent", statistics.SCORE)}


def _cell(estimate: statistics.Estimate) -> dict:
    return {"value": estimate.value, "se": estimate.se}


def analyse(examples: Mapping[str, np.ndarray], runs: Mapping[str, str | Path], size: int = full_run.FULL) -> dict:
    """The perception's share of hybrid's error in every run of `runs` (label -> a ``data_efficiency_full``-style work
    directory) at training size `size`, on the test split `examples` ({field: [N, ...]}, `full_run`'s fields)."""
    physics = baseline_row("physics", baselines.predictions("physics", examples), examples)
    true_state = baseline_row(TRUE_STATE, true_state_predictions(examples), examples)
    reference_rows = {"physics": _estimates([physics]), TRUE_STATE: _estimates([true_state])}
    paper_state = reference.tables().get("table2_state_errors_190k", {}).get("hybrid", {})
    result_rows = [{"run": None, "model": name, "seeds": 0,
                    **{metric: _cell(estimate) for metric, estimate in cells.items()}}
                   for name, cells in reference_rows.items()]
    for label, workdir in runs.items():
        hybrids = [record["row"] for record in full_run.records(workdir).values()
                   if record["row"]["model"] == "hybrid" and record["row"]["train_size"] == size]
        if not hybrids:
            continue
        hybrid = _estimates(hybrids)
        row = {"run": label, "model": "hybrid", "seeds": len(hybrids), "steps": [r["steps"] for r in hybrids],
               **{metric: _cell(estimate) for metric, estimate in hybrid.items()},
               "perception_share": {metric: _cell(statistics.difference(hybrid[metric],
                                                                        reference_rows[TRUE_STATE][metric]))
                                    for metric in hybrid},
               "state_errors": {metric: {"value": float(np.mean([r[metric] for r in hybrids])),
                                         "paper": (paper_state.get(metric) or [None])[0]}
                                for metric in STATE_METRICS if all(r.get(metric) is not None for r in hybrids)}}
        result_rows.append(row)
    gap = {metric: _cell(statistics.difference(reference_rows[TRUE_STATE][metric], reference_rows["physics"][metric]))
           for metric in reference_rows["physics"]}
    return {"size": size, "rows": result_rows, "true_state_minus_physics": gap}


def markdown(results: Mapping) -> str:
    """The analysis as markdown: one line per model, then the perception's share and its state errors."""
    def fmt(cell, sign=""):
        if cell is None or cell["value"] is None:
            return "–"
        return f"{cell['value']:{sign}.2f}" + (f" ± {cell['se']:.2f}" if cell.get("se") is not None else "")

    lines = [f"# The perception's share of hybrid's error at {results['size']:,} examples", "",
             "Translation and rotation in % of zero, the score their mean; ± one standard error (test sequences and "
             "seeds).", "",
             "| run | model | seeds | trans % | rot % | score | perception's share of the score (hybrid − true state) |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for row in results["rows"]:
        share = row.get("perception_share", {}).get(statistics.SCORE)
        lines.append(f"| {row['run'] or '–'} | {row['model']} | {row['seeds']} | {fmt(row['trans_percent'])} | "
                     f"{fmt(row['rot_percent'])} | {fmt(row[statistics.SCORE])} | {fmt(share, '+')} |")
    gap = results["true_state_minus_physics"]
    lines += ["", f"A perfect hybrid (the true state, the window's pusher motion) against physics (the motion from "
              f"first contact): trans {fmt(gap['trans_percent'], '+')}, rot {fmt(gap['rot_percent'], '+')}, score "
              f"{fmt(gap[statistics.SCORE], '+')} points.", "",
              "| run | contact mm | normal ° | position mm | s | paper (contact mm, normal °, s) |",
              "|---|---:|---:|---:|---:|---|"]
    for row in results["rows"]:
        if "state_errors" not in row:
            continue
        errors = row["state_errors"]
        value = lambda metric: f"{errors[metric]['value']:.2f}" if metric in errors else "–"  # noqa: E731
        paper = ", ".join("–" if errors.get(m, {}).get("paper") is None else f"{errors[m]['paper']:g}"
                          for m in ("contact_mm", "normal_deg", "s"))
        lines.append(f"| {row['run']} | {value('contact_mm')} | {value('normal_deg')} | {value('pos_mm')} | "
                     f"{value('s')} | {paper} |")
    return "\n".join(lines) + "\n"


def run(data_dir: str | Path | None, runs: Mapping[str, str | Path], out_dir: str | Path,
        scale: str = full_run.SCALE, size: int = full_run.FULL) -> dict:
    """Reads the ``data_efficiency`` test split at `scale`, analyses `runs` and writes results.json and results.md."""
    spec = full_run.make_spec(data_dir, scale=scale, build=False)
    test = runner.load_splits(spec, spec.dataset, False)["test"]
    examples = train_lib.examples_from_source(test, spec.example_fields())
    results = analyse(examples, runs, size)
    outputs.write_report(out_dir, results, markdown(results))
    return results
