"""The limit surface's shape, measured by the force sensor: the torque-to-force ratio of force-motion pairs.

Lynch's model matches the limit surface of the support by an ellipsoid through its two intercepts, so its
torque-to-force ratio ``c`` is ``l`` for every twist. The exact surface of a pressure over the footprint is not an
ellipsoid: near pure translation its ratio follows the pressure's second moment along the motion (a uniform disc:
0.75 ``l``). The force sensor sees this directly: every window pairs the wrench the pusher applied
(:func:`pushjax.loop.force.window_wrenches`) with the twist the object made, and quasi-static pushing puts that twist
normal to the limit surface at that wrench — no model of the pusher contact is involved. :func:`limit_surface_shape`
measures ``c_eff / l`` per regime of the twist and sets the models' predictions at the same twists beside it
(:func:`shape_models`): a model whose surface has the right shape matches the sensor in every regime.
"""

from __future__ import annotations

import dataclasses
import math

import jax.numpy as jnp
import numpy as np

from pushjax import planar
from pushjax import stats as stats_lib
from pushjax.loop.windows import Examples
from pushjax.physics import effects as effects_lib
from pushjax.physics import limit_surface as limit_surface_lib


SHAPE_REGIMES = ((0.0, 0.3), (0.3, 1.0), (1.0, math.inf))
"""Ranges of ``|omega| l / |v|`` (rotation against translation of a window's twist) in which the limit surface's
shape is measured: near pure translation, mixed, near pure rotation."""
MIN_SHAPE_WINDOWS = 20
"""Windows a regime needs for its ratio."""


@dataclasses.dataclass(frozen=True)
class LimitSurfaceShape:
    """The limit surface's torque-to-force ratio, measured from force-motion pairs and predicted by models.

    On the limit surface the object's twist ``V`` is normal to the surface at the applied wrench ``W``; Lynch's
    ellipsoid gives ``W ∝ (v_x, v_y, omega c^2)`` with one ``c`` (``l``) for every twist, so
    ``c_eff^2 = |m| |v| / (|omega| |F|)`` is ``l^2`` everywhere. The exact surface of a pressure over the footprint
    bends: near pure translation ``c_eff`` follows the pressure's second moment along the motion, not ``l``. Each
    window gives one pair (its mean applied wrench, :func:`window_wrenches`, and its measured twist); per regime of
    :data:`SHAPE_REGIMES`, ``c_eff / l`` is the ratio of sums over its windows (each normalised by its object's ``l``).

    Attributes:
      regimes: the regimes' ``|omega| l / |v|`` ranges.
      measured: per regime {"c_over_l", "std" (sequence bootstrap), "n_windows", "n_sequences"}, or None with fewer
        than :data:`MIN_SHAPE_WINDOWS` windows.
      models: {model: [per regime c_eff / l or None]} of the named models' wrenches at the same twists.
      rim_from_force: the support pressure's rim loading that the force data alone gives (:func:`rim_from_force`),
        {"value", "std"}, or None.
    """

    regimes: list[tuple[float, float]]
    measured: list[dict | None]
    models: dict[str, list[float | None]]
    rim_from_force: dict[str, float] | None = None


def limit_surface_shape(twist: np.ndarray, wrench: np.ndarray, l: np.ndarray, sequence: np.ndarray,
                        models: dict[str, np.ndarray], n_bootstrap: int = 1000, seed: int = 0) -> LimitSurfaceShape:
    """Measures :class:`LimitSurfaceShape` from windows' force-motion pairs.

    Args:
      twist: [N, 3] each window's displacement along the object's axes (m) and rotation (rad).
      wrench: [N, 3] each window's mean applied wrench (:func:`window_wrenches`; NaN rows are left out).
      l: [N] each window's object's limit-surface ratio, m.
      sequence: [N] push sequence of each window (the bootstrap's unit).
      models: {name: [N, 3] wrench the model predicts at ``twist`` (any positive scale)}.
      n_bootstrap, seed: the sequence bootstrap of the measured ratios.
    """
    twist, wrench, l = np.asarray(twist, np.float64), np.asarray(wrench, np.float64), np.asarray(l, np.float64)
    regimes = _regimes(twist, wrench, l)
    measured = []
    for inside in regimes:
        if inside is None:
            measured.append(None)
            continue
        torque, force = (values[inside] for values in _sums(wrench, twist, l))
        ids, index = np.unique(sequence[inside], return_inverse=True)
        per_sequence = np.zeros((len(ids), 2))
        np.add.at(per_sequence, index, np.column_stack([torque, force]))
        counts = stats_lib.resample_sequences(len(ids), n_bootstrap, seed).astype(np.float64)
        resampled = counts @ per_sequence
        ratios = np.sqrt(resampled[:, 0] / np.maximum(resampled[:, 1], 1e-300))
        measured.append({"c_over_l": float(np.sqrt(torque.sum() / force.sum())), "std": float(np.std(ratios, ddof=1)),
                         "n_windows": int(np.count_nonzero(inside)), "n_sequences": len(ids)})
    return LimitSurfaceShape(regimes=list(SHAPE_REGIMES), measured=measured,
                             models={name: _model_ratios(regimes, np.asarray(model, np.float64), twist, l)
                                     for name, model in models.items()})


def _regimes(twist: np.ndarray, wrench: np.ndarray, l: np.ndarray) -> list[np.ndarray | None]:
    """Per regime of :data:`SHAPE_REGIMES`, [N] which windows with a force reading and motion fall in it (None: fewer
    than :data:`MIN_SHAPE_WINDOWS`)."""
    speed, spin = np.linalg.norm(twist[:, :2], axis=1), np.abs(twist[:, 2])
    usable = np.all(np.isfinite(wrench), axis=1) & (speed > 0) & (spin > 0)
    regime_of = spin * l / np.where(speed > 0, speed, 1.0)
    masks = [usable & (regime_of >= low) & (regime_of < high) for low, high in SHAPE_REGIMES]
    return [mask if np.count_nonzero(mask) >= MIN_SHAPE_WINDOWS else None for mask in masks]


def _sums(wrench: np.ndarray, twist: np.ndarray, l: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """[N] ``|m| |v| / l`` and ``|omega| |F| l``: their sums' ratio is ``(c_eff / l)^2``."""
    return (np.abs(wrench[:, 2]) * np.linalg.norm(twist[:, :2], axis=1) / l,
            np.abs(twist[:, 2]) * np.linalg.norm(wrench[:, :2], axis=1) * l)


def _model_ratios(regimes: list[np.ndarray | None], wrench: np.ndarray, twist: np.ndarray,
                  l: np.ndarray) -> list[float | None]:
    torque, force = _sums(wrench, twist, l)
    return [None if inside is None else float(np.sqrt(torque[inside].sum() / force[inside].sum()))
            for inside in regimes]


RIM_GRID = np.linspace(-10.0, 10.0, 41)
"""Pressure rim loadings (``pushjax.physics.effects.support_pressure``) searched by :func:`rim_from_force`."""


def rim_from_force(examples: Examples, measured: LimitSurfaceShape) -> dict[str, float] | None:
    """The support pressure's rim loading whose exact limit surface matches the sensor's ratios.

    Least squares over the measured regimes, each weighted by its standard error (regimes are disjoint sets of windows,
    taken as independent), on :data:`RIM_GRID` refined by a parabola through the best point and its neighbours; the
    standard error is where chi-square rises by 1.

    Returns:
      {"value", "std"}, or None when fewer than two regimes are measured or the best fit is at the grid's edge.
    """
    known = [k for k, entry in enumerate(measured.measured) if entry is not None]
    if len(known) < 2:
        return None
    twist, inputs = measured_twists(examples), examples.inputs
    l = np.asarray(inputs.l, np.float64)
    regimes = _regimes(twist, np.asarray(examples.wrench, np.float64), l)
    target = np.array([measured.measured[k]["c_over_l"] for k in known])
    std = np.array([max(measured.measured[k]["std"], 1e-9) for k in known])
    chi_square = []
    for rim in RIM_GRID:
        ratios = _model_ratios(regimes, _exact_wrench(twist, inputs, rim), twist, l)
        chi_square.append(float(np.sum(((np.array([ratios[k] for k in known]) - target) / std) ** 2)))
    best = int(np.argmin(chi_square))
    if best in (0, len(RIM_GRID) - 1):
        return None
    curvature, slope, _ = np.polyfit(RIM_GRID[best - 1:best + 2], chi_square[best - 1:best + 2], 2)
    if not curvature > 0:
        return None
    return {"value": float(-slope / (2 * curvature)), "std": float(1.0 / np.sqrt(curvature))}


def _exact_wrench(twist: np.ndarray, inputs, rim: float, feet: float = 0.0) -> np.ndarray:
    """[N, 3] the exact limit surface's wrench at ``twist`` for the pressure of ``limit_surface`` with rim loading
    ``rim`` and a share ``feet`` on the hull's corners (both 0: uniform)."""
    weights = np.asarray(inputs.support_weights)
    if rim != 0 or feet != 0:
        corners = None if inputs.support_feet is None else jnp.asarray(inputs.support_feet)
        weights = np.asarray(effects_lib.support_pressure({"rim": rim, "feet": feet},
                                                          jnp.asarray(inputs.support_points), jnp.asarray(weights),
                                                          corners))
    return np.asarray(limit_surface_lib.dissipation(twist, inputs.support_points, weights, inputs.patch_radius)[1],
                      np.float64)


def shape_models(examples: Examples, fitted: dict[str, dict] | None) -> dict[str, np.ndarray]:
    """[N, 3] wrenches the models predict at the windows' measured twists (:func:`limit_surface_shape`'s ``models``).

    Args:
      examples: the windows.
      fitted: the selected model's SI parameters {effect: {parameter: value}} (None: nothing selected); a selected
        ``friction_ratio`` scales the ellipsoid's ``l``, a selected ``limit_surface`` gives its fitted pressure.
    """
    twist = measured_twists(examples)
    inputs = examples.inputs
    l = np.asarray(inputs.l, np.float64)
    models = {"Lynch's ellipsoid (l)": np.column_stack([twist[:, :2], twist[:, 2] * l ** 2])}
    fitted = fitted or {}
    if "friction_ratio" in fitted:
        scale = float(np.exp(fitted["friction_ratio"]["log_scale"]))
        models[f"ellipsoid, fitted friction_ratio ({scale:.3g} l)"] = np.column_stack(
            [twist[:, :2], twist[:, 2] * (scale * l) ** 2])
    models["exact surface, uniform pressure"] = _exact_wrench(twist, inputs, 0.0)
    if "limit_surface" in fitted:
        rim, feet = (float(fitted["limit_surface"][name]) for name in ("rim", "feet"))
        models[f"exact surface, fitted pressure (rim {rim:.3g}, feet {feet:.3g})"] = _exact_wrench(twist, inputs, rim,
                                                                                                  feet)
    return models


def measured_twists(examples: Examples) -> np.ndarray:
    """[N, 3] each window's measured displacement along the object's axes at its start (m) and rotation (rad)."""
    target = np.asarray(examples.target, np.float64)
    return np.column_stack([planar.rotate(target[:, :2], -np.asarray(examples.inputs.object_yaw, np.float64)),
                            target[:, 2]])
