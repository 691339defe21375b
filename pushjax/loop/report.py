"""The loop's results as types, and writing them: ``report.json`` (the issue's schema), ``details.json`` and
``report.md`` (its figures: :mod:`pushjax.loop.figures`)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from pushjax.loop import diagnose as diagnose_lib
from pushjax.loop import force as force_lib
from pushjax.loop import hierarchy
from pushjax.loop import shape as shape_lib
from pushjax.loop import metrics
from pushjax.loop import select as select_lib
from pushjax.loop import variability as variability_lib
from pushjax.physics import model_file

FIGURE_DIR = "figures"


@dataclasses.dataclass(frozen=True)
class Errors:
    """A model's mean errors on a set of windows.

    Attributes:
      trans_percent, rot_percent: translation and rotation error in % of the ``zero`` baseline's on the same windows.
      trans_mm, rot_deg: mean translation (mm) and rotation (deg) error per window.
    """

    trans_percent: float
    rot_percent: float
    trans_mm: float
    rot_deg: float

    @classmethod
    def from_summary(cls, summary: dict, **fields):
        """From :func:`pushjax.loop.metrics.summarize`'s dict (values as plain floats) and a subclass's ``fields``."""
        return cls(**{key: float(summary[key]) for key in metrics.METRIC_KEYS}, **fields)

    @property
    def combined(self) -> float:
        return self.trans_percent + self.rot_percent


@dataclasses.dataclass(frozen=True)
class HeldOutErrors(Errors):
    """A model's mean errors on the test split and their uncertainty.

    Attributes:
      interval: {metric: [low, high]} 95 % bootstrap interval over test push sequences, per :class:`Errors` field.
    """

    interval: dict[str, list[float]]


@dataclasses.dataclass(frozen=True)
class RankedEffect:
    """One library effect fitted alone, as ranked on the select split.

    Attributes:
      effect: the effect's name.
      params: {value name: {"value": float, "std": float or None}} its fitted physical values (first fold).
      select: its out-of-fold errors on the selection windows.
    """

    effect: str
    params: dict[str, dict[str, float | None]]
    select: Errors


@dataclasses.dataclass(frozen=True)
class PusherFriction:
    """The pusher–object friction coefficient the models used.

    Attributes:
      nominal: the coefficient of the settings.
      force_sensor: what the force sensor read on the pool's sliding pushes.
      from_force_sensor: whether the models use the measured coefficient instead of the nominal one.
      used: the coefficient the models use.
    """

    nominal: float
    force_sensor: force_lib.ForceFriction
    from_force_sensor: bool
    used: float


@dataclasses.dataclass(frozen=True)
class Uncertainty:
    """Scores of the predictive distributions on the test split (see :func:`pushjax.loop.metrics.predictive_scores`).

    Attributes:
      selected: scores of the selected model with its fitted noise and each window's motion spread over the pushes'
        parameters (:func:`pushjax.loop.variability.window_spread`) in quadrature.
      noise: [3] that noise: standard deviation along the object's axes and of the rotation (m, m, rad).
      fallback: scores of the learned error term's mean and variance.
    """

    selected: dict[str, float]
    noise: np.ndarray
    fallback: dict[str, float]


@dataclasses.dataclass(frozen=True)
class LoopReport:
    """What the loop found (``report.json``).

    Attributes:
      n_pushes: {"fit", "select", "test", "skipped"} pushes per role (fit: of the first fold) and push files skipped.
      baseline: the plain Lynch model's test errors.
      diagnosis: the plain model's residual on the pool against each variable, strongest first.
      ranking: the single-effect models, best selection score first.
      selected: the selected effects in the order they were selected.
      alternatives: {selected effect: {rival: p-value}} the effects the select split cannot tell a selected one from
        (they passed the same tests with a smaller gain that the selected one's does not exceed beyond noise); a
        rival explains the data as well, so the selected effect's physics is not decided between them.
      after: the selected model's test errors.
      noise_floor: the test split's noise floor: tracking noise and the motion's spread over the pushes' parameters
        (or the spread of repeated pushes).
      variability: {parameter: its spread over the pool's pushes} (:mod:`pushjax.loop.variability`).
      pusher_friction: the pusher–object friction coefficient the models used.
      fallback: the selected model's plus the learned error term's test errors.
      remaining: the variables the selected model's residual still depends on beyond noise (select split).
      uncertainty: how sure the selected model and the learned error term are.
      per_group: the selected model's values per object and per surface, shrunk to a shared value (empty when
        nothing is selected or the pool has one object and one surface).
      limit_surface_shape: the limit surface's torque-to-force ratio per twist regime from the pool's force-motion
        pairs, beside Lynch's ellipsoid's, the exact uniform surface's and the selected model's.
    """

    n_pushes: dict[str, int]
    baseline: HeldOutErrors
    diagnosis: list[diagnose_lib.Dependence]
    ranking: list[RankedEffect]
    selected: list[str]
    alternatives: dict[str, dict[str, float]]
    after: HeldOutErrors
    noise_floor: metrics.NoiseFloor
    variability: dict[str, variability_lib.Variability]
    pusher_friction: PusherFriction
    fallback: HeldOutErrors
    remaining: list[diagnose_lib.Dependence]
    uncertainty: Uncertainty
    per_group: list[hierarchy.GroupValues]
    limit_surface_shape: shape_lib.LimitSurfaceShape

    @property
    def above_floor(self) -> dict[str, float]:
        """{"trans_percent", "rot_percent"}: the selected model's test error above the noise floor, points of %."""
        return {key: getattr(self.after, key) - getattr(self.noise_floor, key) for key in ("trans_percent", "rot_percent")}

    @property
    def explained(self) -> bool:
        """Whether the selected model's test error is within the noise floor's interval (tracking noise and the
        pushes' parameter spread)."""
        return all(getattr(self.after, key) <= self.noise_floor.interval[key][1] for key in self.above_floor)

    @property
    def variability_share(self) -> float:
        """The share of the selected model's test error above the tracking noise that the pushes' parameter spread
        accounts for (at most 1; 0 where the error is not above the tracking noise)."""
        spread = sum(self.noise_floor.from_variability.values())
        above_tracking = self.after.combined - (self.noise_floor.score - spread)
        return float(min(1.0, spread / above_tracking)) if above_tracking > 0 else 0.0

    def as_dict(self) -> dict:
        """The content of ``report.json``."""
        return {
            "n_pushes": self.n_pushes,
            "baseline": dataclasses.asdict(self.baseline),
            "diagnosis": _strengths(self.diagnosis),
            "ranking": [dataclasses.asdict(entry) for entry in self.ranking],
            "selected": self.selected,
            "alternatives": self.alternatives,
            "after": dataclasses.asdict(self.after),
            "noise_floor": self.noise_floor.as_dict(),
            "variability": {name: values.as_dict() for name, values in self.variability.items()},
            "pusher_friction": {**dataclasses.asdict(self.pusher_friction),
                                "force_sensor": self.pusher_friction.force_sensor.as_dict()},
            "explained": self.explained,
            "per_group": [dataclasses.asdict(values) for values in self.per_group],
            "limit_surface_shape": {
                **dataclasses.asdict(self.limit_surface_shape),
                "regimes": [[low, high if math.isfinite(high) else None]
                            for low, high in self.limit_surface_shape.regimes]},
            "fallback": dataclasses.asdict(self.fallback),
            "remaining": {"above_floor": self.above_floor, "variability_share": self.variability_share,
                          "variables": _strengths(self.remaining)},
            "uncertainty": {
                "selected": {**self.uncertainty.selected,
                             "noise": {"x_mm": 1e3 * float(self.uncertainty.noise[0]),
                                       "y_mm": 1e3 * float(self.uncertainty.noise[1]),
                                       "rotation_deg": float(np.degrees(self.uncertainty.noise[2]))}},
                "fallback": self.uncertainty.fallback,
            },
        }


@dataclasses.dataclass(frozen=True)
class LoopDetails:
    """How the loop decided (``details.json``).

    Attributes:
      data_dir: root of the pushes.
      horizon: prediction window, s.
      seed: seed of the split, the tests, the cross-fitting folds and the error terms.
      pusher_friction: nominal pusher–object friction coefficient.
      alpha: family-wise error level of the decisions.
      min_gain: share of the error above the noise floor that a selected effect had to remove.
      cross_fitted: whether effects were chosen cross-fitted over sequence folds (else one fit and one select split).
      n_sequences: {"pool", "test"} push sequences per split.
      n_windows: {"fit", "select", "test"} windows per role (fit: of the first fold).
      skipped: {reason: [push file names]} of the push files that gave no window.
      diagnosis_before: the plain model's residual on the pool against the variables.
      diagnosis_after: the selected model's out-of-fold residual on the selection windows.
      select_noise_floor: the noise floor of the selection windows.
      rounds: the forward-selection rounds.
      fallback_gain: relative selection-error cut of the learned error term over the selected model.
      fallback_p_value: its one-sided sign-flip p-value.
      fallback_beyond_noise: whether the learned error term lowers the selection error beyond noise.
      selected_params: {effect: {value name: {"value", "std"}}} of the selected model refitted on the pool.
    """

    data_dir: str
    horizon: float
    seed: int
    pusher_friction: float
    alpha: float
    min_gain: float
    cross_fitted: bool
    n_sequences: dict[str, int]
    n_windows: dict[str, int]
    skipped: dict[str, list[str]]
    diagnosis_before: list[diagnose_lib.Dependence]
    diagnosis_after: list[diagnose_lib.Dependence]
    select_noise_floor: metrics.NoiseFloor
    rounds: list[select_lib.Round]
    fallback_gain: float
    fallback_p_value: float
    fallback_beyond_noise: bool
    selected_params: dict[str, dict[str, dict[str, float | None]]]

    def as_dict(self) -> dict:
        """The content of ``details.json``."""
        return {
            "data_dir": self.data_dir,
            "horizon": self.horizon,
            "seed": self.seed,
            "pusher_friction": self.pusher_friction,
            "alpha": self.alpha,
            "min_gain": self.min_gain,
            "cross_fitted": self.cross_fitted,
            "n_sequences": self.n_sequences,
            "n_windows": self.n_windows,
            "skipped": self.skipped,
            "diagnosis_before": [dataclasses.asdict(d) for d in self.diagnosis_before],
            "diagnosis_after": [dataclasses.asdict(d) for d in self.diagnosis_after],
            "select_noise_floor": self.select_noise_floor.as_dict(),
            "rounds": [{"gains": dict(zip(r.additions, r.gains)), "p_values": dict(zip(r.additions, r.p_values)),
                        "levels": dict(zip(r.additions, r.levels)),
                        "beyond_noise": dict(zip(r.additions, r.beyond_noise)), "floor": r.floor,
                        "mechanism": [{**dataclasses.asdict(check), "p_value": check.p_value,
                                       "variable": check.variable, "knob": check.is_knob(self.alpha)}
                                      for check in r.mechanism],
                        "incumbent_change": r.incumbent_change, "continuations": r.continuations,
                        "converged": r.converged,
                        "accepted": r.accepted, "indistinguishable": r.indistinguishable} for r in self.rounds],
            "fallback_select": {"gain": self.fallback_gain, "p_value": self.fallback_p_value,
                                "beyond_noise": self.fallback_beyond_noise},
            "selected_params": self.selected_params,
        }


@dataclasses.dataclass(frozen=True)
class LoopResult:
    """What :func:`pushjax.loop.pipeline.close_loop` found and how it decided, and the selected model refitted on
    the pool with the pusher friction the loop used (``model.json``, :mod:`pushjax.physics.model_file`)."""

    report: LoopReport
    details: LoopDetails
    model: model_file.AugmentedModel


def _strengths(dependences: list[diagnose_lib.Dependence]) -> list[dict]:
    return [{"variable": d.variable, "strength": d.strength} for d in dependences]


def write(workdir: Path, result: LoopResult) -> None:
    """Writes ``report.json``, ``details.json``, ``model.json`` and ``report.md`` to ``workdir`` (which exists)."""
    write_json(workdir / "report.json", result.report.as_dict())
    write_json(workdir / "details.json", result.details.as_dict())
    model_file.write(workdir / "model.json", result.model)
    (workdir / "report.md").write_text(markdown(result))


def write_json(path: Path, value) -> None:
    path.write_text(json.dumps(value, indent=2, allow_nan=False) + "\n")


def _metrics_row(label: str, errors: HeldOutErrors) -> str:
    low, high = (sum(bound) for bound in zip(errors.interval["trans_percent"], errors.interval["rot_percent"]))
    return (f"| {label} | {errors.trans_percent:.1f} | {errors.rot_percent:.1f} | {errors.trans_mm:.3f} "
            f"| {errors.rot_deg:.3f} | {errors.combined:.1f} ({low:.1f}–{high:.1f}) |")


def _params_text(params: dict) -> str:
    def spread(std):
        return "?" if std is None else f"{std:.2g}"

    return ", ".join(f"{name} = {value['value']:.4g} ± {spread(value['std'])}" for name, value in params.items()) or "-"


def _shape_lines(shape: shape_lib.LimitSurfaceShape, fitted: dict | None) -> list[str]:
    """The force sensor's torque-to-force ratio per twist regime beside the models' (report.md), and the pressure's
    rim loading from the force data beside the motion fit's (``fitted``: the selected ``limit_surface`` values)."""
    if not any(shape.measured):
        return ["", "Limit surface from the force sensor: too few windows with force and motion to measure its shape."]
    names = list(shape.models)
    lines = ["", "Limit surface from the force sensor (pool pushes): the torque-to-force ratio `c_eff / l` of the "
             "wrench the pusher applied and the twist the object made (`|m| |v| / (|ω| |F|)`, ratio of sums per "
             "regime, sequence-bootstrap standard error), beside the models' at the same twists. Lynch's ellipsoid "
             "is 1 everywhere; a surface of the right shape follows the sensor in every regime.", "",
             "| rotation against translation, ω l / v | measured | windows | " + " | ".join(names) + " |",
             "|---|---|---|" + "---|" * len(names)]
    for (low, high), measured, index in zip(shape.regimes, shape.measured, range(len(shape.regimes))):
        if measured is None:
            continue
        regime = f"{low:g}–{high:g}" if math.isfinite(high) else f"≥ {low:g}"
        lines.append(f"| {regime} | {measured['c_over_l']:.3f} ± {measured['std']:.3f} | {measured['n_windows']} | "
                     + " | ".join(f"{shape.models[name][index]:.3f}" for name in names) + " |")
    rim = shape.rim_from_force
    if rim is not None:
        lines += ["", f"Pressure rim loading (`limit_surface.rim`) from the force data alone: {rim['value']:.3g} ± "
                  f"{rim['std']:.2g}."]
        motion = (fitted or {}).get("rim")
        if motion is not None and motion["std"]:
            lines[-1] += f" From the motion fit: {motion['value']:.3g} ± {motion['std']:.2g}; " + _combined_rim(
                motion, rim)
    return lines


def _combined_rim(motion: dict, force: dict, alpha: float = 0.05) -> str:
    """The motion fit's and the force data's rim together, or why they are not combined: two measurements of one
    pressure must agree before an inverse-variance mean of them means anything."""
    z = (motion["value"] - force["value"]) / math.hypot(motion["std"], force["std"])
    p_value = math.erfc(abs(z) / math.sqrt(2))
    if p_value <= alpha:
        return (f"the two disagree (z = {z:.2g}, p = {p_value:.2g}), so the motion fit's rim absorbs something the "
                "force sensor does not see, and they are not combined.")
    weights = np.array([1 / motion["std"] ** 2, 1 / force["std"] ** 2])
    value = float(np.dot(weights, [motion["value"], force["value"]]) / weights.sum())
    std = float(1 / np.sqrt(weights.sum()))
    return (f"they agree (z = {z:.2g}); both together: {value:.3g} ± {std:.2g}, an interval {motion['std'] / std:.2g} "
            "times narrower than the motion's alone.")


def _variability_lines(variability: dict[str, variability_lib.Variability]) -> list[str]:
    """A table of the parameters' spread over the pushes, or nothing."""
    if not variability:
        return []
    lines = ["", "## Push-to-push variability", "",
             "Parameters read on each pool push, pooled with the pushes as random-effects groups: the spread between "
             "pushes (relative standard deviation, 95 % Q-profile interval) apart from the readings' measurement noise. "
             "The selected model's intervals widen by it and the noise floor holds it.", "",
             "| parameter | mean | relative sd (95 % interval) | measurement noise (relative) | pushes | source |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {name} | {values.mean:.4g} ± {values.mean_std:.2g} | {values.relative_sd:.3f} ({values.interval[0]:.3f}–"
              f"{values.interval[1]:.3f}) | {values.measurement_relative_sd:.3f} | {values.n_pushes} | {values.source} |"
              for name, values in variability.items()]
    return lines


def _alternatives_lines(alternatives: dict[str, dict[str, float]]) -> list[str]:
    """A paragraph naming the selected effects the data cannot tell from others, or nothing."""
    if not alternatives:
        return []
    pairs = "; ".join(f"`{name}` from " + ", ".join(f"`{rival}` (p = {p:.2g})" for rival, p in rivals.items())
                      for name, rivals in alternatives.items())
    return [f"**Not decided by this data**: {pairs} (one-sided sign-flip p-value that the selected effect's gain "
            "exceeds the other's). Each explains the select split about as well, so the physics behind the selected "
            "effect is one of them. Pushes that vary what tells them apart separate them: a table-fixed effect "
            "(`friction_field`, `table_tilt`) from an object-fixed one (`cof_offset`, `pressure_gradient`, "
            "`limit_surface`) by start poses spread over the table (`python -m experiments.record_pushes "
            "--start_poses=scattered` on the testbed), the others by more objects, surfaces or speeds.", ""]


def _uncertainty_row(label: str, scores: dict) -> str:
    return (f"| {label} | {scores['nlpd']:.2f} | {scores['coverage_68']:.1%} | {scores['coverage_95']:.1%} | "
            f"{scores['calibrated_coverage_68']:.1%} | {scores['calibrated_coverage_95']:.1%} |")


def markdown(result: LoopResult) -> str:
    """The readable report."""
    report, details = result.report, result.details
    lines = (_summary_lines(report, details) + _diagnosis_lines(details) + _ranking_lines(report)
             + _pusher_friction_lines(report) + _variability_lines(report.variability)
             + _selection_lines(details) + _selected_model_lines(report, details) + _after_lines(report, details))
    return "\n".join(lines) + "\n"


def _summary_lines(report: LoopReport, details: LoopDetails) -> list[str]:
    """The data, the errors before and after on the test split and how sure the model is."""
    header = ("| model | translation % | rotation % | translation mm | rotation deg | sum % (95 % interval) |\n"
              "|---|---|---|---|---|---|")
    pushes, windows = report.n_pushes, details.n_windows
    roles = ("cross-fitted over sequence folds (every pool push fits and selects, never both for one model)"
             if details.cross_fitted else "one fit split and one select split")
    noise = report.uncertainty.noise
    return [
        "# Closing the loop: residual → effect → refit",
        "",
        f"Data: `{details.data_dir}`, horizon {details.horizon} s, seed {details.seed}. "
        f"Pushes: {pushes['fit']} fit, {pushes['select']} select, {pushes['test']} test, {pushes['skipped']} files "
        f"skipped ({windows['fit']} fit, {windows['select']} select and {windows['test']} test windows); effects are "
        f"chosen {roles}, refitted on every push but the test split's, and measured on the test split only. "
        f"Nominal model: uniform-pressure limit surface, pusher friction {details.pusher_friction}. Errors are "
        "test-split means; % is relative to the `zero` baseline (predicting no motion); intervals are bootstrap "
        "intervals over test push sequences.",
        "",
        "## Before and after (test split)",
        "",
        header,
        _metrics_row("plain Lynch model", report.baseline),
        _metrics_row("selected: " + (" + ".join(report.selected) or "nothing"), report.after),
        _metrics_row("selected + learned error term", report.fallback),
        "",
        *_alternatives_lines(report.alternatives),
        "## How sure the model is (test split)",
        "",
        "Negative log predictive density per window (translation in mm, rotation in deg) and the share of the "
        "outputs (object axes x, y and rotation) inside the central 68 % and 95 % intervals. The physical model's "
        "noise level is fitted on its out-of-fold residual on the select split: "
        f"{1e3 * float(noise[0]):.2f} mm, {1e3 * float(noise[1]):.2f} mm, {float(np.degrees(noise[2])):.2f} deg. "
        "Gaussian intervals assume that noise is normal; the calibrated intervals' half-widths are the quantiles of "
        "the out-of-fold standardised residuals on the select split (split conformal), so they hold their level on "
        "new pushes whatever the residual's shape.",
        "",
        "| model | NLPD | 68 % coverage | 95 % coverage | calibrated 68 % | calibrated 95 % |",
        "|---|---|---|---|---|---|",
        _uncertainty_row("selected model + fitted noise", report.uncertainty.selected),
        _uncertainty_row("learned error term (mean and variance)", report.uncertainty.fallback),
    ]


def _diagnosis_lines(details: LoopDetails) -> list[str]:
    lines = ["", "## Diagnosis of the plain model's residual", "",
             "Strength: share of the translation + rotation error that a cross-fitted correction by the "
             "variable's bins removes (see `pushjax.loop.diagnose`); lower: one-sided bootstrap bound.", "",
             "| variable | strength | lower | axes | beyond noise |", "|---|---|---|---|---|"]
    lines += [f"| {d.variable} | {d.strength:.3f} | {d.lower:.3f} | {d.frame} | {d.beyond_noise} |"
              for d in details.diagnosis_before]
    return lines + ["", f"![residual of the plain model]({FIGURE_DIR}/residual_baseline.png)"]


def _ranking_lines(report: LoopReport) -> list[str]:
    lines = ["", "## Effects ranked by select-split error (each fitted alone)", "",
             "| effect | parameters (± standard error) | sum % | translation mm | rotation deg |", "|---|---|---|---|---|"]
    return lines + [f"| {entry.effect} | {_params_text(entry.params)} | {entry.select.combined:.1f} | "
                    f"{entry.select.trans_mm:.3f} | {entry.select.rot_deg:.3f} |" for entry in report.ranking]


def _pusher_friction_lines(report: LoopReport) -> list[str]:
    friction, sensor = report.pusher_friction, report.pusher_friction.force_sensor
    return ["", "## Pusher friction from the force sensor", "",
            (f"While the pusher slid along the object, the force sensor read a pusher–object friction coefficient of "
             f"{sensor.value:.3f} ± {sensor.std or 0:.3f} ({sensor.n_sequences} pool sequences, "
             f"{sensor.n_pushes_without} pushes without sliding or force; nominal {friction.nominal:g})"
             if sensor.value is not None else
             f"No pool push slid with a force reading ({sensor.n_pushes_without} pushes)") + ". "
            + (f"Every model uses the measured {friction.used:.3f}, and `pusher_friction` is not a candidate: "
               "a measured parameter is no knob." if friction.from_force_sensor else
               f"The models use the nominal {friction.used:g}"
               + (" (too few sequences slid for a measurement)." if not sensor.measured else "."))]


def _selection_lines(details: LoopDetails) -> list[str]:
    """Forward selection round by round: the gains, the tests, the fits' convergence and the mechanism checks."""
    select_floor = details.select_noise_floor
    lines = ["", "## Forward selection", "",
             f"Every candidate of a round is tested: its gain on the select split must be beyond noise (one-sided "
             f"sign-flip tests over select push sequences, Holm's procedure over the round's candidates at the "
             f"family-wise level {details.alpha:g}) and remove more than {details.min_gain:g} of the current "
             f"error above the select split's noise floor ({select_floor.score:.1f} % from {select_floor.source}); of "
             f"those that pass, the largest gain is added.", ""]
    for k, round_ in enumerate(details.rounds, 1):
        gains = dict(zip(round_.additions, round_.gains))
        best = round_.accepted or max(gains, key=gains.get)
        index = round_.additions.index(best)
        passed = [name for name, beyond in zip(round_.additions, round_.beyond_noise) if beyond]
        lines.append(f"{k}. {'added' if round_.accepted else 'stop; largest gain'} `{best}`: gain "
                     f"{round_.gains[index]:+.3f}, p = {round_.p_values[index]:.2g} (Holm level "
                     f"{round_.levels[index]:.2g}); candidates beyond noise: {', '.join(passed) or 'none'}")
        if k > 1:
            lines.append(f"   - the current model fitted as far as the candidates (the gains' reference): selection "
                         f"score {-100 * round_.incumbent_change:+.2f} %"
                         + (f" in the last of {round_.continuations + 1} continuations of every fit"
                            if round_.continuations else "")
                         + ("" if round_.converged else
                            f", more than {100 * select_lib.CONVERGENCE_TOLERANCE:g} %: **its fits had not converged**, "
                            "so nothing is added (rerun with more `--steps`)"))
        lines += [f"   - mechanism check of `{check.effect}`: {_mechanism_verdict(check, details.alpha)}"
                  for check in round_.mechanism]
        if round_.indistinguishable:
            lines.append("   - indistinguishable on the select split: " + ", ".join(
                f"`{name}` (p = {p:.2g})" for name, p in round_.indistinguishable.items()))
    return lines


def _mechanism_verdict(check: select_lib.MechanismCheck, alpha: float) -> str:
    if check.p_value is None:
        return "not testable here (one group, or too few sequences per group)"
    worst = check.tests[0]
    return (f"p = {worst.p_value:.2g} for agreement of {worst.value} across {worst.variable}, "
            f"between-group spread {worst.relative_spread:.2f} of the effect's size: "
            + ("**a knob, not a mechanism**" if check.is_knob(alpha) else "a mechanism"))


def _selected_model_lines(report: LoopReport, details: LoopDetails) -> list[str]:
    """The selected model's parameters, the limit surface's shape and the values per object and surface."""
    lines = []
    if report.selected:
        lines += ["", "Fitted parameters of the selected model (every pool push):", ""]
        lines += [f"- {name}: {_params_text(params)}" for name, params in details.selected_params.items()]
    lines += _shape_lines(report.limit_surface_shape, details.selected_params.get("limit_surface"))
    if report.per_group:
        lines += ["", "Per object and surface (fitted on each group's pool pushes; shrunk: pulled towards the shared "
                  "value by as much as the group's own error allows; spread: the between-group standard deviation):",
                  "", "| variable | value | shared | spread | p (groups differ) | group: fitted → shrunk |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {entry.variable} | {entry.effect}.{entry.value} | {entry.shared['value']:.4g} ± "
                  f"{entry.shared['std']:.2g} | {entry.spread:.3g} | {entry.p_value:.2g} | "
                  + "; ".join(f"{group}: {values['fitted']:.4g} → {values['shrunk']:.4g} ± {values['shrunk_std']:.2g}"
                              for group, values in entry.groups.items()) + " |"
                  for entry in report.per_group]
    return lines


def _after_lines(report: LoopReport, details: LoopDetails) -> list[str]:
    """The residual after the fix, the learned error term, the noise floor and the verdict."""
    lines = ["", "## Residual after the fix (select split, out of fold)", "",
             "| variable | strength | lower | beyond noise |", "|---|---|---|---|"]
    lines += [f"| {d.variable} | {d.strength:.3f} | {d.lower:.3f} | {d.beyond_noise} |"
              for d in details.diagnosis_after]
    lines += ["", f"![residual after the fix]({FIGURE_DIR}/residual_after.png)", "",
              f"![strengths]({FIGURE_DIR}/diagnosis.png)", "",
              f"Learned error term on the select split: gain {details.fallback_gain:+.3f} over the selected model, "
              f"p = {details.fallback_p_value:.2g}.", ""]
    floor, above = report.noise_floor, report.above_floor
    lines.append(
        f"Noise floor of the test split (from {floor.source}, {floor.n_windows} windows): translation "
        f"{floor.trans_percent:.1f} % ({floor.interval['trans_percent'][0]:.1f}–{floor.interval['trans_percent'][1]:.1f}),"
        f" rotation {floor.rot_percent:.1f} % ({floor.interval['rot_percent'][0]:.1f}–"
        f"{floor.interval['rot_percent'][1]:.1f}).")
    if report.variability:
        lines[-1] += (f" The push-to-push variability adds {floor.from_variability['trans_percent']:.1f} and "
                      f"{floor.from_variability['rot_percent']:.1f} points of it to the tracking noise: "
                      f"{report.variability_share:.0%} of the selected model's error above the tracking noise.")
    lines.append("")
    if report.explained:
        lines.append("**Explained:** the selected model's test error is within the noise floor's interval.")
    else:
        remaining = ", ".join(f"**{d.variable}** (a correction for it removes {d.strength:.1%} of the error)"
                              for d in report.remaining) or "no single variable"
        lines.append(
            f"**Not explained:** the selected model's test error is {above['trans_percent']:.1f} (translation) and "
            f"{above['rot_percent']:.1f} (rotation) points of % above the noise floor; the learned error term "
            f"{'lowers' if details.fallback_beyond_noise else 'does not lower'} the error beyond noise, and the "
            f"residual still depends on {remaining}. Test-split sum with the learned term "
            f"{report.fallback.combined:.1f} % instead of {report.after.combined:.1f} %.")
    return lines
