"""The residual decomposition's rows and its report (`pushjax.paper.residual`, which re-exports them).

`CHAIN` and `REFERENCES` name the rows of the decomposition in their order and say what each is told and scored
against; `markdown` writes the table, the section on what the parts bound and the checks; `write` writes
``results.json`` and ``results.md``.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from pathlib import Path

from pushjax import outputs

CHAIN = (
    ("physics", "(a)", "motion capture", "motion capture",
     "Table 1's physics: Lynch, nominal mu and l, state annotated on the motion-capture poses"),
    ("clean_labels", "(a)", "noise-free", "motion capture", "the same predictions against the noise-free labels"),
    ("clean_state", "(a)", "noise-free", "noise-free", "and the state annotated on the true poses"),
    ("object_load", "(b)", "noise-free", "noise-free",
     "and l and centre of friction of the plate's own uneven load (per object)"),
    ("true_mu", "(b)", "noise-free", "noise-free", "and the push's own pusher-object friction (per push)"),
    ("drawn_load", "(b)", "noise-free", "noise-free",
     "and l and centre of friction of the whole drawn load where the plate is: table unevenness and friction "
     "field added (per surface), window mean"),
    ("exact_drawn", "(c)", "noise-free", "noise-free",
     "the exact limit surface of that drawn load on the simulator's point supports, instead of Lynch's ellipsoid"),
    ("exact_measured", "(c)", "noise-free", "noise-free",
     "the exact limit surface of the supports' measured friction capacity (normal force x coefficient, speed term "
     "included), window mean"),
)
"""The decomposition's rows in order: (name, part, labels, state, what the model is told / scored against)."""
REFERENCES = (
    ("zero", "reference", "motion capture", "-", "zero motion (the denominator of every row)"),
    ("zero_clean_labels", "reference", "noise-free", "-", "zero motion against the noise-free labels"),
    ("truth", "reference", "motion capture", "-",
     "the noise-free motion itself against the motion-capture labels: the label noise, about the floor of any model"),
    ("hidden_draws", "reference", "noise-free", "-",
     "the noise-free motion moved by what the hidden draws (the push's friction, the table's load and friction "
     "field where the plate is) change in the exact quasi-static model: their share of any state-based model's error"),
    ("state_floor", "reference", "motion capture", "-",
     "the same against the motion-capture labels: about the best error of a model given the state and the object"),
    ("hidden_draws_lynch", "reference", "noise-free", "-",
     "as `hidden_draws`, with what the hidden draws change in Lynch's model (about the centre of friction)"),
    ("state_floor_lynch", "reference", "motion capture", "-", "the same against the motion-capture labels"),
)
"""Reference rows (not in the chain of differences)."""


def _cell(row: Mapping, metric: str) -> str:
    se = row.get(f"{metric}_se")
    return f"{row[metric]:.1f} ± {se:.1f}" if se is not None and math.isfinite(se) else f"{row[metric]:.1f}"


def _change(values: Mapping, metric: str) -> str:
    return f"{values[metric]:+.1f} ± {values[f'{metric}_se']:.1f}"


def _pair(values: Mapping) -> str:
    """``+a ± s / +b ± t``: a change in translation and rotation points."""
    return f"{_change(values, 'trans_percent')} / {_change(values, 'rot_percent')}"


def _negated(values: Mapping) -> dict:
    """A row's difference from the one before, as the drop it makes (positive: the row's error is lower)."""
    return {key: -value if isinstance(value, float) and not key.endswith("_se") else value
            for key, value in values.items()}


def markdown(results: Mapping) -> str:
    """The decomposition as markdown: the rows, the parts and what they bound."""
    rows = {row["component"]: row for row in results["rows"]}
    lines = _table_lines(results, rows) + _bound_lines(results["parts"], rows) + _check_lines(results)
    return "\n".join(lines) + "\n"


def _table_lines(results: Mapping, rows: Mapping) -> list[str]:
    """The title, what the numbers are and the table of the rows."""
    zero = results["zero"]
    lines = [
        "# The physics baseline's error decomposed",
        "",
        f"`{results['dataset']}` ({results['testbed']} testbed), split `{results['split']}`: {results['subset']}, "
        f"{results['examples']:,} examples. `python -m experiments.residual_decomposition` "
        "(`pushjax.paper.residual`). Errors in % of the zero baseline on the motion-capture labels (Table 1's "
        f"denominator: {zero['trans_mm']:.2f} mm / {zero['rot_deg']:.2f}° per example) ± a bootstrap over push "
        "sequences; Δ is the paired difference from the row above (same resamples).",
        "",
        "| part | row | labels | state | what Lynch is told | translation % | rotation % | Δ translation | "
        "Δ rotation | mm / ° |",
        "|---|---|---|---|---|---:|---:|---:|---:|---|",
    ]
    for name, *_ in (*CHAIN, *REFERENCES):
        row = rows[name]
        change = row.get("difference")
        lines.append(f"| {row['part']} | `{name}` | {row['labels']} | {row['state']} | {row['description']} | "
                     f"{_cell(row, 'trans_percent')} | {_cell(row, 'rot_percent')} | "
                     f"{_change(change, 'trans_percent') if change else ''} | "
                     f"{_change(change, 'rot_percent') if change else ''} | "
                     f"{row['trans_mm']:.3f} / {row['rot_deg']:.3f} |")
    return lines


def _bound_lines(parts: Mapping, rows: Mapping) -> list[str]:
    """The section "What it bounds": the parts of the error and what a model could gain."""
    floor, truth, physics, state = rows["drawn_load"], rows["truth"], rows["physics"], rows["state_floor"]
    return [
        "",
        "## What it bounds",
        "",
        f"* **(a) tracking noise**: {_pair(parts['tracking'])} points (translation / rotation; `physics` − "
        f"`clean_state`), of which the labels {_pair(_negated(rows['clean_labels']['difference']))} and the state "
        f"annotated on noisy poses {_pair(_negated(rows['clean_state']['difference']))}. Irreducible: the labels "
        "(and the depth images a model sees) come from the motion capture. The noise-free motion itself scores "
        f"{_cell(truth, 'trans_percent')} / {_cell(truth, 'rot_percent')} % against the motion-capture labels "
        "(`truth`): no model's error on Table 1's metric falls much below that.",
        f"* **(b) push-to-push randomness**: {_pair(parts['randomness'])} points (`clean_state` − `drawn_load`): "
        f"the plate's own load (per object) {_pair(parts['object_load'])}, then the hidden draws (the push's own "
        f"friction {_pair(_negated(rows['true_mu']['difference']))} and the table's load and friction field where "
        f"the plate is {_pair(_negated(rows['drawn_load']['difference']))}) {_pair(parts['hidden_draws'])}. A model "
        "given the state cannot know the push's friction or the table's realisation where the plate is (nor can "
        "one given the depth image, whose scene transform hides the table position): irreducible. The plate's own "
        "load is fixed per object, learnable from the object's identity.",
        f"* **(c) what is left**: {_cell(floor, 'trans_percent')} / {_cell(floor, 'rot_percent')} % of zero "
        "(`drawn_load`, against the noise-free labels, Lynch told every drawn parameter): the structural misfit "
        "of the quasi-static ellipsoid to the MuJoCo plate, a function of the state and the object that a model "
        "could in principle learn. The exact limit surface of the supports' measured friction capacity removes "
        f"{_pair(parts['exact_limit_surface'])} points of it (`drawn_load` − `exact_measured`: the load's shape "
        f"and its transfer as the plate slides); the remaining {_cell(rows['exact_measured'], 'trans_percent')} / "
        f"{_cell(rows['exact_measured'], 'rot_percent')} % is dynamics (inertia, the plate sliding on after the "
        "pusher stops) and the load changing within the window.",
        f"* **The best a state-based model could reach**: about {_cell(state, 'trans_percent')} / "
        f"{_cell(state, 'rot_percent')} % of zero on Table 1's metric (`state_floor`: the truth moved by what the "
        "hidden draws change in the exact quasi-static model, against the motion-capture labels; "
        f"{_cell(rows['state_floor_lynch'], 'trans_percent')} / {_cell(rows['state_floor_lynch'], 'rot_percent')} % "
        f"with Lynch's sensitivity instead, `state_floor_lynch`), against `physics`' {_cell(physics, 'trans_percent')}"
        f" / {_cell(physics, 'rot_percent')} %: a model given the state (and the object) could gain at most about "
        f"{_pair(parts['learnable_gap'])} points over `physics` ({_pair(parts['learnable_gap_lynch'])} with Lynch's "
        "sensitivity), by learning the structural misfit (c) and the per-object load. Irreducible: the label noise "
        f"(`truth`) and the hidden draws (`hidden_draws`, {_cell(rows['hidden_draws'], 'trans_percent')} / "
        f"{_cell(rows['hidden_draws'], 'rot_percent')} % against the noise-free labels; Lynch: "
        f"{_cell(rows['hidden_draws_lynch'], 'trans_percent')} / {_cell(rows['hidden_draws_lynch'], 'rot_percent')}"
        " %), which add roughly in quadrature. The floor assumes the plate responds to the hidden draws as the exact "
        "quasi-static model does (it fits the plate better than Lynch's: `exact_drawn` against `drawn_load`) and "
        "takes the prediction at the nominal draws for the best guess without them (a model that learnt the "
        "conditional median over the draws could do slightly better); errors are norms, so the rows' steps depend "
        "on their order and do not add exactly.",
    ]


def _check_lines(results: Mapping) -> list[str]:
    """The section "Checks": the resimulation, the labels cut again, the contact flags, the solves' convergence."""
    checks = results["checks"]
    return [
        "",
        "## Checks",
        "",
        f"* Every one of the {checks['resimulated_identical']} pushes simulated again reproduced its stored file bit "
        "for bit (tip pose, tracked object pose, wrench), so its simulated true pose is the truth behind the file.",
        f"* The labels cut again from the files on the stored windows and transforms match the stored ones to "
        f"{checks['noisy_motion_max_difference_m'] * 1e3:.1e} mm and {checks['noisy_yaw_max_difference_rad']:.1e} "
        f"rad (float32 storage); Table 1's `physics` on these examples by `pushjax.train.evaluate`: "
        f"{checks['table1_physics']['trans_percent']:.2f} / {checks['table1_physics']['rot_percent']:.2f} %.",
        f"* The contact flag annotated on the true pose differs from the stored one in "
        f"{checks['contact_flag_changed']} examples; the exact limit surface solves converged in all but "
        f"{checks['exact_not_converged']} (largest residual {checks['exact_largest_residual']:.1e}).",
        f"* Wall time {results['wall_s']:.0f} s, of which {results['simulation_s']:.0f} s simulating.",
    ]


def write(results: Mapping, out_dir: str | Path) -> list[Path]:
    """``results.json`` (lists of numbers on one line each) and ``results.md`` in ``out_dir``; their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    text = json.dumps(outputs.compact(results), indent=1)
    text = re.sub(r"\[([^\[\]{}\"]*)\]", lambda match: "[" + " ".join(match.group(1).split()) + "]", text)
    paths = [out_dir / "results.json", out_dir / "results.md"]
    paths[0].write_text(text + "\n")
    paths[1].write_text(markdown(results))
    return paths
