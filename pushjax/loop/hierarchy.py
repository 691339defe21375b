"""Parameters that may differ per object or per surface: fitted on each group, shrunk towards a shared value.

A pressure belongs to an object and a friction to a surface, so one global value of either averages the groups or
is absorbed by another parameter. The selected effects are fitted on the pool sequences of each group of a variable
(:func:`fit_groups`, also the mechanism check's fits) and every reported value is pooled by a random-effects model
(:func:`pushjax.loop.metrics.random_effects`): the shared value, the spread between groups, and each group's value
shrunk towards the shared one by as much as its own error allows (empirical Bayes). A group with a precise fit
keeps its value; a group with few pushes borrows from the others.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from pushjax.loop import fit as fit_lib
from pushjax.loop import metrics
from pushjax.loop.windows import Examples

GROUP_VARIABLES = ("object", "surface")
"""Variables whose groups may carry values of their own (a pressure per object, a friction per surface)."""
MIN_GROUP_SEQUENCES = 8
"""Fewest pool sequences of a group for it to be fitted on its own."""


def fit_groups(pool: Examples, effects: tuple[str, ...], variable: str, settings: fit_lib.FitConfig,
               initial: dict) -> tuple[list[str], list[fit_lib.FitResult]]:
    """Fits ``effects`` on the pool sequences of each group of ``variable`` with :data:`MIN_GROUP_SEQUENCES`.

    The groups are fitted in one call on the pool's batch, each on its own windows (``fit_effects``' subsets).

    Returns:
      (the groups' labels, their fits); both empty when fewer than two groups have enough sequences.
    """
    labels = pool.variables[variable]
    groups = [label for label in np.unique(labels)
              if len(np.unique(pool.sequence[labels == label])) >= MIN_GROUP_SEQUENCES]
    if len(groups) < 2:
        return [], []
    fits = fit_lib.fit_effects([effects] * len(groups), pool, settings, initial=[initial] * len(groups),
                               subsets=[labels == label for label in groups])
    return [str(label) for label in groups], fits


def pool_values(fits: Sequence[fit_lib.FitResult], effect: str
                ) -> dict[str, tuple[np.ndarray, np.ndarray, metrics.RandomEffects]]:
    """{value name: ([G] values, [G] standard errors, their random-effects pooling)} of ``effect`` over the groups'
    fits; a value without a standard error on some group (not differentiable at its optimum) is left out."""
    pooled = {}
    for name in fits[0].physical[effect]:
        estimates = [result.physical[effect][name] for result in fits]
        if any(estimate["std"] is None or not estimate["std"] > 0 for estimate in estimates):
            continue
        value = np.array([estimate["value"] for estimate in estimates])
        std = np.array([estimate["std"] for estimate in estimates])
        pooled[name] = (value, std, metrics.random_effects(value, std))
    return pooled


@dataclasses.dataclass(frozen=True)
class GroupValues:
    """One reported value of a selected effect over the groups of one variable.

    Attributes:
      variable: the grouping variable.
      effect, value: the effect and its reported value's name.
      shared: the random-effects shared value and its standard error, {"value", "std"}.
      spread: the between-group standard deviation.
      p_value: Cochran's Q p-value (small: the groups differ beyond their errors).
      groups: {group: {"fitted", "fitted_std", "shrunk", "shrunk_std"}}.
    """

    variable: str
    effect: str
    value: str
    shared: dict[str, float]
    spread: float
    p_value: float
    groups: dict[str, dict[str, float]]


def hierarchical(pool: Examples, model: fit_lib.FitResult, settings: fit_lib.FitConfig,
                 variables: Sequence[str] = GROUP_VARIABLES) -> list[GroupValues]:
    """The selected model's values per group of each variable, with shrinkage to a shared value.

    Args:
      pool: the pool windows (never the test split).
      model: the selected effects fitted on the whole pool (the start of every group's fit).
      settings: optimiser settings.
      variables: grouping variables; one with fewer than two groups of enough sequences is left out.

    Returns:
      One :class:`GroupValues` per variable, effect and reported value with standard errors on every group.
    """
    results = []
    for variable in variables:
        groups, fits = fit_groups(pool, model.effects, variable, settings, model.params)
        for effect in model.effects if fits else ():
            for name, (value, std, pooled) in pool_values(fits, effect).items():
                results.append(GroupValues(
                    variable=variable, effect=effect, value=name, shared={"value": pooled.mean, "std": pooled.mean_std},
                    spread=pooled.tau, p_value=pooled.p_value,
                    groups={group: {"fitted": float(v), "fitted_std": float(s), "shrunk": float(shrunk),
                                    "shrunk_std": float(shrunk_std)}
                            for group, v, s, shrunk, shrunk_std in zip(groups, value, std, pooled.shrunk,
                                                                       pooled.shrunk_std)}))
    return results
