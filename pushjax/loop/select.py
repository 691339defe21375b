"""Which effects does the data need? Held-out ranking and greedy forward selection with a parsimony rule.

Every library effect is fitted alone on the fit split and ranked by its held-out translation + rotation
error (% of the ``zero`` baseline). Greedy forward selection then starts from the plain model and, in
each round, fits the current set plus each remaining effect (warm-started from the current fit and the
effect's own fit) and keeps the best addition only when its held-out gain is beyond noise: the lower
one-sided bootstrap bound (resampling held-out push sequences, paired; Bonferroni over the round's
candidates) of the relative error reduction must exceed ``min_gain``. A practical threshold as well as a
statistical one, because simulated or well-tracked data resolve differences far too small to matter.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np

from pushjax.loop import fit as fit_lib
from pushjax.loop import metrics
from pushjax.loop.windows import Examples
from pushjax.physics.effects import EFFECT_NAMES

MIN_GAIN = 0.1
"""Default relative cut of the held-out error that an added effect must achieve at its lower bound."""


@dataclasses.dataclass(frozen=True)
class Candidate:
    """A fitted model and its held-out performance.

    Attributes:
      effects: effect names (empty: the plain Lynch model).
      fit: the fit, or None for the plain model.
      errors: held-out per-window errors.
      heldout: held-out summary {trans_pct, rot_pct, trans_mm, rot_deg}.
    """

    effects: tuple[str, ...]
    fit: fit_lib.FitResult | None
    errors: metrics.WindowErrors
    heldout: dict[str, float]

    @property
    def score(self) -> float:
        return metrics.combined(self.heldout)


@dataclasses.dataclass(frozen=True)
class Round:
    """One round of forward selection.

    Attributes:
      candidates: the models tried (current set plus one effect each).
      additions: the effect each candidate adds.
      gains: relative held-out error cut of each over the current model (point estimates).
      lower: lower bootstrap bound of the best candidate's gain.
      accepted: the effect added in this round, or None (selection stops).
    """

    candidates: list[Candidate]
    additions: list[str]
    gains: list[float]
    lower: float
    accepted: str | None


@dataclasses.dataclass(frozen=True)
class Selection:
    """Result of :func:`select_effects`.

    Attributes:
      baseline: the plain model.
      ranking: the single-effect models, best held-out score first.
      rounds: the forward-selection rounds.
      final: the selected model (the baseline when nothing was selected).
    """

    baseline: Candidate
    ranking: list[Candidate]
    rounds: list[Round]
    final: Candidate

    @property
    def selected(self) -> list[str]:
        """Effect names in the order they were selected."""
        return [round_.accepted for round_ in self.rounds if round_.accepted is not None]


def _evaluate(results: Sequence[fit_lib.FitResult | None], heldout: Examples) -> list[Candidate]:
    predictions = fit_lib.predict(list(results), heldout)
    candidates = []
    for result, prediction in zip(results, predictions):
        errors = metrics.window_errors(prediction, heldout.target, heldout.sequence)
        candidates.append(Candidate(effects=() if result is None else result.effects, fit=result, errors=errors,
                                    heldout=metrics.summarize(errors)))
    return candidates


def select_effects(
    fit: Examples,
    heldout: Examples,
    effects: Sequence[str] = EFFECT_NAMES,
    settings: fit_lib.FitSettings = fit_lib.FitSettings(),
    min_gain: float = MIN_GAIN,
    alpha: float = 0.05,
    n_bootstrap: int = 1000,
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> Selection:
    """Ranks the effects by held-out error and selects a combination by forward selection.

    Args:
      fit: examples the parameters are fitted on.
      heldout: examples the models are compared on (other push sequences).
      effects: candidate effect names.
      settings: optimiser settings.
      min_gain: relative held-out error cut an added effect must reach at its lower bound.
      alpha: family-wise error level of each round's decision.
      n_bootstrap: bootstrap resamplings of the held-out sequences.
      seed: seed of the bootstrap.
      progress: called with a short message before each fitting round.

    Returns:
      The :class:`Selection`.
    """
    effects = tuple(name for name in EFFECT_NAMES if name in effects)
    report = progress or (lambda message: None)
    baseline = _evaluate([None], heldout)[0]
    report(f"fitting {len(effects)} effects")
    singles = _evaluate(fit_lib.fit_effects([(name,) for name in effects], fit, settings), heldout)
    ranking = sorted(singles, key=lambda candidate: candidate.score)
    single_params = {candidate.effects[0]: candidate.fit.params[candidate.effects[0]] for candidate in singles}

    current, candidates, rounds = baseline, singles, []
    while candidates:
        scores = metrics.bootstrap_combined([current.errors] + [c.errors for c in candidates], n_bootstrap, seed)
        relative = 1 - scores[:, 1:] / scores[:, :1]
        gains = [1 - candidate.score / current.score for candidate in candidates]
        best = int(np.argmax(gains))
        lower = float(np.quantile(relative[:, best], alpha / len(candidates)))
        accepted = lower > min_gain
        additions = [[name for name in c.effects if name not in current.effects][0] for c in candidates]
        rounds.append(Round(candidates=candidates, additions=additions, gains=gains, lower=lower,
                            accepted=additions[best] if accepted else None))
        if not accepted:
            break
        current = candidates[best]
        remaining = [name for name in effects if name not in current.effects]
        if not remaining:
            break
        report(f"fitting {current.effects} plus one of {len(remaining)} effects")
        sets = [current.effects + (name,) for name in remaining]
        starts = [{**current.fit.params, name: single_params[name]} for name in remaining]
        candidates = _evaluate(fit_lib.fit_effects(sets, fit, settings, initial=starts), heldout)
    return Selection(baseline=baseline, ranking=ranking, rounds=rounds, final=current)
