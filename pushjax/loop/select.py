"""Which effects does the data need? Ranking and greedy forward selection, decided on the select split only.

Every library effect is fitted alone on the fit sequences and ranked by its translation + rotation error
(% of the ``zero`` baseline) on the selection sequences (out of fold: the select split, or every pool
sequence when cross-fitted, see :mod:`pushjax.loop.splits`). Greedy forward selection starts from the plain
model and, in each round, fits the current set plus each remaining effect (warm-started from the current
fit and the effect's own fit) and keeps the best addition only when it lowers the error beyond noise:
the one-sided paired sign-flip test over selection sequences (:func:`pushjax.loop.metrics.sign_flip_pvalues`)
must give a p-value of at most ``alpha`` over the number of candidates of the round (Bonferroni: the
family-wise error of the round's decision is at most ``alpha``), and the point estimate of the relative
gain must exceed ``min_gain`` (0 by default: any improvement beyond noise counts). The selected set is
then refitted on the whole pool; the test split is never used here.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

from pushjax.loop import fit as fit_lib
from pushjax.loop import metrics
from pushjax.loop.splits import Split
from pushjax.physics.effects import EFFECT_NAMES

MIN_GAIN = 0.0
"""Default relative cut of the selection error that an added effect's point estimate must exceed."""


@dataclasses.dataclass(frozen=True)
class Candidate:
    """A model fitted once per fold and its out-of-fold performance on the selection windows.

    Attributes:
      effects: effect names (empty: the plain Lynch model).
      fits: per fold, the fit (None for the plain model).
      prediction: [N, 3] out-of-fold predictions on the selection windows (m, m, rad).
      errors: their per-window errors.
      summary: {trans_pct, rot_pct, trans_mm, rot_deg} on the selection windows.
    """

    effects: tuple[str, ...]
    fits: list[fit_lib.FitResult | None]
    prediction: np.ndarray
    errors: metrics.WindowErrors
    summary: dict[str, float]

    @property
    def score(self) -> float:
        return metrics.combined(self.summary)


@dataclasses.dataclass(frozen=True)
class Round:
    """One round of forward selection.

    Attributes:
      candidates: the models tried (current set plus one effect each).
      additions: the effect each candidate adds.
      gains: relative selection-error cut of each over the current model (point estimates).
      p_values: one-sided sign-flip p-value of each gain.
      level: the p-value the best addition had to reach (``alpha`` over the number of candidates).
      accepted: the effect added in this round, or None (selection stops).
    """

    candidates: list[Candidate]
    additions: list[str]
    gains: list[float]
    p_values: list[float]
    level: float
    accepted: str | None


@dataclasses.dataclass(frozen=True)
class Selection:
    """Result of :func:`select_effects`.

    Attributes:
      baseline: the plain model.
      ranking: the single-effect models, best selection score first.
      rounds: the forward-selection rounds.
      final: the selected candidate (the baseline when nothing was selected).
      model: the selected effects refitted on the whole pool (None when nothing was selected).
    """

    baseline: Candidate
    ranking: list[Candidate]
    rounds: list[Round]
    final: Candidate
    model: fit_lib.FitResult | None

    @property
    def selected(self) -> list[str]:
        """Effect names in the order they were selected."""
        return [round_.accepted for round_ in self.rounds if round_.accepted is not None]


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
    settings: fit_lib.FitSettings = fit_lib.FitSettings(),
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
      min_gain: relative selection-error cut an added effect's point estimate must exceed.
      alpha: family-wise error level of each round's decision.
      seed: seed of the sign-flip test.
      progress: called with a short message before each fitting round.

    Returns:
      The :class:`Selection`.
    """
    effects = tuple(name for name in EFFECT_NAMES if name in effects)
    report = progress or (lambda message: None)
    folds = _Folds(split)
    baseline = folds.evaluate([()], [[None] for _ in folds.fit])[0]
    report(f"fitting {len(effects)} effects")
    sets = [(name,) for name in effects]
    singles = folds.evaluate(sets, [fit_lib.fit_effects(sets, fit, settings) for fit in folds.fit])
    ranking = sorted(singles, key=lambda candidate: candidate.score)
    single_params = [{c.effects[0]: c.fits[k].params[c.effects[0]] for c in singles} for k in range(len(folds.fit))]

    current, candidates, rounds = baseline, singles, []
    while candidates:
        per_sequence = metrics.sequence_gains(current.errors, [c.errors for c in candidates])
        gains = [float(g) for g in per_sequence.sum(axis=1) / current.score]
        p_values = [float(p) for p in metrics.sign_flip_pvalues(per_sequence, seed=seed)]
        best = int(np.argmax(gains))
        level = alpha / len(candidates)
        accepted = p_values[best] <= level and gains[best] > min_gain
        additions = [[name for name in c.effects if name not in current.effects][0] for c in candidates]
        rounds.append(Round(candidates=candidates, additions=additions, gains=gains, p_values=p_values, level=level,
                            accepted=additions[best] if accepted else None))
        if not accepted:
            break
        current = candidates[best]
        remaining = [name for name in effects if name not in current.effects]
        if not remaining:
            break
        report(f"fitting {current.effects} plus one of {len(remaining)} effects")
        sets = [current.effects + (name,) for name in remaining]
        per_fold = [fit_lib.fit_effects(sets, fit, settings,
                                        initial=[{**current.fits[k].params, name: single_params[k][name]}
                                                 for name in remaining])
                    for k, fit in enumerate(folds.fit)]
        candidates = folds.evaluate(sets, per_fold)
    model = None
    if current.effects:
        report(f"refitting {current.effects} on every pool sequence")
        model = fit_lib.fit_effects([current.effects], split.pool, settings, initial=[current.fits[0].params])[0]
    return Selection(baseline=baseline, ranking=ranking, rounds=rounds, final=current, model=model)
