"""The effects that move the contact or the centre of friction: ``frame_offset``, ``cof_offset``, ``friction_field``,
``pressure_gradient`` and ``leading_edge`` (their physics: :mod:`pushjax.physics.effects`)."""

from __future__ import annotations

import jax
import jax.numpy as jnp

from pushjax.physics.effects.types import Effect, zeros
from pushjax.physics.effects.vectors import dot, rotate, safe_norm

__all__ = ["COF_OFFSET", "FRAME_OFFSET", "FRICTION_FIELD", "LEADING_EDGE", "MEAN_SQUARE_RADIUS", "PRESSURE_GRADIENT",
           "SECOND_MOMENT", "leading_edge_shift"]

SECOND_MOMENT = 9 / 16
"""Second moment of a plate's support per axis over l^2 (a uniform disc's: R^2 / 4 with l = 2 R / 3)."""
MEAN_SQUARE_RADIUS = 9 / 8
"""Mean squared distance of a plate's support from its centre over l^2 (a uniform disc's; 1.14 for a square)."""


def _frame_offset_modify(params, state, inputs):
    shift = -rotate(params["offset"], inputs.object_yaw)  # true outline minus annotated outline
    length, touching = safe_norm(state.normal)
    unit_normal = state.normal / jnp.where(touching, length, 1.0)[..., None]
    approach = dot(inputs.pusher_motion, unit_normal)
    moving_in = approach > 0

    def contact_fraction(gap):
        return jnp.where(moving_in, jnp.clip(gap / jnp.where(moving_in, approach, 1.0), 0.0, 1.0), 0.0)

    delay = contact_fraction(inputs.gap + dot(shift, unit_normal)) - contact_fraction(inputs.gap)
    slide = delay[..., None] * inputs.pusher_motion - shift
    along_side = slide - dot(slide, unit_normal)[..., None] * unit_normal
    # A contact that the annotation placed beyond the window (s = 0) but the true outline brings into it.
    reached = (delay < 0) & (state.s == 0)
    return state.replace(
        contact=state.contact + along_side,
        action=state.action - delay[..., None] * inputs.pusher_motion,
        s=jnp.where(reached, 1.0, state.s),
        centre=state.centre + shift,
    )


def _offset_physical(params):
    return {"offset_x_mm": 1e3 * params["offset"][..., 0], "offset_y_mm": 1e3 * params["offset"][..., 1]}


def _cof_offset_modify(params, state, inputs):
    offset = rotate(params["offset"], inputs.object_yaw)
    return state.replace(contact=state.contact - offset, centre=state.centre + offset)


def _friction_field_modify(params, state, inputs):
    gradient, curvature = params["gradient"], params["curvature"]
    x, y = inputs.object_position[..., 0], inputs.object_position[..., 1]
    # Gradient of log mu(p) = g . p + p^T H p / 2 where the object is.
    local = jnp.stack([gradient[..., 0] + curvature[..., 0] * x + curvature[..., 1] * y,
                       gradient[..., 1] + curvature[..., 1] * x + curvature[..., 2] * y], axis=-1)
    # Friction weighting exp(grad . r) moves the centre of friction by the support's second moment times the
    # gradient; the second moment per axis is SECOND_MOMENT l^2 (isotropic approximation).
    shift = SECOND_MOMENT * (state.l ** 2)[..., None] * local
    return state.replace(contact=state.contact - shift, centre=state.centre + shift)


def _friction_field_physical(params):
    gradient, curvature = params["gradient"], params["curvature"]
    return {"gradient_x_per_m": gradient[..., 0], "gradient_y_per_m": gradient[..., 1],
            "curvature_xx_per_m2": curvature[..., 0], "curvature_xy_per_m2": curvature[..., 1],
            "curvature_yy_per_m2": curvature[..., 2]}


def _pressure_gradient_modify(params, state, inputs):
    offset = rotate(params["offset"], inputs.object_yaw)
    # A linear pressure gradient that moves the centre of pressure by c leaves E|r - c|^2 = E|r|^2 - |c|^2 about
    # it; with E|r|^2 = MEAN_SQUARE_RADIUS l^2, l shrinks by the same factor's square root.
    share = jnp.sum(params["offset"] ** 2, axis=-1) / (MEAN_SQUARE_RADIUS * state.l ** 2)
    return state.replace(contact=state.contact - offset, centre=state.centre + offset,
                         l=state.l * jnp.sqrt(jnp.maximum(1.0 - share, 0.05)))


def _pressure_gradient_physical(params):
    return {**_offset_physical(params),
            "offset_over_l": jnp.hypot(params["offset"][..., 0], params["offset"][..., 1])}


def leading_edge_shift(lever: jax.Array, contact: jax.Array, normal: jax.Array, action: jax.Array, l: jax.Array,
                       mu: jax.Array, s: jax.Array = 1.0) -> jax.Array:
    """How far the pushing force tips the support pressure towards the leading edge (``leading_edge``,
    :mod:`pushjax.physics.effects`).

    Args:
      lever: [...] the table's friction coefficient times the pushing contact's height above the table, m.
      contact: [..., 2] contact point relative to the centre of friction, world axes, m.
      normal: [..., 2] inward surface normal (any length, 0 = no contact).
      action: [..., 2] pusher motion, m.
      l: [...] limit-surface ratio, m (> 0).
      mu: [...] pusher-object friction coefficient (>= 0).
      s: [...] contact indicator in [0, 1], scales the force.

    Returns:
      [..., 2] the centre of pressure's shift, world axes, m: ``lever`` times the pusher's force over the maximal
      friction force under Lynch's ellipsoid (on the limit surface, ``|f|^2 + (c x f)^2 / l^2 = 1``); zero where the
      pusher does not push.
    """
    cx, cy = contact[..., 0], contact[..., 1]
    nx, ny = normal[..., 0], normal[..., 1]
    ux, uy = action[..., 0], action[..., 1]
    l2 = l * l
    # The sticking force P u = l^2 u + (c . u) c, or the friction cone's boundary on its side when it leaves the cone.
    c_dot_u = cx * ux + cy * uy
    px, py = l2 * ux + c_dot_u * cx, l2 * uy + c_dot_u * cy
    cross = nx * py - ny * px
    inside = jnp.abs(cross) <= mu * (nx * px + ny * py)
    side_mu = jnp.where(cross > 0, mu, -mu)
    fx, fy = jnp.where(inside, px, nx - side_mu * ny), jnp.where(inside, py, ny + side_mu * nx)
    torque = cx * fy - cy * fx
    size = fx * fx + fy * fy + torque * torque / l2
    pushing = (ux * nx + uy * ny > 0) & (size > 0)
    scale = jnp.where(pushing, s / jnp.sqrt(jnp.where(pushing, size, 1.0)), 0.0)
    return jnp.asarray(lever)[..., None] * jnp.stack([fx * scale, fy * scale], axis=-1)


def _leading_edge_modify(params, state, inputs):
    shift = leading_edge_shift(params["lever"], state.contact, state.normal, state.action, state.l, state.mu, state.s)
    return state.replace(contact=state.contact - shift, centre=state.centre + shift)



FRAME_OFFSET = Effect(name="frame_offset", init=zeros(offset=(2,)), typical={"offset": 0.01},
                      modify=_frame_offset_modify, physical=_offset_physical, per_object=True)
COF_OFFSET = Effect(name="cof_offset", init=zeros(offset=(2,)), typical={"offset": 0.01}, modify=_cof_offset_modify,
                    physical=_offset_physical, per_object=True)
FRICTION_FIELD = Effect(name="friction_field", init=zeros(gradient=(2,), curvature=(3,)),
                        typical={"gradient": 3.0, "curvature": 30.0}, modify=_friction_field_modify,
                        physical=_friction_field_physical)
PRESSURE_GRADIENT = Effect(name="pressure_gradient", init=zeros(offset=(2,)), typical={"offset": 0.01},
                           modify=_pressure_gradient_modify, physical=_pressure_gradient_physical, per_object=True)
LEADING_EDGE = Effect(name="leading_edge", init=zeros(lever=()), typical={"lever": 0.003}, modify=_leading_edge_modify,
                      physical=lambda p: {"lever_mm": 1e3 * p["lever"]})
