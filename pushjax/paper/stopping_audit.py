"""Which models of a convergence-criterion run the trend rule would have kept training.

The ``data_efficiency_full`` run stopped each model when the best of its last five validation scores was not 1 %
better than the best before them (`pushjax.train.convergence.CRITERION`). `audit` replays every recorded model's
validation curve (its constant-rate phase) under `pushjax.train.stopping.RULE` and says, at the step the criterion
stopped it:

* ``improving``: the trend of its last 10 000 steps still falls (`pushjax.train.stopping.IMPROVING`: the one-sided
  95 % lower bound on the gain above zero) -- a model stopped while improving;
* ``rule_stops``: the trend rule would have stopped there too (its upper bound on the gain below 0.5 points per
  10 000 steps); ``too_short``: fewer steps than the rule's window, so it could not have stopped yet;
* ``first_stop``: the first evaluation at which the rule stops within the recorded curve (None: never).

A run of fixed budgets (the paper's 75 000 steps, `pushjax.train.convergence.PAPER_SCHEDULE`) is judged by the
continuation rule instead (`continuations`): per variant and size, each seed's trend at its last score and whether
`pushjax.train.stopping.long_run_continues` sends the variant's seeds on to twice their steps.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path

from pushjax import outputs
from pushjax.paper import full_run
from pushjax.train import stopping


def _curve(record: Mapping) -> tuple[list[int], list[float]]:
    """(steps, scores) of a record's constant-rate phase, the score the mean of translation and rotation."""
    points = [point for point in record["validation"] if point["step"] <= record["row"]["constant_steps"]]
    return [point["step"] for point in points], [(point["trans_percent"] + point["rot_percent"]) / 2.0
                                                 for point in points]


def audit_record(record: Mapping, rule: stopping.TrendRule = stopping.RULE) -> dict:
    """One model's row: its key, variant, size, seed, the criterion's stop and the trend rule's verdict there."""
    row = record["row"]
    stop = row["constant_steps"]
    steps, scores = _curve(record)
    trend, end = rule.trend(steps, scores), stopping.IMPROVING.trend(steps, scores, require_span=False)
    return {"key": record["key"], "variant": row["model"], "size": row["train_size"], "seed": row["seed"],
            "stopped_at": stop, "criterion_met": bool(row["converged"]), "too_short": trend is None,
            "rule_stops": trend is not None and trend.gain_upper < rule.max_gain,
            "improving": end is not None and end.gain_lower > 0.0,
            "end_trend": None if end is None else dataclasses.asdict(end),
            "trend": None if trend is None else dataclasses.asdict(trend),
            "first_stop": rule.first_stop(steps, scores)}


def continuations(records: Mapping[str, Mapping], rule: stopping.TrendRule = stopping.RULE) -> list[dict]:
    """Per (variant, size) of the fixed-budget `records` (their criterion's ``stop_on_plateau`` false), in key order:
    the seeds, their steps, each one's trend over the rule's window at its last score and whether the rule stops it,
    and ``continues``: `pushjax.train.stopping.long_run_continues` over the seeds (then ``next_steps``, twice the
    most steps, else None)."""
    groups: dict[tuple[str, int], list[Mapping]] = {}
    for key in sorted(records):
        record = records[key]
        if not record["criterion"]["stop_on_plateau"]:
            groups.setdefault((record["row"]["model"], record["row"]["train_size"]), []).append(record)
    rows = []
    for (variant, size), members in groups.items():
        curves = [_curve(record) for record in members]
        trends = [rule.trend(steps, scores) for steps, scores in curves]
        continues = stopping.long_run_continues(curves, rule)
        rows.append({"variant": variant, "size": size, "seeds": [record["row"]["seed"] for record in members],
                     "steps": [record["row"]["steps"] for record in members],
                     "trends": [None if trend is None else dataclasses.asdict(trend) for trend in trends],
                     "rule_stops": [rule.stops(steps, scores) for steps, scores in curves], "continues": continues,
                     "next_steps": 2 * max(record["row"]["steps"] for record in members) if continues else None})
    return rows


def audit(workdir: str | Path, rule: stopping.TrendRule = stopping.RULE) -> dict:
    """The rows of every model recorded in `workdir` (a ``data_efficiency_full`` run), their counts and the
    fixed-budget models' `continuations`."""
    records = full_run.records(workdir)
    rows = [audit_record(record, rule) for record in records.values()]
    met = [row for row in rows if row["criterion_met"]]
    counts = {
        "models": len(rows), "criterion_met": len(met),
        "stopped_while_improving": sum(row["improving"] for row in met),
        "budget_ended_while_improving": sum(row["improving"] for row in rows if not row["criterion_met"]),
        "rule_would_not_stop": sum(not row["rule_stops"] for row in met),
        "rule_too_short": sum(row["too_short"] for row in met),
        "rule_agrees": sum(row["rule_stops"] for row in met),
    }
    return {"rule": dataclasses.asdict(rule), "workdir": str(workdir), "counts": counts, "rows": rows,
            "continuations": continuations(records, rule)}


def markdown(results: Mapping) -> str:
    """The audit as a markdown table, its counts first."""
    counts, rule = results["counts"], results["rule"]
    lines = [
        "# The convergence criterion replayed under the trend rule",
        "",
        f"Of {counts['models']} models, the criterion ended {counts['criterion_met']} (the others ran to their "
        f"budget). At the step it stopped them, {counts['stopped_while_improving']} were still improving (the "
        f"trend of their last 10 000 steps falling, its one-sided 95% lower bound above 0), and so were "
        f"{counts['budget_ended_while_improving']} of the {counts['models'] - counts['criterion_met']} that their "
        f"budget ended; the trend rule (upper bound on the gain below {rule['max_gain']} points per {rule['per_steps']} "
        f"steps) would have stopped {counts['rule_agrees']} of them there and kept training "
        f"{counts['rule_would_not_stop']} ({counts['rule_too_short']} of them shorter than its window).",
        "",
        "Gains are score points (the mean of translation and rotation in % of zero) per 10 000 steps, positive when "
        "the score falls: over the last 10 000 steps (improving: its lower bound above 0) and over the rule's window.",
        "",
        "| model | stopped at | criterion | gain, last 10 k steps | improving | gain, rule's window | its 95 % bounds "
        "| rule stops there | rule's first stop |",
        "|---|---:|---|---:|---|---:|---|---|---:|",
    ]
    for row in results["rows"]:
        trend, end = row["trend"], row["end_trend"]
        end_gain = "–" if end is None else f"{end['gain']:+.2f} ± {end['gain_se']:.2f}"
        gain = "–" if trend is None else f"{trend['gain']:+.2f} ± {trend['gain_se']:.2f}"
        bounds = "–" if trend is None else f"[{trend['gain_lower']:+.2f}, {trend['gain_upper']:+.2f}]"
        stops = "window not spanned" if row["too_short"] else ("yes" if row["rule_stops"] else "no")
        first = "–" if row["first_stop"] is None else f"{row['first_stop']:,}"
        lines.append(f"| {row['key']} | {row['stopped_at']:,} | {'met' if row['criterion_met'] else 'budget'} | "
                     f"{end_gain} | {'yes' if row['improving'] else 'no'} | {gain} | {bounds} | {stops} | {first} |")
    if results.get("continuations"):
        lines += ["", "## Fixed budgets: the continuation rule", "",
                  f"A variant's recorded seeds continue to twice their steps unless the rule stops every one of "
                  f"them at its last score (`pushjax.train.stopping.long_run_continues`: one seed's upper bound on "
                  f"the gain per {rule['per_steps']} steps over the last {rule['window_steps']} at or above "
                  f"{rule['max_gain']} points continues them all).", "",
                  "| variant | size | seed | steps | gain, rule's window | its 95 % bounds | rule stops | the variant |",
                  "|---|---:|---:|---:|---:|---|---|---|"]
        for row in results["continuations"]:
            verdict = f"continues to {row['next_steps']:,}" if row["continues"] else "stops"
            for seed, steps, trend, stops in zip(row["seeds"], row["steps"], row["trends"], row["rule_stops"]):
                gain = "–" if trend is None else f"{trend['gain']:+.2f} ± {trend['gain_se']:.2f}"
                bounds = "–" if trend is None else f"[{trend['gain_lower']:+.2f}, {trend['gain_upper']:+.2f}]"
                lines.append(f"| {row['variant']} | {row['size']:,} | {seed} | {steps:,} | {gain} | {bounds} | "
                             f"{'yes' if stops else 'no'} | {verdict} |")
    return "\n".join(lines) + "\n"


def write(results: Mapping, out_dir: str | Path) -> list[Path]:
    """``results.json`` and ``results.md`` of the audit in `out_dir`; their paths."""
    return outputs.write_report(out_dir, results, markdown(results))
