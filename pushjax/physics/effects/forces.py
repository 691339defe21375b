"""The effects on the forces of the quasi-static balance: the support's friction (``friction_ratio``,
``anisotropic_friction``), the pusher's (``pusher_friction``) and gravity's pull on a tilted table (``table_tilt``);
their physics: :mod:`pushjax.physics.effects`."""

from __future__ import annotations

import jax.numpy as jnp

from pushjax.physics.effects.types import Effect, zeros
from pushjax.physics.effects.vectors import safe_norm

__all__ = ["ANISOTROPIC_FRICTION", "FRICTION_RATIO", "PUSHER_FRICTION", "TABLE_TILT"]

_MAX_DRIFT_FORCE = 0.95
"""Largest in-plane force over the maximal friction force: beyond 1 the object slides away unpushed."""


def _friction_ratio_modify(params, state, inputs):
    return state.replace(l=state.l * jnp.exp(params["log_scale"]))


def _anisotropic_friction_modify(params, state, inputs):
    a, b = params["log_metric"][..., 0], params["log_metric"][..., 1]
    # (a + ib) e^{2i yaw}: the traceless symmetric matrix turned into world axes.
    cos, sin = jnp.cos(2 * inputs.object_yaw), jnp.sin(2 * inputs.object_yaw)
    a_world, b_world = a * cos - b * sin, a * sin + b * cos
    # exp(S) = cosh(r) I + sinh(r) / r S, since S^2 = r^2 I.
    r2 = a * a + b * b
    small = r2 < 1e-8
    r = jnp.sqrt(jnp.where(small, 1.0, r2))
    cosh_r = jnp.where(small, 1 + r2 / 2, jnp.cosh(r))
    sinhc_r = jnp.where(small, 1 + r2 / 6, jnp.sinh(r) / r)
    # The only effect that sets the metric, so it replaces the identity.
    return state.replace(metric=(cosh_r + sinhc_r * a_world, sinhc_r * b_world, cosh_r - sinhc_r * a_world))


def _anisotropic_friction_physical(params):
    a, b = params["log_metric"][..., 0], params["log_metric"][..., 1]
    r = jnp.sqrt(a * a + b * b)
    # Eigenvector of S with eigenvalue +r (weaker friction) at atan2(b, a) / 2; the stronger axis is
    # perpendicular to it.
    axis = jnp.degrees(0.5 * jnp.arctan2(b, a)) + 90.0
    axis = jnp.where(axis > 90.0, axis - 180.0, axis)
    return {"ratio": jnp.exp(r), "strong_axis_deg": axis}


def _pusher_friction_modify(params, state, inputs):
    return state.replace(mu=state.mu * jnp.exp(params["log_scale"]))


def _table_tilt_modify(params, state, inputs):
    return state.replace(drift_force=state.drift_force + params["drift_force"])


def _table_tilt_project(params):
    force = params["drift_force"]
    length, _ = safe_norm(force)
    return {"drift_force": force * jnp.minimum(1.0, _MAX_DRIFT_FORCE / jnp.maximum(length, 1e-12))[..., None]}


def _table_tilt_physical(params):
    force = params["drift_force"]
    return {"drift_over_friction": jnp.hypot(force[..., 0], force[..., 1]),
            "downhill_azimuth_deg": jnp.degrees(jnp.arctan2(force[..., 1], force[..., 0]))}



FRICTION_RATIO = Effect(name="friction_ratio", init=zeros(log_scale=()), typical={"log_scale": 0.3},
                        modify=_friction_ratio_modify, physical=lambda p: {"scale": jnp.exp(p["log_scale"])},
                        per_object=True)
ANISOTROPIC_FRICTION = Effect(name="anisotropic_friction", init=zeros(log_metric=(2,)), typical={"log_metric": 0.5},
                              modify=_anisotropic_friction_modify, physical=_anisotropic_friction_physical,
                              general_solver=True)
PUSHER_FRICTION = Effect(name="pusher_friction", init=zeros(log_scale=()), typical={"log_scale": 0.5},
                         modify=_pusher_friction_modify, physical=lambda p: {"mu_scale": jnp.exp(p["log_scale"])})
TABLE_TILT = Effect(name="table_tilt", init=zeros(drift_force=(2,)), typical={"drift_force": 0.2},
                    modify=_table_tilt_modify, project=_table_tilt_project, physical=_table_tilt_physical,
                    general_solver=True)
