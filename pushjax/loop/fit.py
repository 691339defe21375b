"""Fitting effect parameters by gradient descent through the differentiable model, many models at once.

Every candidate model is the full effect library (:func:`pushjax.physics.effects.compose` of all
effects) with a 0/1 mask per effect: masked effects keep their "no effect" parameters (zeros). So
candidates with different effect sets share one compiled program; their losses are summed, which
leaves each candidate's gradient its own, and Adam (elementwise) then optimises them independently.
Parameters are optimised in units of each parameter's typical magnitude.

The loss of a window is its translation error over the mean translation of the fit windows plus its
rotation error over their mean rotation (the paper's translation + rotation error, as fractions of the
``zero`` baseline), each smoothed near zero (``sqrt(e^2 + floor^2)``).

Parameter uncertainty: the cluster-robust sandwich covariance ``H^-1 (sum_j g_j g_j^T) H^-1`` of the
optimum, with ``H`` the Gauss-Newton loss Hessian and ``g_j`` the loss gradient summed over push sequence ``j``
(windows of one push are not independent), propagated to the reported values by their Jacobian.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

import jax
import jax.numpy as jnp
import numpy as np
import optax
from jax.flatten_util import ravel_pytree

from pushjax.loop.windows import Examples
from pushjax.physics import effects as effects_lib
from pushjax.physics.effects import EFFECT_NAMES, EFFECTS, ELLIPSOID_EFFECTS, PushInputs

_Item = TypeVar("_Item")
_Result = TypeVar("_Result")

MIN_PADDED_SIZE = 256
"""Smallest padded example count (see :func:`padded_size`)."""

FINE_PADDING_ABOVE = 2048
"""Example count above which :func:`padded_size` pads to the next sixteenth of a power of two instead of the power."""


def side_by_side(function: Callable[[_Item], _Result], items: Sequence[_Item]) -> list[_Result]:
    """``[function(item) for item in items]`` for independent fits (the cross-fitting folds', the two families'), run
    side by side in threads (XLA computes outside the GIL, and one fit keeps about one core busy), in order; the same
    programs on the same inputs, so the same results as one after another."""
    items = list(items)
    workers = min(len(items), os.cpu_count() or 1)
    if workers < 2:
        return [function(item) for item in items]
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="fit") as pool:
        return list(pool.map(function, items))


def padded_size(count: int) -> int:
    """The example count a batch of ``count`` windows is padded to (with zero weight): the next power of two, at least
    :data:`MIN_PADDED_SIZE`, and above :data:`FINE_PADDING_ABOVE` the next multiple of a sixteenth of that power (at
    most an eighth more than ``count``). The loop fits dozens of subsets (folds, groups of the mechanism check, the
    pool), and compiling a program per distinct size cost more than three quarters of its time (500 pushes: 177
    compilations, 434 s of 554 s), so sizes are few; but a fit's time grows with its padded size, and a power of two
    nearly doubled the largest fits' (a fold of 500 pushes: 2 192 windows, 4 096 computed)."""
    power = max(MIN_PADDED_SIZE, 1 << max(count - 1, 0).bit_length())
    if power <= FINE_PADDING_ABOVE:
        return power
    step = power // 16
    return -(-count // step) * step


@dataclasses.dataclass(frozen=True)
class FitConfig:
    """Optimiser settings.

    Attributes:
      steps: Adam steps (full batch) of a fit from "no effect".
      warm_steps: Adam steps of a fit that starts from fitted parameters (a later round of selection, a refit, a group
        of the mechanism check): the parameters it starts from are already near the optimum.
      learning_rate: initial step size in units of each parameter's typical magnitude (cosine decay).
      translation_floor_mm: smoothing of the translation error near 0, mm.
      rotation_floor_deg: smoothing of the rotation error near 0, deg.
    """

    steps: int = 300
    warm_steps: int = 100
    learning_rate: float = 0.05
    translation_floor_mm: float = 0.1
    rotation_floor_deg: float = 0.1


@dataclasses.dataclass(frozen=True)
class FitResult:
    """One fitted candidate model.

    Attributes:
      effects: the effect names, in library order.
      params: {effect: {parameter: NumPy array}} in SI units (see :mod:`pushjax.physics.effects`).
      loss: final fit loss.
      compute_physical: computes :attr:`physical` (the sandwich standard errors need the residual's Jacobian, and
        most fits of forward selection, e.g. every fold's but the first, are never reported).
    """

    effects: tuple[str, ...]
    params: dict[str, dict[str, np.ndarray]]
    loss: float
    compute_physical: Callable[[], dict[str, dict[str, dict[str, float | None]]]] = dataclasses.field(
        default=dict, repr=False, compare=False)

    @functools.cached_property
    def physical(self) -> dict[str, dict[str, dict[str, float | None]]]:
        """{effect: {value name: {"value": float, "std": float or None}}}, the reported values with their standard
        errors (None where the value is not differentiable at the optimum); computed on first use."""
        return self.compute_physical()


@dataclasses.dataclass(frozen=True)
class Batch:
    """Examples as padded device arrays: inputs [P, ...], target [P, 3], weight [P] (0 for padding)."""

    inputs: PushInputs
    target: jax.Array
    weight: jax.Array
    count: int


def to_batch(examples: Examples) -> Batch:
    """Pads ``examples`` to :func:`padded_size` by repeating the first window."""
    count = len(examples)
    size = padded_size(count)
    index = np.concatenate([np.arange(count), np.zeros(size - count, int)])

    def pad(values):
        return jnp.asarray(np.asarray(values)[index], jnp.float32)

    inputs = jax.tree.map(pad, examples.inputs)
    weight = np.zeros(size, np.float32)
    weight[:count] = 1.0
    return Batch(inputs=inputs, target=pad(examples.target), weight=jnp.asarray(weight), count=count)


def zero_scales(examples: Examples | np.ndarray) -> tuple[float, float]:
    """(mean translation m, mean |rotation| rad) of the windows (or of their [N, 3] targets): the zero baseline's mean
    errors."""
    target = np.asarray(examples.target if isinstance(examples, Examples) else examples)
    return (max(float(np.mean(np.linalg.norm(target[:, :2], axis=1))), 1e-6),
            max(float(np.mean(np.abs(target[:, 2]))), 1e-6))


def _family_names(exact: bool) -> tuple[str, ...]:
    """The effects of one compiled full model: the ellipsoidal library, or every effect that composes with the exact
    limit surface (``limit_surface`` itself included)."""
    if not exact:
        return ELLIPSOID_EFFECTS
    return tuple(name for name in EFFECT_NAMES if name not in EFFECTS["limit_surface"].excludes)


_FULL_MODELS = {exact: effects_lib.compose(_family_names(exact)) for exact in (False, True)}
_TYPICAL = {name: {key: float(value) for key, value in EFFECTS[name].typical.items()} for name in EFFECT_NAMES}


def is_exact(candidate: Sequence[str]) -> bool:
    """Whether a candidate effect set uses the exact limit surface (and so the second compiled family)."""
    return "limit_surface" in candidate


def _params_from_scaled(scaled, mask, exact):
    """SI parameters of one candidate from its scaled variables and [E] effect mask."""
    return {name: {key: mask[i] * value * _TYPICAL[name][key] for key, value in scaled[name].items()}
            for i, name in enumerate(_family_names(exact))}


def _scaled_from_params(params):
    return {name: {key: value / _TYPICAL[name][key] for key, value in values.items()} for name, values in params.items()}


def _window_loss(params, inputs, target, scales, floors, exact):
    prediction = _FULL_MODELS[exact](params, inputs)
    translation = jnp.sum((prediction[:, :2] - target[:, :2]) ** 2, axis=-1) / scales[0] ** 2
    rotation = (prediction[:, 2] - target[:, 2]) ** 2 / scales[1] ** 2
    return jnp.sqrt(translation + floors[0] ** 2) + jnp.sqrt(rotation + floors[1] ** 2)


def _candidate_loss(scaled, mask, batch_inputs, target, weight, scales, floors, exact):
    losses = _window_loss(_params_from_scaled(scaled, mask, exact), batch_inputs, target, scales, floors, exact)
    return jnp.sum(weight * losses) / jnp.sum(weight)


@functools.partial(jax.jit, static_argnames=("learning_rate", "exact"))
def _optimise(scaled, masks, inputs, target, weights, scales, floors, steps, learning_rate, exact):
    # The number of steps is traced, not static: cold and warm fits share one compiled program. Every slot has its own
    # window weights [S, P] and error scales [S, 2] (a slot may fit a subset of the batch's windows).
    optimiser = optax.adam(lambda count: learning_rate * 0.5 * (1 + jnp.cos(jnp.pi * jnp.minimum(count, steps) / steps)))

    def total(scaled):
        losses = jax.vmap(_candidate_loss, in_axes=(0, 0, None, None, 0, 0, 0, None))(
            scaled, masks, inputs, target, weights, scales, floors, exact)
        return jnp.sum(losses), losses

    def project(scaled):
        params = jax.vmap(lambda s, m: _params_from_scaled(s, m, exact))(scaled, masks)
        return _scaled_from_params(effects_lib.project_params(params))

    def step(_, carry):
        scaled, state = carry
        gradient = jax.grad(lambda scaled: total(scaled)[0])(scaled)
        updates, state = optimiser.update(gradient, state, scaled)
        return project(optax.apply_updates(scaled, updates)), state

    scaled = project(scaled)
    scaled, _ = jax.lax.fori_loop(0, steps, step, (scaled, optimiser.init(scaled)))
    return scaled, total(scaled)[1]


@functools.partial(jax.jit, static_argnames="exact")
def _residual_jacobian(scaled, mask, inputs, target, scales, own, exact):
    """Scaled residuals [N, 3] of one candidate and their Jacobian [N, 3, P] by the flat variables, computed for the
    variables where ``own`` [P] is true (the candidate's own: the masked effects' variables have no effect) and zero
    elsewhere."""
    flat, unravel = ravel_pytree(scaled)

    def residuals(flat):
        prediction = _FULL_MODELS[exact](_params_from_scaled(unravel(flat), mask, exact), inputs)
        return (prediction - target) / jnp.stack([scales[0], scales[0], scales[1]])

    value = residuals(flat)

    # One forward-mode derivative per variable in sequence: jax.jacfwd's vmap over the basis gives some of the exact
    # limit surface's columns as zeros under jit (jax 0.10.2, XLA:CPU), one at a time is right. A variable the
    # candidate does not own skips its solve (one compiled program for every candidate of a family).
    def column(args):
        basis, needed = args
        return jax.lax.cond(needed, lambda: jax.jvp(residuals, (flat,), (basis,))[1], lambda: jnp.zeros_like(value))

    columns = jax.lax.map(column, (jnp.eye(len(flat), dtype=flat.dtype), own))
    return value, jnp.moveaxis(columns, 0, -1)


def _own_variables(scaled, candidate: Sequence[str]) -> np.ndarray:
    """[P] whether each flat variable of ``scaled`` (in :func:`ravel_pytree`'s order) belongs to the candidate's
    effects."""
    names = list(scaled)
    owner, _ = ravel_pytree({name: {key: np.full(np.shape(value), i, np.float32) for key, value in values.items()}
                             for i, (name, values) in enumerate(scaled.items())})
    return np.isin(np.asarray(owner).astype(int), [names.index(name) for name in candidate])


@functools.partial(jax.jit, static_argnames="exact")
def _physical_jacobian(scaled, mask, exact):
    flat, unravel = ravel_pytree(scaled)

    def values(flat):
        return effects_lib.physical_params(_params_from_scaled(unravel(flat), mask, exact))

    return values(flat), jax.jacfwd(lambda flat: ravel_pytree(values(flat))[0])(flat)


def _unflatten_like(tree, flat: np.ndarray):
    """``flat`` (the leaves of ``tree`` raveled in order, as :func:`ravel_pytree` does) in the structure of ``tree``."""
    leaves, treedef = jax.tree.flatten(tree)
    parts = np.split(flat, np.cumsum([np.size(leaf) for leaf in leaves])[:-1])
    return jax.tree.unflatten(treedef, [part.reshape(np.shape(leaf)) for part, leaf in zip(parts, leaves)])


def _masks(candidates: Sequence[Sequence[str]], exact: bool) -> np.ndarray:
    return np.array([[name in candidate for name in _family_names(exact)] for candidate in candidates], np.float32)


def _slots(count: int, family_size: int, exact: bool) -> int:
    """The candidate slots of one compiled fit: the ellipsoidal family's always its full size (its model is cheap, and
    each other count compiled its own program: 8-10 s each), the exact surface's a power of two up to the family's
    size (no exact limit surface solved for many padding slots when one candidate needs it)."""
    if not exact:
        return max(count, family_size)
    return max(count, min(family_size, 1 << max(count - 1, 0).bit_length()))


def _stack(trees):
    return jax.tree.map(lambda *leaves: jnp.stack(leaves), *trees)


def fit_effects(
    candidates: Sequence[Sequence[str]],
    examples: Examples,
    settings: FitConfig = FitConfig(),
    initial: Sequence[dict | None] | None = None,
    subsets: Sequence[np.ndarray | None] | None = None,
) -> list[FitResult]:
    """Fits every candidate effect set on ``examples`` at once.

    Args:
      candidates: effect-name sets, e.g. ``[("cof_offset",), ("cof_offset", "table_tilt")]``.
      examples: the fit windows.
      settings: optimiser settings.
      initial: per candidate, None or SI parameters {effect: {parameter: value}} to start from
        (effects not given start at "no effect"); a family whose every candidate starts from given parameters is
        fitted with ``settings.warm_steps``.
      subsets: per candidate, None (every window) or a [N] boolean mask of the windows it is fitted on, with the error
        scales of those windows: fits of one model on several groups of a data set (the mechanism check's, the
        per-group values') run as one compiled call on one batch.

    Returns:
      One :class:`FitResult` per candidate, in order.
    """
    candidates = [tuple(effects_lib.init_params(candidate)) for candidate in candidates]  # checked, in library order
    if not candidates:
        return []
    initial = list(initial or []) + [None] * (len(candidates) - len(initial or []))
    subsets = list(subsets or []) + [None] * (len(candidates) - len(subsets or []))
    batch = to_batch(examples)
    padding = len(batch.weight) - batch.count
    used = [np.ones(batch.count, bool) if subset is None else np.asarray(subset, bool) for subset in subsets]
    for k, subset in enumerate(used):
        if subset.shape != (batch.count,) or not subset.any():
            raise ValueError(f"subsets[{k}]: expected a [{batch.count}] boolean mask with a window in it")
    scales = [np.asarray(zero_scales(np.asarray(examples.target)[subset]), np.float32) for subset in used]
    floors = [np.array([1e-3 * settings.translation_floor_mm / scale[0],
                        math.radians(settings.rotation_floor_deg) / scale[1]], np.float32) for scale in scales]
    weights = [np.concatenate([subset, np.zeros(padding, bool)]).astype(np.float32) for subset in used]
    results: list[FitResult | None] = [None] * len(candidates)

    def fit_family(exact: bool) -> None:
        members = [k for k, candidate in enumerate(candidates) if is_exact(candidate) == exact]
        if not members:
            return
        names = _family_names(exact)
        slots = _slots(len(members), len(names), exact)
        group = [candidates[k] for k in members]
        masks = _masks(group + [()] * (slots - len(group)), exact)
        starts = []
        for start in [initial[k] for k in members] + [None] * (slots - len(members)):
            params = effects_lib.init_params(names)
            for name, values in (start or {}).items():
                if name in params:
                    params[name] = {key: jnp.asarray(value, jnp.float32) for key, value in values.items()}
            starts.append(_scaled_from_params(params))
        # Padding slots repeat the first member's windows and scales (their losses are not used).
        filled = members + [members[0]] * (slots - len(members))
        warm = all(initial[k] for k in members)
        scaled, losses = _optimise(_stack(starts), jnp.asarray(masks), batch.inputs, batch.target,
                                   jnp.asarray(np.stack([weights[k] for k in filled])),
                                   jnp.asarray(np.stack([scales[k] for k in filled])),
                                   jnp.asarray(np.stack([floors[k] for k in filled])),
                                   steps=settings.warm_steps if warm else settings.steps,
                                   learning_rate=settings.learning_rate, exact=exact)
        scaled, losses = jax.device_get((scaled, losses))
        for slot, k in enumerate(members):
            one = jax.tree.map(lambda leaf: leaf[slot], scaled)
            params = _params_from_scaled(one, masks[slot], exact)
            sequence = np.where(weights[k] > 0, np.concatenate([examples.sequence, np.full(padding, -1)]), -1)
            results[k] = FitResult(
                effects=candidates[k],
                params={name: {key: np.asarray(value) for key, value in params[name].items()}
                        for name in candidates[k]},
                loss=float(losses[slot]),
                compute_physical=functools.partial(_physical_with_std, one, masks[slot], batch,
                                                   jnp.asarray(scales[k]), floors[k], sequence, candidates[k], exact),
            )

    side_by_side(fit_family, (False, True))
    return results


def _physical_with_std(scaled, mask, batch, scales, floors, sequence, candidate, exact):
    own = jnp.asarray(_own_variables(scaled, candidate))
    residual, jacobian = jax.device_get(_in_chunks(
        lambda inputs, target: _residual_jacobian(scaled, jnp.asarray(mask), inputs, target, scales, own, exact),
        batch.inputs, batch.target))
    floors = np.asarray(floors, np.float64)
    used = sequence >= 0
    residual, jacobian, sequence = residual[used].astype(np.float64), jacobian[used].astype(np.float64), sequence[used]
    # Loss terms sqrt(|r_xy|^2 + f0^2) and sqrt(r_theta^2 + f1^2): gradients and Gauss-Newton curvatures.
    planar = residual[:, :2]
    spread_t = np.sum(planar ** 2, axis=1) + floors[0] ** 2
    spread_r = residual[:, 2] ** 2 + floors[1] ** 2
    d_loss = np.concatenate([planar / np.sqrt(spread_t)[:, None], (residual[:, 2] / np.sqrt(spread_r))[:, None]], 1)
    curvature = np.zeros((len(residual), 3, 3))
    curvature[:, :2, :2] = (np.eye(2)[None] * spread_t[:, None, None]
                            - planar[:, :, None] * planar[:, None, :]) / spread_t[:, None, None] ** 1.5
    curvature[:, 2, 2] = floors[1] ** 2 / spread_r ** 1.5
    count = len(residual)
    gradients = np.einsum("nkp,nk->np", jacobian, d_loss) / count
    hessian = np.einsum("nkp,nkl,nlq->pq", jacobian, curvature, jacobian) / count
    # The candidate's own variables (the masked ones have no effect and zero Jacobian).
    active = np.flatnonzero(np.any(jacobian != 0, axis=(0, 1)))
    ids, index = np.unique(sequence, return_inverse=True)
    per_sequence = np.zeros((len(ids), len(active)))
    np.add.at(per_sequence, index, gradients[:, active])
    h = hessian[np.ix_(active, active)]
    eigenvalues, eigenvectors = np.linalg.eigh(0.5 * (h + h.T))
    floor = max(1e-12, 1e-9 * float(np.max(np.abs(eigenvalues), initial=0.0)))
    inverse = eigenvectors @ np.diag(1.0 / np.maximum(np.abs(eigenvalues), floor)) @ eigenvectors.T
    meat = per_sequence.T @ per_sequence * len(ids) / max(len(ids) - 1, 1)
    covariance = inverse @ meat @ inverse
    value_tree, value_jacobian = jax.device_get(_physical_jacobian(scaled, jnp.asarray(mask), exact))
    value_jacobian = np.asarray(value_jacobian, np.float64)[:, active]
    std = np.sqrt(np.maximum(np.einsum("qp,pr,qr->q", value_jacobian, covariance, value_jacobian), 0.0))
    std_tree = _unflatten_like(value_tree, std)
    # A value whose derivative does not exist at the optimum (e.g. an axis at zero anisotropy) has no std.
    return {name: {key: {"value": float(value_tree[name][key]),
                         "std": float(std_tree[name][key]) if np.isfinite(std_tree[name][key]) else None}
                   for key in value_tree[name]} for name in candidate}


@functools.partial(jax.jit, static_argnames="exact")
def _predict_one(scaled, inputs, exact):
    return _FULL_MODELS[exact](_params_from_scaled(scaled, jnp.ones(len(_family_names(exact))), exact), inputs)


def _in_chunks(function, *trees):
    """``function(*trees)`` for trees of [P, ...] arrays of a padded batch (P a multiple of :data:`MIN_PADDED_SIZE`),
    computed :data:`MIN_PADDED_SIZE` windows at a time: a window's value depends on its own inputs only, and one chunk
    size compiles one program for every batch size (each size compiled its own, 2-5 s)."""
    size = len(jax.tree.leaves(trees[0])[0])
    chunks = [function(*jax.tree.map(lambda leaf: leaf[start:start + MIN_PADDED_SIZE], trees))
              for start in range(0, size, MIN_PADDED_SIZE)]
    return jax.tree.map(lambda *parts: jnp.concatenate(parts), *chunks)


def predict(results: Sequence[FitResult | None], examples: Examples) -> np.ndarray:
    """[M, N, 3] predictions on ``examples`` of fitted models (None: the plain Lynch model)."""
    batch = to_batch(examples)
    prediction = np.zeros((len(results), batch.count, 3))
    for k, result in enumerate(results):
        exact = result is not None and is_exact(result.effects)
        full = effects_lib.init_params(_family_names(exact))
        for name, values in (result.params if result is not None else {}).items():
            full[name] = {key: jnp.asarray(value, jnp.float32) for key, value in values.items()}
        scaled = _scaled_from_params(full)
        prediction[k] = np.asarray(_in_chunks(lambda inputs: _predict_one(scaled, inputs, exact), batch.inputs),
                                   np.float64)[:batch.count]
    return prediction
