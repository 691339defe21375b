"""Writing the loop's results: ``report.json`` (the issue's schema), ``details.json``, ``report.md`` and
figures of the residual against the candidate variables."""

from __future__ import annotations

import json
import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pushjax.loop import diagnose as diagnose_lib
from pushjax.loop.metrics import METRIC_KEYS
from pushjax.loop.windows import CATEGORICAL, VARIABLES, Examples

FIGURE_DIR = "figures"


def write_json(path: Path, value) -> None:
    path.write_text(json.dumps(value, indent=2, allow_nan=False) + "\n")


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
    figure, axes = plt.subplots(rows, max(columns, 1), figsize=(4 * max(columns, 1), 3 * rows), squeeze=False)
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
    plt.close(figure)


def strength_figure(path: Path, before: list, after: list) -> None:
    """Bar chart of each variable's strength before and after the fix."""
    names = [d.variable for d in before]
    after_by_name = {d.variable: d.strength for d in after}
    y = np.arange(len(names))
    figure, axis = plt.subplots(figsize=(7, 0.4 * len(names) + 1.2))
    axis.barh(y - 0.2, [d.strength for d in before], height=0.4, label="plain model")
    axis.barh(y + 0.2, [after_by_name[name] for name in names], height=0.4, label="after the fix")
    axis.set_yticks(y, names, fontsize=8)
    axis.invert_yaxis()
    axis.axvline(0.0, color="black", linewidth=0.5)
    axis.set_xlabel("share of the error a correction for the variable removes")
    axis.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=80)
    plt.close(figure)


def _metrics_row(label: str, summary: dict) -> str:
    low, high = (sum(bound) for bound in zip(summary["interval"]["trans_percent"], summary["interval"]["rot_percent"]))
    return (f"| {label} | {summary['trans_percent']:.1f} | {summary['rot_percent']:.1f} | {summary['trans_mm']:.3f} "
            f"| {summary['rot_deg']:.3f} | {summary['trans_percent'] + summary['rot_percent']:.1f} ({low:.1f}–{high:.1f}) |")


def _params_text(params: dict) -> str:
    def spread(std):
        return "?" if std is None else f"{std:.2g}"

    return ", ".join(f"{name} = {value['value']:.4g} ± {spread(value['std'])}" for name, value in params.items()) or "-"


def _uncertainty_row(label: str, scores: dict) -> str:
    return (f"| {label} | {scores['nlpd']:.2f} | {scores['coverage_68']:.1%} | {scores['coverage_95']:.1%} | "
            f"{scores['calibrated_coverage_68']:.1%} | {scores['calibrated_coverage_95']:.1%} |")


def markdown(report: dict, details: dict) -> str:
    """The readable report."""
    header = ("| model | translation % | rotation % | translation mm | rotation deg | sum % (95 % interval) |\n"
              "|---|---|---|---|---|---|")
    pushes, windows = report["n_pushes"], details["n_windows"]
    roles = ("cross-fitted over sequence folds (every pool push fits and selects, never both for one model)"
             if details["cross_fitted"] else "one fit split and one select split")
    lines = [
        "# Closing the loop: residual → effect → refit",
        "",
        f"Data: `{details['data_dir']}`, horizon {details['horizon']} s, seed {details['seed']}. "
        f"Pushes: {pushes['fit']} fit, {pushes['select']} select, {pushes['test']} test, {pushes['skipped']} files "
        f"skipped ({windows['fit']} fit, {windows['select']} select and {windows['test']} test windows); effects are "
        f"chosen {roles}, refitted on every push but the test split's, and measured on the test split only. "
        f"Nominal model: uniform-pressure limit surface, pusher friction {details['pusher_friction']}. Errors are "
        "test-split means; % is relative to the `zero` baseline (predicting no motion); intervals are bootstrap "
        "intervals over test push sequences.",
        "",
        "## Before and after (test split)",
        "",
        header,
        _metrics_row("plain Lynch model", report["baseline"]),
        _metrics_row("selected: " + (" + ".join(report["selected"]) or "nothing"), report["after"]),
        _metrics_row("selected + learned error term", report["fallback"]),
        "",
        "## How sure the model is (test split)",
        "",
        "Negative log predictive density per window (translation in mm, rotation in deg) and the share of the "
        "outputs (object axes x, y and rotation) inside the central 68 % and 95 % intervals. The physical model's "
        "noise level is fitted on its out-of-fold residual on the select split: "
        f"{report['uncertainty']['selected']['noise']['x_mm']:.2f} mm, "
        f"{report['uncertainty']['selected']['noise']['y_mm']:.2f} mm, "
        f"{report['uncertainty']['selected']['noise']['rotation_deg']:.2f} deg. Gaussian intervals assume that "
        "noise is normal; the calibrated intervals' half-widths are the quantiles of the out-of-fold standardised "
        "residuals on the select split (split conformal), so they hold their level on new pushes whatever the "
        "residual's shape.",
        "",
        "| model | NLPD | 68 % coverage | 95 % coverage | calibrated 68 % | calibrated 95 % |",
        "|---|---|---|---|---|---|",
        _uncertainty_row("selected model + fitted noise", report["uncertainty"]["selected"]),
        _uncertainty_row("learned error term (mean and variance)", report["uncertainty"]["fallback"]),
    ]
    lines += ["", "## Diagnosis of the plain model's residual", "",
              "Strength: share of the translation + rotation error that a cross-fitted correction by the "
              "variable's bins removes (see `pushjax.loop.diagnose`); lower: one-sided bootstrap bound.", "",
              "| variable | strength | lower | axes | beyond noise |", "|---|---|---|---|---|"]
    lines += [f"| {d['variable']} | {d['strength']:.3f} | {d['lower']:.3f} | {d['frame']} | {d['beyond_noise']} |"
              for d in details["diagnosis_before"]]
    lines += ["", f"![residual of the plain model]({FIGURE_DIR}/residual_baseline.png)", "",
              "## Effects ranked by select-split error (each fitted alone)", "",
              "| effect | parameters (± standard error) | sum % | translation mm | rotation deg |", "|---|---|---|---|---|"]
    lines += [f"| {entry['effect']} | {_params_text(entry['params'])} | "
              f"{entry['select']['trans_percent'] + entry['select']['rot_percent']:.1f} | {entry['select']['trans_mm']:.3f} | "
              f"{entry['select']['rot_deg']:.3f} |" for entry in report["ranking"]]
    friction, sensor = report["pusher_friction"], report["pusher_friction"]["force_sensor"]
    lines += ["", "## Pusher friction from the force sensor", "",
              (f"While the pusher slid along the object, the force sensor read a pusher–object friction coefficient of "
               f"{sensor['value']:.3f} ± {sensor['std'] or 0:.3f} ({sensor['n_sequences']} pool sequences, "
               f"{sensor['n_pushes_without']} pushes without sliding or force; nominal {friction['nominal']:g})"
               if sensor["value"] is not None else
               f"No pool push slid with a force reading ({sensor['n_pushes_without']} pushes)") + ". "
              + (f"Every model uses the measured {friction['used']:.3f}, and `pusher_friction` is not a candidate: "
                 "a measured parameter is no knob." if friction["from_force_sensor"] else
                 f"The models use the nominal {friction['used']:g}"
                 + (" (too few sequences slid for a measurement)." if not sensor["measured"] else "."))]
    select_floor = details["select_noise_floor"]
    lines += ["", "## Forward selection", "",
              f"Every candidate of a round is tested: its gain on the select split must be beyond noise (one-sided "
              f"sign-flip tests over select push sequences, Holm's procedure over the round's candidates at the "
              f"family-wise level {details['alpha']:g}) and remove more than {details['min_gain']:g} of the current "
              f"error above the select split's noise floor ({select_floor['trans_percent'] + select_floor['rot_percent']:.1f} "
              f"% from {select_floor['source']}); of those that pass, the largest gain is added.", ""]
    for k, round_ in enumerate(details["rounds"], 1):
        best = round_["accepted"] or max(round_["gains"], key=round_["gains"].get)
        lines.append(f"{k}. {'added' if round_['accepted'] else 'stop; largest gain'} `{best}`: gain "
                     f"{round_['gains'][best]:+.3f}, p = {round_['p_values'][best]:.2g} (Holm level "
                     f"{round_['levels'][best]:.2g}); candidates beyond noise: "
                     f"{', '.join(name for name, passed in round_['beyond_noise'].items() if passed) or 'none'}")
        for check in round_["mechanism"]:
            if check["p_value"] is None:
                verdict = "not testable here (one group, or too few sequences per group)"
            else:
                worst = check["tests"][0]
                verdict = (f"p = {worst['p_value']:.2g} for agreement of {worst['value']} across {worst['variable']}, "
                           f"between-group spread {worst['relative_spread']:.2f} of the effect's size: "
                           + ("**a knob, not a mechanism**" if check["knob"] else "a mechanism"))
            lines.append(f"   - mechanism check of `{check['effect']}`: {verdict}")
    if report["selected"]:
        lines += ["", "Fitted parameters of the selected model (every pool push):", ""]
        lines += [f"- {name}: {_params_text(params)}" for name, params in details["selected_params"].items()]
    if report["per_group"]:
        lines += ["", "Per object and surface (fitted on each group's pool pushes; shrunk: pulled towards the shared "
                  "value by as much as the group's own error allows; spread: the between-group standard deviation):",
                  "", "| variable | value | shared | spread | p (groups differ) | group: fitted → shrunk |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {entry['variable']} | {entry['effect']}.{entry['value']} | {entry['shared']['value']:.4g} ± "
                  f"{entry['shared']['std']:.2g} | {entry['spread']:.3g} | {entry['p_value']:.2g} | "
                  + "; ".join(f"{group}: {values['fitted']:.4g} → {values['shrunk']:.4g} ± {values['shrunk_std']:.2g}"
                              for group, values in entry["groups"].items()) + " |"
                  for entry in report["per_group"]]
    fallback = details["fallback_select"]
    lines += ["", "## Residual after the fix (select split, out of fold)", "",
              "| variable | strength | lower | beyond noise |", "|---|---|---|---|"]
    lines += [f"| {d['variable']} | {d['strength']:.3f} | {d['lower']:.3f} | {d['beyond_noise']} |"
              for d in details["diagnosis_after"]]
    lines += ["", f"![residual after the fix]({FIGURE_DIR}/residual_after.png)", "",
              f"![strengths]({FIGURE_DIR}/diagnosis.png)", "",
              f"Learned error term on the select split: gain {fallback['gain']:+.3f} over the selected model, "
              f"p = {fallback['p_value']:.2g}.", ""]
    floor, above = report["noise_floor"], report["remaining"]["above_floor"]
    lines.append(
        f"Noise floor of the test split (from {floor['source']}, {floor['n_windows']} windows): translation "
        f"{floor['trans_percent']:.1f} % ({floor['interval']['trans_percent'][0]:.1f}–{floor['interval']['trans_percent'][1]:.1f}),"
        f" rotation {floor['rot_percent']:.1f} % ({floor['interval']['rot_percent'][0]:.1f}–"
        f"{floor['interval']['rot_percent'][1]:.1f}).")
    lines.append("")
    if report["explained"]:
        lines.append("**Explained:** the selected model's test error is within the noise floor's interval.")
    else:
        remaining = ", ".join(f"**{entry['variable']}** (a correction for it removes {entry['strength']:.1%} of the "
                              "error)" for entry in report["remaining"]["variables"]) or "no single variable"
        lines.append(
            f"**Not explained:** the selected model's test error is {above['trans_percent']:.1f} (translation) and "
            f"{above['rot_percent']:.1f} (rotation) points of % above the noise floor; the learned error term "
            f"{'lowers' if fallback['beyond_noise'] else 'does not lower'} the error beyond noise, and the residual "
            f"still depends on {remaining}. Test-split sum with the learned term "
            f"{report['fallback']['trans_percent'] + report['fallback']['rot_percent']:.1f} % instead of "
            f"{report['after']['trans_percent'] + report['after']['rot_percent']:.1f} %.")
    return "\n".join(lines) + "\n"


def as_summary(summary: dict) -> dict:
    """The four error metrics as plain floats."""
    return {key: float(summary[key]) for key in METRIC_KEYS}
