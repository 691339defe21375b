"""Which effects does the data need? Ranking and greedy forward selection, decided on the select split only.

Every library effect is fitted alone on the fit sequences and ranked by its translation + rotation error
(% of the ``zero`` baseline) on the selection sequences (out of fold: the select split, or every pool
sequence when cross-fitted, see :mod:`pushjax.loop.splits`). Greedy forward selection starts from the plain
model and, in each round, fits the current set plus each remaining effect (warm-started from the current
fit and the effect's own fit; an effect that excludes some of the current ones, such as ``limit_surface``, which
subsumes ``friction_ratio`` and ``pressure_gradient``, replaces them) and tests every candidate:

* beyond noise: the one-sided paired sign-flip test over selection sequences
  (:func:`pushjax.loop.metrics.sign_flip_pvalues`), Holm's step-down procedure over the round's candidates
  (:func:`pushjax.loop.metrics.holm`), so the family-wise error of the round is at most ``alpha``;
* worth having: the gain must remove more than ``min_gain`` of the error the current model has above the noise
  floor (:func:`pushjax.loop.metrics.noise_floor` of the selection windows): close to the floor, nothing more is
  there to explain.

* a mechanism, not a knob (:func:`check_mechanism`): the added effect's parameters, fitted separately on the pool
  sequences of each object, surface or push velocity (where the data has several with enough sequences), agree
  within their standard errors (Cochran's Q) or, where they do not, spread between groups by at most
  :data:`MECHANISM_SPREAD` of the effect's size (a practical margin). Parameters that belong to one object (a pressure, a marker, a hidden
  weight: ``Effect.per_object``) are compared across surfaces and velocities only.

Among the candidates that pass, the one with the largest gain is added; selection stops when none passes.

The other candidates that passed the first two tests and whose gain the added one does not beat beyond noise (the
same sign-flip test on the per-sequence difference, at ``alpha``) are its indistinguishable rivals: the data cannot
tell the added effect from them (a table-fixed friction field and a moved centre of mass from one start pose), and
the report names them. The selected set is then refitted on the whole pool; the test split is never used here.

From the second round on, a candidate's fit starts from the current model's and runs ``warm_steps`` further, so the
current model is fitted as far in the same call (its continuation) and every gain is measured against that: an added
effect must not win by the extra steps alone. The continuation is also the fits' convergence check: where it lowers
the current model's selection score by more than :data:`CONVERGENCE_TOLERANCE`, every fit of the round is continued
by ``warm_steps`` again, up to :data:`MAX_CONTINUATIONS` times; a round whose fits still have not converged adds
nothing (selection stops; raise the fit steps) — an effect that takes up an under-fitted one's misfit is a knob, not a
discovery (BENCHMARKS.md, "Does the loop's fit converge?"). The first round's single fits are not checked
(their current model, the plain one, has nothing to fit).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

from pushjax.loop import fit as fit_lib
from pushjax.loop import hierarchy, metrics
from pushjax.loop.splits import Split
from pushjax.loop.windows import Examples
from pushjax.physics.effects import EFFECT_NAMES, EFFECTS

MIN_GAIN = 0.05
"""Default share of the current model's selection error above the noise floor that an added effect must remove."""
CONVERGENCE_TOLERANCE = 0.01
"""Largest share of the current model's selection score that fitting it ``warm_steps`` further may remove for its
fits to count as converged (fixed before it was measured on the loop's data sets). At the default 300 steps the exact
limit surface's fit loss on a centre-loaded pressure is within 0.2 % of its converged value, at 150 steps 10 % above it
(BENCHMARKS.md)."""
MAX_CONTINUATIONS = 3
"""How many times a round's fits are continued by ``warm_steps`` more where the current model's has not converged."""


@dataclasses.dataclass(frozen=True)
class Candidate:
    """A model fitted once per fold and its out-of-fold performance on the selection windows.

    Attributes:
      effects: effect names (empty: the plain Lynch model).
      fits: per fold, the fit (None for the plain model).
      prediction: [N, 3] out-of-fold predictions on the selection windows (m, m, rad).
      errors: their per-window errors.
      summary: {trans_percent, rot_percent, trans_mm, rot_deg} on the selection windows.
    """

    effects: tuple[str, ...]
    fits: list[fit_lib.FitResult | None]
    prediction: np.ndarray
    errors: metrics.WindowErrors
    summary: dict[str, float]

    @property
    def score(self) -> float:
        return metrics.combined(self.summary)


MECHANISM_GROUPS = ("object", "surface", "push velocity")
"""Variables whose values split the pool into groups on which an added effect's parameters must agree."""
MECHANISM_SPREAD = 0.5
"""Largest between-group spread of a value, over the effect's size, that still counts as one mechanism.

Fixed before the power / false-discovery table of issue 29 was measured. The spread is the random-effects standard
deviation between groups (DerSimonian-Laird); the size is the largest distance of the effect's values in the same unit
from their "no effect" values (offsets x and y share one size), and a direction (a value in degrees) counts a size of
90 degrees. With many pushes the groups' standard errors shrink below the misfit that any simulator leaves, so
"agree within their standard errors" alone rejects a true centre-of-mass offset whose groups agree within 1-3 mm
(BENCHMARKS.md, 500 pushes); a knob's groups differ by as much as the effect itself."""
DIRECTION_SIZE_DEG = 90.0
"""The size a direction (a value in degrees) is compared with: its spread may reach ``MECHANISM_SPREAD`` of it."""


@dataclasses.dataclass(frozen=True)
class Heterogeneity:
    """Whether one reported value of an effect agrees across the groups of one variable.

    Attributes:
      variable: the grouping variable (one of :data:`MECHANISM_GROUPS`).
      value: the reported value's name (``pushjax.physics.effects``' physical values).
      p_value: Cochran's Q p-value, Bonferroni-adjusted over the check's tests.
      relative_spread: the between-group standard deviation over the effect's size (see :data:`MECHANISM_SPREAD`).
    """

    variable: str
    value: str
    p_value: float
    relative_spread: float

    def is_knob(self, alpha: float) -> bool:
        return self.p_value <= alpha and self.relative_spread > MECHANISM_SPREAD


@dataclasses.dataclass(frozen=True)
class MechanismCheck:
    """Whether an effect's parameters agree across groups of the data.

    Attributes:
      effect: the added effect.
      tests: one per grouping variable and reported value, most heterogeneous (smallest p-value) first; empty when no
        grouping could be tested (one group, or groups with too few sequences).
      values: {grouping variable: {group: {value name: {"value", "std"}}}} of the fits on each group.
    """

    effect: str
    tests: list[Heterogeneity]
    values: dict[str, dict[str, dict[str, dict]]]

    @property
    def p_value(self) -> float | None:
        """The smallest adjusted heterogeneity p-value (None: not testable)."""
        return self.tests[0].p_value if self.tests else None

    @property
    def variable(self) -> str | None:
        """The grouping variable of the smallest p-value (None: not testable)."""
        return self.tests[0].variable if self.tests else None

    def is_knob(self, alpha: float) -> bool:
        """A knob, not a mechanism: some value differs between groups beyond both noise and the practical margin."""
        return any(test.is_knob(alpha) for test in self.tests)


@dataclasses.dataclass(frozen=True)
class Round:
    """One round of forward selection.

    Attributes:
      candidates: the models tried (current set plus one effect each).
      additions: the effect each candidate adds.
      gains: relative selection-error cut of each over the current model (point estimates).
      p_values: one-sided sign-flip p-value of each gain.
      levels: the level Holm's procedure compared each p-value with.
      beyond_noise: whether Holm's procedure rejects "no gain" for each.
      floor: the gain (points of the combined score) an addition had to exceed: ``min_gain`` times the current
        error above the noise floor.
      mechanism: the mechanism checks made in this round, in the order of the candidates' gains.
      incumbent_change: the share of the current model's selection score that its last continuation by
        ``warm_steps`` removed (the continued model is what the gains are measured against; 0 in the first round, whose
        current model, the plain one, has nothing to fit).
      continuations: how many times the round's fits were continued beyond the first ``warm_steps`` because the
        current model's had not converged (at most :data:`MAX_CONTINUATIONS`).
      converged: whether ``incumbent_change`` is at most :data:`CONVERGENCE_TOLERANCE`; a round whose fits have not
        converged adds nothing.
      accepted: the effect added in this round, or None (selection stops).
      indistinguishable: {effect: one-sided p-value that the accepted effect's gain exceeds its gain} of the other
        candidates beyond noise and above the floor, with a smaller gain, that the accepted one does not beat at
        ``alpha`` (empty when nothing was accepted).
    """

    candidates: list[Candidate]
    additions: list[str]
    gains: list[float]
    p_values: list[float]
    levels: list[float]
    beyond_noise: list[bool]
    floor: float
    mechanism: list[MechanismCheck]
    incumbent_change: float
    continuations: int
    converged: bool
    accepted: str | None
    indistinguishable: dict[str, float]


@dataclasses.dataclass(frozen=True)
class Selection:
    """Result of :func:`select_effects`.

    Attributes:
      baseline: the plain model.
      ranking: the single-effect models, best selection score first.
      rounds: the forward-selection rounds.
      final: the selected candidate (the baseline when nothing was selected).
      model: the selected effects refitted on the whole pool (None when nothing was selected).
      noise_floor: the noise floor of the selection windows.
    """

    baseline: Candidate
    ranking: list[Candidate]
    rounds: list[Round]
    final: Candidate
    model: fit_lib.FitResult | None
    noise_floor: metrics.NoiseFloor

    @property
    def selected(self) -> list[str]:
        """The final model's effects in the order they were selected (one replaced by a later one left out)."""
        accepted = [round_.accepted for round_ in self.rounds if round_.accepted is not None]
        return [name for name in accepted if name in self.final.effects]

    @property
    def converged(self) -> bool:
        """Whether every round's fits passed the convergence check (see :data:`CONVERGENCE_TOLERANCE`)."""
        return all(round_.converged for round_ in self.rounds)

    @property
    def alternatives(self) -> dict[str, dict[str, float]]:
        """{selected effect: its indistinguishable rivals with their p-values}, for the selected effects that have
        any."""
        return {round_.accepted: round_.indistinguishable for round_ in self.rounds
                if round_.accepted in self.final.effects and round_.indistinguishable}


class _Folds:
    """The fit and select windows of each fold, and the selection windows in fold order."""

    def __init__(self, split: Split):
        self.fit = [split.pool.select(fit) for fit, _ in split.folds]
        self.select = [split.pool.select(select) for _, select in split.folds]
        self.selection = split.pool.select(split.select_index)

    def evaluate(self, sets: Sequence[tuple[str, ...]], per_fold: list[list[fit_lib.FitResult | None]]
                 ) -> list[Candidate]:
        """Candidates from ``per_fold[k][m]``, the fit of set ``m`` on fold ``k``."""
        predictions = np.concatenate([fit_lib.predict(results, select)
                                      for results, select in zip(per_fold, self.select)], axis=1)
        candidates = []
        for m, effects in enumerate(sets):
            errors = metrics.window_errors(predictions[m], self.selection.target, self.selection.sequence)
            candidates.append(Candidate(effects=tuple(effects), fits=[fold[m] for fold in per_fold],
                                        prediction=predictions[m], errors=errors, summary=metrics.summarize(errors)))
        return candidates


def select_effects(
    split: Split,
    effects: Sequence[str] = EFFECT_NAMES,
    settings: fit_lib.FitConfig = fit_lib.FitConfig(),
    min_gain: float = MIN_GAIN,
    alpha: float = 0.05,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> Selection:
    """Ranks the effects on the selection windows and selects a combination by forward selection.

    Args:
      split: the fit/select roles of the pool (:func:`pushjax.loop.splits.split`).
      effects: candidate effect names.
      settings: optimiser settings.
      min_gain: share of the current selection error above the noise floor that an added effect must remove.
      alpha: family-wise error level of each round's decision.
      seed: seed of the sign-flip test.
      progress: called with a short message before each fitting round.

    Returns:
      The :class:`Selection`.
    """
    effects = tuple(name for name in EFFECT_NAMES if name in effects)
    report = progress or (lambda message: None)
    folds = _Folds(split)
    selection_windows = folds.selection
    floor = metrics.noise_floor(selection_windows.target, selection_windows.sequence, selection_windows.push,
                                selection_windows.window, selection_windows.tracking_noise, seed=seed)
    baseline = folds.evaluate([()], [[None] for _ in folds.fit])[0]
    report(f"fitting {len(effects)} effects")
    sets = [(name,) for name in effects]
    singles = folds.evaluate(sets, fit_lib.side_by_side(lambda fit: fit_lib.fit_effects(sets, fit, settings),
                                                        folds.fit))
    ranking = sorted(singles, key=lambda candidate: candidate.score)
    single_params = [{c.effects[0]: c.fits[k].params[c.effects[0]] for c in singles} for k in range(len(folds.fit))]

    current, candidates, additions, rounds = baseline, singles, list(effects), []
    incumbent_change, continuations = 0.0, 0
    while candidates:
        converged = incumbent_change <= CONVERGENCE_TOLERANCE
        per_sequence = metrics.sequence_gains(current.errors, [c.errors for c in candidates])
        points = per_sequence.sum(axis=1)
        gains = [float(g) for g in points / current.score]
        p_values = metrics.sign_flip_pvalues(per_sequence, seed=seed)
        beyond_noise, levels = metrics.holm(p_values, alpha)
        required = min_gain * max(current.score - floor.score, 0.0)
        passing = np.flatnonzero(beyond_noise & (points > required) & converged)
        best, checks = None, []
        for index in passing[np.argsort(-points[passing], kind="stable")]:
            checks.append(check_mechanism(split.pool, candidates[index].effects, additions[index], settings,
                                          candidates[index].fits[0].params))
            if not checks[-1].is_knob(alpha):
                best = int(index)
                break
        rounds.append(Round(candidates=candidates, additions=additions, gains=gains,
                            p_values=[float(p) for p in p_values], levels=[float(level) for level in levels],
                            beyond_noise=[bool(b) for b in beyond_noise], floor=float(required), mechanism=checks,
                            incumbent_change=float(incumbent_change), continuations=continuations,
                            converged=bool(converged),
                            accepted=additions[best] if best is not None else None,
                            indistinguishable=_rivals(per_sequence, points, passing, best, additions, alpha, seed)))
        if best is None:
            break
        current = candidates[best]
        sets, additions = _next_sets(current.effects, effects)
        if not sets:
            break
        report(f"fitting {current.effects} plus one of {len(sets)} effects, and {current.effects} further")
        candidates, current, incumbent_change, continuations = _fit_round(folds, current, sets, additions,
                                                                          single_params, settings, report)
    model = None
    if current.effects:
        report(f"refitting {current.effects} on every pool sequence")
        model = fit_lib.fit_effects([current.effects], split.pool, settings, initial=[current.fits[0].params])[0]
    return Selection(baseline=baseline, ranking=ranking, rounds=rounds, final=current, model=model,
                     noise_floor=floor)


def _fit_round(folds: _Folds, current: Candidate, sets: list[tuple[str, ...]], additions: list[str],
               single_params: list[dict], settings: fit_lib.FitConfig, report: Callable[[str], None]
               ) -> tuple[list[Candidate], Candidate, float, int]:
    """Fits a round's candidate sets, each warm-started from the current fit and its added effect's single fit, with
    the current set continued beside them, and continues them all while the current one's score still changes.

    Returns:
      (the candidates, the current set fitted as far as them, the share of its score the last continuation removed,
      the number of continuations).
    """
    starts = [[{**{name: current.fits[k].params[name] for name in effects_set if name in current.effects},
                name: single_params[k][name]} for effects_set, name in zip(sets, additions)]
              for k in range(len(folds.fit))]
    for continuations in range(MAX_CONTINUATIONS + 1):
        per_fold = fit_lib.side_by_side(
            lambda k: fit_lib.fit_effects(sets + [current.effects], folds.fit[k], settings,
                                          initial=starts[k] + [current.fits[k].params]),
            range(len(folds.fit)))
        *candidates, continued = folds.evaluate(sets + [current.effects], per_fold)
        incumbent_change = (current.score - continued.score) / max(current.score, np.finfo(float).tiny)
        current = continued
        if incumbent_change <= CONVERGENCE_TOLERANCE or continuations == MAX_CONTINUATIONS:
            break
        report(f"continuing the fits of {current.effects} and its candidates (not converged)")
        starts = [[candidate.fits[k].params for candidate in candidates] for k in range(len(folds.fit))]
    return candidates, current, incumbent_change, continuations


def check_mechanism(pool: Examples, effects: tuple[str, ...], added: str, settings: fit_lib.FitConfig,
                    initial: dict) -> MechanismCheck:
    """Fits ``effects`` on the pool sequences of each group and tests whether ``added``'s values agree.

    For each variable of :data:`MECHANISM_GROUPS` with at least two groups of :data:`pushjax.loop.hierarchy.MIN_GROUP_SEQUENCES` sequences
    (only ``surface`` and ``push velocity`` for a per-object effect) and each reported value: Cochran's Q over the
    groups (inverse-variance weights from the sandwich standard errors) against chi-square with groups - 1 degrees of
    freedom, Bonferroni-adjusted over the check's tests, and the DerSimonian-Laird between-group standard deviation
    relative to the effect's size (:data:`MECHANISM_SPREAD`). A value is a knob's when both are beyond their bounds.
    """
    variables = [name for name in MECHANISM_GROUPS if not (EFFECTS[added].per_object and name == "object")]
    neutral = {name: float(value) for name, value in EFFECTS[added].physical(EFFECTS[added].init()).items()}
    values, raw = {}, []
    for variable in variables:
        groups, fits = hierarchy.fit_groups(pool, effects, variable, settings, initial)
        if not fits:
            continue
        values[variable] = {label: result.physical[added] for label, result in zip(groups, fits)}
        pooled = {name: result for name, (_, _, result) in hierarchy.pool_values(fits, added).items()}
        centres = {name: result.fixed_mean for name, result in pooled.items()}
        for name, result in pooled.items():
            raw.append((result.p_value, variable, name,
                        result.tau / max(_effect_size(name, centres, neutral), np.finfo(float).tiny)))
    tests = [Heterogeneity(variable=variable, value=name, p_value=min(1.0, p_value * len(raw)),
                           relative_spread=relative)
             for p_value, variable, name, relative in sorted(raw, key=lambda test: test[0])]
    return MechanismCheck(effect=added, tests=tests, values=values)


def _rivals(per_sequence: np.ndarray, points: np.ndarray, passing: np.ndarray, best: int | None,
            additions: Sequence[str], alpha: float, seed: int) -> dict[str, float]:
    """{addition: p-value} of the passing candidates with a smaller gain than ``best`` whose per-sequence gains
    [S] ``best``'s do not exceed beyond noise (one-sided sign-flip test of the difference at ``alpha``)."""
    if best is None:
        return {}
    smaller = [int(index) for index in passing if index != best and points[index] <= points[best]]
    if not smaller:
        return {}
    p_values = metrics.sign_flip_pvalues(per_sequence[best] - per_sequence[smaller], seed=seed)
    return {additions[index]: float(p) for index, p in zip(smaller, p_values) if p > alpha}


def _unit(name: str) -> str:
    return name.rsplit("_", 1)[-1]


def _effect_size(name: str, pooled: dict[str, float], neutral: dict[str, float]) -> float:
    """The size ``name``'s spread is compared with: the largest distance from "no effect" of the values in its unit."""
    if _unit(name) == "deg":
        return DIRECTION_SIZE_DEG
    return max(abs(pooled[other] - neutral[other]) for other in pooled if _unit(other) == _unit(name))


def _next_sets(current: tuple[str, ...], effects: Sequence[str]) -> tuple[list[tuple[str, ...]], list[str]]:
    """The next round's candidate sets and the effect each adds: the current set plus each remaining effect, less
    the current effects the added one excludes; an effect that a current one excludes is not a candidate."""
    sets, additions = [], []
    for name in effects:
        if name in current or any(name in EFFECTS[other].excludes for other in current):
            continue
        kept = tuple(other for other in current if other not in EFFECTS[name].excludes)
        sets.append(kept + (name,))
        additions.append(name)
    return sets, additions
