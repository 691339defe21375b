"""The library of effects (:data:`EFFECTS`, in the order they are applied) and the functions on its names and
parameters."""

from __future__ import annotations

from collections.abc import Sequence

import jax

from pushjax.physics.effects import centre, exact_surface, forces, slide
from pushjax.physics.effects.types import Effect, Params

__all__ = ["EFFECTS", "EFFECT_NAMES", "ELLIPSOID_EFFECTS", "check_names", "compatible", "init_params", "needs_support",
           "physical_params", "project_params"]

EFFECTS: dict[str, Effect] = {
    effect.name: effect
    for effect in (centre.FRAME_OFFSET, centre.COF_OFFSET, forces.FRICTION_RATIO, forces.ANISOTROPIC_FRICTION,
                   forces.PUSHER_FRICTION, forces.TABLE_TILT, slide.INERTIA, centre.FRICTION_FIELD,
                   slide.FRICTION_SPEED, centre.PRESSURE_GRADIENT, centre.LEADING_EDGE, exact_surface.LIMIT_SURFACE)
}
"""The library, in the order in which effects are applied."""

EFFECT_NAMES = tuple(EFFECTS)
ELLIPSOID_EFFECTS = tuple(name for name in EFFECT_NAMES if EFFECTS[name].solve is None)
"""The effects that keep Lynch's ellipsoidal limit surface: any of them compose, and their zero parameters are
Lynch's model."""


def needs_support(names: Sequence[str]) -> bool:
    """Whether the named effects include one that solves the exact limit surface and so needs the object's support
    (:attr:`PushInputs.support_points`)."""
    return any(EFFECTS[name].solve is not None for name in names)


def compatible(names: Sequence[str]) -> bool:
    """Whether the named effects can be composed (no one excludes another)."""
    return not any(other in names for name in names for other in EFFECTS[name].excludes)


def check_names(names: Sequence[str]) -> tuple[str, ...]:
    """The named effects in library order; ValueError for a string, an unknown name or two that exclude each other."""
    if isinstance(names, str):
        raise ValueError(f"effects: expected a sequence of effect names, got the string {names!r}")
    unknown = [name for name in names if name not in EFFECTS]
    if unknown:
        raise ValueError(f"effects: unknown {', '.join(map(repr, unknown))}; known: {', '.join(EFFECT_NAMES)}")
    clashes = [f"{name} with {other}" for name in names for other in EFFECTS[name].excludes if other in names]
    if clashes:
        raise ValueError(f"effects: cannot compose {', '.join(clashes)} (see pushjax.physics.effects)")
    return tuple(name for name in EFFECT_NAMES if name in names)


def init_params(names: Sequence[str] = ELLIPSOID_EFFECTS) -> dict[str, Params]:
    """The "no effect" parameters of the named effects, {effect: {parameter: zeros}}."""
    return {name: EFFECTS[name].init() for name in check_names(names)}


def project_params(params_by_effect: dict[str, Params]) -> dict[str, Params]:
    """Parameters moved into their valid set (e.g. ``inverse_deceleration >= 0``)."""
    return {name: EFFECTS[name].project(params) for name, params in params_by_effect.items()}


def physical_params(params_by_effect: dict[str, Params]) -> dict[str, dict[str, jax.Array]]:
    """Readable values (names carry units) of the parameters, {effect: {value name: value}}."""
    return {name: EFFECTS[name].physical(params) for name, params in params_by_effect.items()}

