"""The ``limit_surface`` effect: the exact limit surface of the object's support (:mod:`pushjax.physics.limit_surface`)
instead of Lynch's ellipsoid, with the support's pressure (:func:`support_pressure`); its physics:
:mod:`pushjax.physics.effects`."""

from __future__ import annotations

import jax
import jax.numpy as jnp

from pushjax.physics import limit_surface as exact_limit_surface
from pushjax.physics.effects.types import Effect, Params, zeros
from pushjax.physics.effects.vectors import rotate

__all__ = ["LIMIT_SURFACE", "LIMIT_SURFACE_ITERATIONS", "support_pressure"]

LIMIT_SURFACE_ITERATIONS = (5, 6)
"""Newton iterations (sticking, slipping) of ``limit_surface``'s solve: with the support cells' patches (radius about an
eighth of the plate's) the twists of the loop's windows agree with 20 iterations' to 1e-7 relative in float32 from 4
and 5 on; one more each for margin (fewer iterations are the fit's largest saving)."""


def support_pressure(params: Params, points: jax.Array, area: jax.Array, feet: jax.Array | None = None) -> jax.Array:
    """[..., K] normalised support pressure of ``limit_surface`` (see :mod:`pushjax.physics.effects`).

    Args:
      params: ``limit_surface``'s parameters (``rim`` [...], ``feet`` [...] in [0, 1]).
      points: [..., K, 2] support points, object axes, m.
      area: [..., K] their area weights (zero for the hull's corners).
      feet: [..., K] the loads on the hull's corners (:attr:`PushInputs.support_feet`); None: no corners, ``feet``
        must then be 0.
    """
    area = area / jnp.sum(area, axis=-1, keepdims=True)
    square = jnp.sum(points ** 2, axis=-1)
    mean_square = jnp.sum(area * square, axis=-1, keepdims=True)
    log_pressure = jnp.asarray(params["rim"])[..., None] * (square / mean_square - 1.0)
    log_pressure = jnp.where(area > 0, log_pressure, -jnp.inf)
    weights = area * jnp.exp(log_pressure - jnp.max(log_pressure, axis=-1, keepdims=True))
    footprint = weights / jnp.sum(weights, axis=-1, keepdims=True)
    if feet is None:
        return footprint
    share = jnp.asarray(params["feet"])[..., None]
    return (1.0 - share) * footprint + share * feet


def _limit_surface_solve(params, state, inputs):
    if inputs.support_points is None or inputs.support_weights is None or inputs.patch_radius is None:
        raise ValueError("limit_surface: needs PushInputs.support_points, support_weights and patch_radius "
                         "(pushjax.geometry.support_cells)")
    points = jnp.asarray(inputs.support_points)
    feet = None if inputs.support_feet is None else jnp.asarray(inputs.support_feet)
    pressure = support_pressure(params, points, jnp.asarray(inputs.support_weights), feet)
    # World axes. The support is centred where the other effects put the centre of friction (cof_offset moves the
    # pressure with it, frame_offset the whole plate), and the contact is relative to that centre.
    world = rotate(points, jnp.asarray(inputs.object_yaw)[..., None])
    return exact_limit_surface.predict(state.contact, state.normal, state.action, state.mu, world, pressure,
                                       inputs.patch_radius, state.s, state.drift_force,
                                       stick_iterations=LIMIT_SURFACE_ITERATIONS[0],
                                       slip_iterations=LIMIT_SURFACE_ITERATIONS[1])


def _limit_surface_physical(params):
    return {"rim": params["rim"], "feet": params["feet"]}


def _limit_surface_project(params):
    return {**params, "feet": jnp.clip(params["feet"], 0.0, 1.0)}


LIMIT_SURFACE = Effect(name="limit_surface", init=zeros(rim=(), feet=()), typical={"rim": 1.0, "feet": 0.3},
                       physical=_limit_surface_physical, project=_limit_surface_project, solve=_limit_surface_solve,
                       excludes=("friction_ratio", "pressure_gradient", "anisotropic_friction"), per_object=True)
