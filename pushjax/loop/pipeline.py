"""The whole loop on a directory of pushes: examples → split → diagnosis → effects → fallback → report.

:func:`decide` makes every decision (which effects, whether anything remains) from the fit and select
sequences only; :func:`close_loop` then refits on the pool, measures on the untouched test split and writes
the report.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import tqdm

from pushjax.loop import correction as correction_lib
from pushjax.loop import diagnose as diagnose_lib
from pushjax.loop import force as force_lib
from pushjax.loop import figures as figures_lib
from pushjax.loop import fit as fit_lib
from pushjax.loop import hierarchy as hierarchy_lib
from pushjax.loop import metrics
from pushjax.loop import report as report_lib
from pushjax.loop import select as select_lib
from pushjax.loop import shape as shape_lib
from pushjax.loop import splits as splits_lib
from pushjax.loop import variability as variability_lib
from pushjax.loop.windows import NOMINAL_PUSHER_FRICTION, Examples, build_examples
from pushjax.mit.files import iter_pushes
from pushjax.physics import model_file
from pushjax.physics.effects import EFFECT_NAMES


@dataclasses.dataclass(frozen=True)
class LoopConfig:
    """Settings of :func:`close_loop`.

    Attributes:
      horizon: prediction window, s.
      stride: time between window starts, s (default ``horizon / 2``).
      test_fraction: share of push sequences in the untouched test split.
      select_fraction: share of push sequences in the select split (when not cross-fitted).
      pusher_friction: nominal pusher-object friction coefficient, used where the force sensor does not measure it.
      measure_pusher_friction: give the model the pusher-object friction that the force sensor measured on the pool's
        sliding pushes (:mod:`pushjax.loop.force`) and drop ``pusher_friction`` from the candidates, where enough
        sequences slid.
      effects: candidate library effects.
      min_gain: share of the current selection error above the noise floor that an effect must remove to be
        selected (on top of being beyond noise).
      min_strength: share of the error a variable's correction must remove to count as structure.
      alpha: family-wise error level of the selection, fallback and diagnosis decisions.
      n_bootstrap: bootstrap resamplings of push sequences.
      fit: optimiser settings of the effect fits.
      correction: training settings of the fallback error term.
    """

    horizon: float = 0.5
    stride: float | None = None
    test_fraction: float = splits_lib.TEST_FRACTION
    select_fraction: float = splits_lib.SELECT_FRACTION
    pusher_friction: float = NOMINAL_PUSHER_FRICTION
    measure_pusher_friction: bool = True
    effects: tuple[str, ...] = EFFECT_NAMES
    min_gain: float = select_lib.MIN_GAIN
    min_strength: float = diagnose_lib.MIN_STRENGTH
    alpha: float = 0.05
    n_bootstrap: int = 1000
    fit: fit_lib.FitConfig = fit_lib.FitConfig()
    correction: correction_lib.CorrectionConfig = correction_lib.CorrectionConfig()

    def __post_init__(self):
        """Raises ValueError naming the first field outside its range."""
        checks = [
            ("horizon", 0 < self.horizon < math.inf, "a positive duration in s"),
            ("stride", self.stride is None or 0 < self.stride < math.inf, "a positive duration in s or None"),
            ("select_fraction", 0 < self.select_fraction < 1, "a fraction in (0, 1)"),
            ("test_fraction", 0 < self.test_fraction < 1 - self.select_fraction,
             f"a fraction in (0, {1 - self.select_fraction:g})"),
            ("pusher_friction", 0 <= self.pusher_friction < math.inf, "a friction coefficient >= 0"),
            ("effects", bool(self.effects) and set(self.effects) <= set(EFFECT_NAMES),
             f"library effects from {','.join(EFFECT_NAMES)}"),
            ("min_gain", 0 <= self.min_gain < 1, "a share of the error above the noise floor in [0, 1)"),
            ("min_strength", 0 <= self.min_strength <= 1, "a share of the error in [0, 1]"),
            ("alpha", 0 < self.alpha < 1, "a level in (0, 1)"),
            ("n_bootstrap", self.n_bootstrap >= 1, "at least 1 resampling"),
            ("fit", self.fit.steps >= 1 and self.fit.warm_steps >= 1, "at least 1 Adam step (steps, warm_steps)"),
        ]
        for field, valid, expected in checks:
            if not valid:
                raise ValueError(f"{field}: expected {expected}, got {getattr(self, field)!r}")


@dataclasses.dataclass(frozen=True)
class Decision:
    """What the fit and select sequences decided (see :func:`decide`).

    Attributes:
      split: the roles of the sequences (with the measured pusher friction in their inputs where it is used).
      force: the pusher–object friction that the force sensor read on the pool's sliding pushes.
      selection: ranking, rounds and the selected model.
      fallback_gain: relative selection-error cut of the learned error term over the selected model.
      fallback_p_value: its one-sided sign-flip p-value.
      variables: the candidate variables (those that vary).
      diagnosis_before: the plain model's residual on the pool against the variables.
      diagnosis_after: the selected model's out-of-fold residual on the selection windows.
      noise: [3] standard deviation of that residual along the object's axes and of the rotation (m, m, rad).
      variability: {parameter: its spread over the pool's pushes} (:func:`pushjax.loop.variability.measure`).
      selected_multipliers, fallback_multipliers: [L, 3] split-conformal half-widths of the
        :data:`pushjax.loop.metrics.COVERAGE_LEVELS` intervals (:func:`pushjax.loop.metrics.interval_multipliers`), in
        units of the selected model's predictive standard deviation (``noise`` and each window's motion spread over the
        pushes' parameters in quadrature, :func:`pushjax.loop.variability.window_spread`) and of the error term's own
        standard deviation for the fallback, from their out-of-fold residuals on the selection windows.
      alpha: the level of the fallback's test.
      error_term: the learned error term trained on the whole pool on the selected model's predictions (the fallback
        :func:`measure` reports on the test split), trained beside the folds' own.
    """

    split: splits_lib.Split
    force: force_lib.ForceFriction
    selection: select_lib.Selection
    fallback_gain: float
    fallback_p_value: float
    variables: list[str]
    diagnosis_before: list[diagnose_lib.Dependence]
    diagnosis_after: list[diagnose_lib.Dependence]
    noise: np.ndarray
    variability: dict[str, variability_lib.Variability]
    selected_multipliers: np.ndarray
    fallback_multipliers: np.ndarray
    alpha: float
    error_term: correction_lib.ErrorCorrection

    @property
    def fallback_helps(self) -> bool:
        """Whether the learned error term lowers the selection error beyond noise."""
        return self.fallback_p_value <= self.alpha and self.fallback_gain > 0

    @property
    def remaining(self) -> list[diagnose_lib.Dependence]:
        """The variables the selected model's residual still depends on beyond noise."""
        return [d for d in self.diagnosis_after if d.beyond_noise]


def decide(examples: Examples, settings: LoopConfig = LoopConfig(), seed: int = 0,
           progress: Callable[[str], None] | None = None) -> Decision:
    """Splits the windows, selects effects and tests the fallback and the diagnosis, all without the test split.

    Args:
      examples: the windows of every push.
      settings: the loop's settings.
      seed: seed of the split, the tests, the cross-fitting folds and the error terms.
      progress: called with a short message before each stage.

    Raises:
      ValueError: too few push sequences (see :func:`pushjax.loop.splits.split`).
    """
    report = progress or (lambda message: None)
    split, force, effects = measured_split(examples, settings, seed)
    diagnose = dict(min_strength=settings.min_strength, n_bootstrap=settings.n_bootstrap, alpha=settings.alpha,
                    seed=seed)
    variables = [name for name, values in split.pool.variables.items() if len(np.unique(values)) > 1]
    report("diagnosing the plain model")
    before = diagnose_lib.diagnose(split.pool, fit_lib.predict([None], split.pool)[0], variables, **diagnose)
    selection = select_lib.select_effects(split, effects, settings.fit, settings.min_gain, settings.alpha,
                                          seed, report)
    final = selection.final
    report("fitting the learned error term on each fold and on the pool")

    def error_term(k: int):
        """Fold k's out-of-fold (mean, std) on its select windows; for k = the number of folds, the pool's term."""
        if k == len(split.folds):
            model = selection.model
            return correction_lib.fit_error_correction(split.pool, fit_lib.predict([model], split.pool)[0],
                                                       settings.correction, seed)
        fit, select = (split.pool.select(index) for index in split.folds[k])
        result = final.fits[k]
        term = correction_lib.fit_error_correction(fit, fit_lib.predict([result], fit)[0], settings.correction, seed)
        return term(select, fit_lib.predict([result], select)[0])

    *out_of_fold, pool_term = fit_lib.side_by_side(error_term, range(len(split.folds) + 1))
    means, stds = zip(*out_of_fold, strict=True)
    selection_windows = split.pool.select(split.select_index)
    fallback = metrics.window_errors(np.concatenate(means), selection_windows.target, selection_windows.sequence)
    gains = metrics.sequence_gains(final.errors, [fallback])
    report("diagnosing the selected model")
    after = diagnose_lib.diagnose(selection_windows, final.prediction, variables, **diagnose)
    yaw = np.asarray(selection_windows.inputs.object_yaw, np.float64)
    local = metrics.standardised_residuals(final.prediction, np.ones_like(final.prediction), selection_windows.target,
                                           yaw)
    noise = np.sqrt(np.mean(local ** 2, axis=0))
    variability = variability_lib.measure(split.pool)
    # The predictive standard deviation: the fitted noise and the window's motion spread over the pushes' parameters
    # in quadrature, so that the intervals widen where a push's own parameters matter (a sliding contact).
    selected_std = np.sqrt(noise ** 2 + variability_lib.window_spread(selection.model, selection_windows,
                                                                       variability) ** 2)
    fallback_z = metrics.standardised_residuals(np.concatenate(means), np.concatenate(stds), selection_windows.target,
                                                yaw)
    return Decision(split=split, force=force, selection=selection, fallback_gain=float(gains.sum() / final.score),
                    fallback_p_value=float(metrics.sign_flip_pvalues(gains, seed=seed)[0]), variables=variables,
                    diagnosis_before=before, diagnosis_after=after, noise=noise, variability=variability,
                    selected_multipliers=metrics.interval_multipliers(local / selected_std),
                    fallback_multipliers=metrics.interval_multipliers(fallback_z),
                    alpha=settings.alpha, error_term=pool_term)


def measured_split(examples: Examples, settings: LoopConfig = LoopConfig(), seed: int = 0
                   ) -> tuple[splits_lib.Split, force_lib.ForceFriction, tuple[str, ...]]:
    """The fit/select/test roles of the windows, the pusher friction the force sensor reads on the pool and the
    candidate effects: where the sensor measured it, every window carries the measured coefficient and
    ``pusher_friction`` is no candidate."""
    split = splits_lib.split(examples, len(settings.effects), settings.alpha, settings.test_fraction,
                             settings.select_fraction, seed)
    force = force_lib.estimate(split.pool.push_friction, split.pool.push, split.pool.sequence)
    effects = settings.effects
    if settings.measure_pusher_friction and force.measured:
        split = dataclasses.replace(split, pool=with_pusher_friction(split.pool, force.value),
                                    test=with_pusher_friction(split.test, force.value))
        effects = tuple(name for name in effects if name != "pusher_friction")
    return split, force, effects


def with_pusher_friction(examples: Examples, mu: float) -> Examples:
    """``examples`` with the pusher–object friction coefficient ``mu`` in every window's model inputs."""
    return dataclasses.replace(examples, inputs=examples.inputs.replace(mu=np.full(len(examples), float(mu))))


def close_loop(
    data_dir: str | os.PathLike,
    workdir: str | os.PathLike,
    settings: LoopConfig = LoopConfig(),
    seed: int = 0,
    progress: bool = True,
) -> report_lib.LoopResult:
    """Runs the loop and writes ``report.json``, ``details.json``, ``model.json`` (the selected model,
    :mod:`pushjax.physics.model_file`), ``report.md`` and figures to ``workdir``.

    Args:
      data_dir: root of pushes in the raw MIT layout (``<surface>/<object>/motion_surface=...h5``).
      workdir: output directory (created).
      settings: the loop's settings.
      seed: seed of the split, the tests, the cross-fitting folds and the error terms.
      progress: show tqdm progress bars.

    Returns:
      What the loop found (the content of ``report.json``) and how it decided (``details.json``).

    Raises:
      ValueError: ``data_dir`` is not a directory, holds no usable push, or too few push sequences to
        select on (the message names how many were found and how many are needed).
    """
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        raise ValueError(f"data_dir: {str(data_dir)!r} is not a directory")
    pushes = iter_pushes(data_dir)
    if not pushes.paths:
        raise ValueError(f"data_dir: no push files (motion_surface=...h5) below {str(data_dir)!r}; "
                         f"{pushes.summary()}")
    # Closed before an error propagates, so that the error is the last line the user sees.
    with tqdm.tqdm(total=4, desc="close loop", unit="stage", disable=not progress) as stages:

        def stage(message: str) -> None:
            stages.set_postfix_str(message)

        stage("loading pushes")
        loading = tqdm.tqdm(pushes, total=len(pushes.paths), desc="pushes", unit="push", disable=not progress,
                            leave=False)
        try:
            examples, build = build_examples(loading, horizon=settings.horizon, stride=settings.stride,
                                             pusher_friction=settings.pusher_friction)
            stages.update()
            decision = decide(examples, settings, seed, stage)
        except ValueError as error:  # the files skipped, if any, may be why
            raise ValueError(f"data_dir: {error}" + (f"; {pushes.summary()}" if pushes.n_skipped else "")) from None
        stages.update()

        stage("refitting on the pool and measuring on the test split")
        report = measure(decision, settings, seed, n_skipped=pushes.n_skipped + build.n_skipped)
        stages.update()

        stage("writing the report")
        details = _details(decision, settings, seed, data_dir,
                           skipped={**{reason: [p.name for p in paths] for reason, paths in pushes.skipped.items()},
                                    **build.skipped})
        model = decision.selection.model
        selected_model = model_file.AugmentedModel.create(
            model.effects if model is not None else (), model.params if model is not None else {},
            float(decision.split.pool.inputs.mu[0]))
        result = report_lib.LoopResult(report=report, details=details, model=selected_model)
        _write(Path(workdir), result, decision)
        stages.update()
    return result


def measure(decision: Decision, settings: LoopConfig, seed: int, n_skipped: int = 0) -> report_lib.LoopReport:
    """Refits the decided model's per-group values, the limit surface's shape and the error term on the pool, and
    measures every model on the untouched test split."""
    split, selection = decision.split, decision.selection
    pool, test = split.pool, split.test
    model = selection.model

    def limit_surface_shape() -> shape_lib.LimitSurfaceShape:
        shape = shape_lib.limit_surface_shape(
            shape_lib.measured_twists(pool), pool.wrench, pool.inputs.l, pool.sequence,
            shape_lib.shape_models(pool, model.params if model is not None else None), settings.n_bootstrap, seed)
        return dataclasses.replace(shape, rim_from_force=shape_lib.rim_from_force(pool, shape))

    def per_group_values() -> list[hierarchy_lib.GroupValues]:
        return hierarchy_lib.hierarchical(pool, model, settings.fit) if model is not None else []

    per_group, shape = fit_lib.side_by_side(lambda compute: compute(), [per_group_values, limit_surface_shape])
    plain_test, model_test = fit_lib.predict([None, model], test)
    fallback_mean, fallback_std = decision.error_term(test, model_test)

    def measured(prediction) -> report_lib.HeldOutErrors:
        errors = metrics.window_errors(prediction, test.target, test.sequence)
        return report_lib.HeldOutErrors.from_summary(
            metrics.summarize(errors), interval=metrics.bootstrap_interval(errors, settings.n_bootstrap, seed))

    yaw = np.asarray(test.inputs.object_yaw, np.float64)
    spread = variability_lib.window_spread(model, test, decision.variability)
    selected_std = np.sqrt(decision.noise ** 2 + spread ** 2)
    return report_lib.LoopReport(
        n_pushes={**split.n_pushes(), "skipped": int(n_skipped)},
        baseline=measured(plain_test),
        diagnosis=decision.diagnosis_before,
        ranking=[report_lib.RankedEffect(effect=c.effects[0], params=c.fits[0].physical[c.effects[0]],
                                         select=report_lib.Errors.from_summary(c.summary))
                 for c in selection.ranking],
        selected=selection.selected,
        alternatives=selection.alternatives,
        after=measured(model_test),
        noise_floor=metrics.noise_floor(test.target, test.sequence, test.push, test.window, test.tracking_noise,
                                        settings.n_bootstrap, seed, variability=spread),
        variability=decision.variability,
        pusher_friction=report_lib.PusherFriction(
            nominal=settings.pusher_friction, force_sensor=decision.force,
            from_force_sensor=settings.measure_pusher_friction and decision.force.measured,
            used=float(pool.inputs.mu[0])),
        fallback=measured(fallback_mean),
        remaining=decision.remaining,
        uncertainty=report_lib.Uncertainty(
            selected=metrics.predictive_scores(model_test, selected_std, test.target, yaw,
                                               decision.selected_multipliers),
            noise=decision.noise,
            fallback=metrics.predictive_scores(fallback_mean, fallback_std, test.target, yaw,
                                               decision.fallback_multipliers)),
        per_group=per_group,
        limit_surface_shape=shape,
    )


def _details(decision: Decision, settings: LoopConfig, seed: int, data_dir: Path,
             skipped: dict[str, list[str]]) -> report_lib.LoopDetails:
    split, selection = decision.split, decision.selection
    model = selection.model
    return report_lib.LoopDetails(
        data_dir=str(data_dir),
        horizon=settings.horizon,
        seed=seed,
        pusher_friction=settings.pusher_friction,
        alpha=settings.alpha,
        min_gain=settings.min_gain,
        cross_fitted=split.cross_fitted,
        n_sequences={"pool": split.pool.n_sequences, "test": split.test.n_sequences},
        n_windows={"fit": len(split.folds[0][0]), "select": len(split.select_index), "test": len(split.test)},
        skipped=skipped,
        diagnosis_before=decision.diagnosis_before,
        diagnosis_after=decision.diagnosis_after,
        select_noise_floor=selection.noise_floor,
        rounds=selection.rounds,
        fallback_gain=decision.fallback_gain,
        fallback_p_value=decision.fallback_p_value,
        fallback_beyond_noise=decision.fallback_helps,
        selected_params=model.physical if model is not None else {},
    )


def _write(workdir: Path, result: report_lib.LoopResult, decision: Decision) -> None:
    """The report's files and its figures."""
    selection = decision.selection
    figures = workdir / report_lib.FIGURE_DIR
    figures.mkdir(parents=True, exist_ok=True)
    report_lib.write(workdir, result)
    selection_windows = decision.split.pool.select(decision.split.select_index)
    figures_lib.residual_figure(figures / "residual_baseline.png", selection_windows, selection.baseline.prediction,
                               "Residual of the plain model (median per bin)", decision.variables)
    figures_lib.residual_figure(figures / "residual_after.png", selection_windows, selection.final.prediction,
                               "Residual after the fix: " + (" + ".join(selection.selected) or "nothing selected"),
                               decision.variables)
    figures_lib.strength_figure(figures / "diagnosis.png", decision.diagnosis_before, decision.diagnosis_after)
