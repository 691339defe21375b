"""The solves of the pushing model: Lynch's ellipsoid generalised to a force metric and a drift force
(:func:`limit_surface_predict`), and the model augmented by named effects (:func:`compose`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import jax
import jax.numpy as jnp

from pushjax.physics import lynch
from pushjax.physics.effects.registry import EFFECTS, check_names
from pushjax.physics.effects.types import ModelState, Params, PushInputs
from pushjax.physics.effects.vectors import safe_sqrt

__all__ = ["compose", "limit_surface_predict"]


def limit_surface_predict(contact, normal, action, l, mu, s=1.0, metric=None, drift_force=None) -> jax.Array:
    """Object twist under a generalised ellipsoidal limit surface (see :mod:`pushjax.physics.effects`).

    Args:
      contact: [..., 2] contact point relative to the centre of friction, m.
      normal: [..., 2] inward surface normal (any length, 0 = no contact).
      action: [..., 2] pusher motion, m.
      l: [...] limit-surface ratio m_max / f_max, m (> 0).
      mu: [...] pusher-object friction coefficient (>= 0).
      s: [...] contact indicator in [0, 1], scales the twist.
      metric: (A_xx, A_xy, A_yy), each [...], the symmetric positive definite force metric (world
        axes) normalised so that isotropic friction is the identity; None for the identity.
      drift_force: [..., 2] constant in-plane force at the centre over the maximal friction force
        (|.| < 1); None for none.

    Returns:
      [..., 3] twist (dx m, dy m, dtheta rad) of the centre of friction; equals
      ``lynch.predict(contact, normal, action, l, mu, s)`` for the identity metric and no drift force.
    """
    cx, cy = contact[..., 0], contact[..., 1]
    nx, ny = normal[..., 0], normal[..., 1]
    ux, uy = action[..., 0], action[..., 1]
    if metric is None:
        one, zero = jnp.ones_like(cx), jnp.zeros_like(cx)
        metric = (one, zero, one)
    axx, axy, ayy = metric
    gx, gy = (jnp.zeros_like(cx), jnp.zeros_like(cx)) if drift_force is None else (
        drift_force[..., 0], drift_force[..., 1])
    b = 1.0 / (l * l)
    # Contact-velocity map M = A_f + b (k x c)(k x c)^T and its adjugate.
    mxx, mxy, myy = axx + b * cy * cy, axy - b * cx * cy, ayy + b * cx * cx
    det = mxx * myy - mxy * mxy

    def adjugate(vx, vy):
        return myy * vx - mxy * vy, -mxy * vx + mxx * vy

    # Contact velocity caused by the drift force alone: w = A_f g.
    wx, wy = axx * gx + axy * gy, axy * gx + ayy * gy
    g_metric = gx * wx + gy * wy
    adj_ux, adj_uy = adjugate(ux, uy)
    adj_wx, adj_wy = adjugate(wx, wy)
    q = g_metric - (wx * adj_wx + wy * adj_wy) / det
    free = jnp.maximum(1.0 - q, 1e-6)
    sigma = safe_sqrt(ux * adj_ux + uy * adj_uy)  # sqrt(det u^T M^-1 u)
    root = jnp.sqrt(free * det)

    # Sticking force f ∝ sqrt((1 - q) det) adj(M) u - sigma adj(M) w, and the cone test.
    fx, fy = root * adj_ux - sigma * adj_wx, root * adj_uy - sigma * adj_wy
    pushing = ux * nx + uy * ny > 0
    inside = jnp.abs(nx * fy - ny * fx) <= mu * (nx * fx + ny * fy)
    sticking = pushing & inside
    # Sticking twist: (A_f, b c x) applied to adj(M) u / det, plus the drift term.
    drift = sigma / root
    qx, qy = gx - adj_wx / det, gy - adj_wy / det
    q_torque = -(cx * adj_wy - cy * adj_wx) / det
    stick = (
        (axx * adj_ux + axy * adj_uy) / det + drift * (axx * qx + axy * qy),
        (axy * adj_ux + ayy * adj_uy) / det + drift * (axy * qx + ayy * qy),
        b * (cx * adj_uy - cy * adj_ux) / det + drift * b * q_torque,
    )

    # Slipping along the friction-cone boundary on the side where the sticking force leaves it.
    side_mu = jnp.where(nx * fy - ny * fx > 0, mu, -mu)
    bx, by = nx - side_mu * ny, ny + side_mu * nx
    mbx, mby = mxx * bx + mxy * by, mxy * bx + myy * by
    gamma = bx * mbx + by * mby  # f_b^T M f_b, zero only without contact
    beta = bx * wx + by * wy
    has_boundary = gamma > 0
    safe_gamma = jnp.where(has_boundary, gamma, 1.0)
    lam = (-beta + jnp.sqrt(jnp.maximum(beta * beta + safe_gamma * (1.0 - g_metric), 1e-12 * safe_gamma))) / safe_gamma
    normal_velocity = (lam * mbx + wx) * nx + (lam * mby + wy) * ny
    slipping = pushing & ~sticking & has_boundary & (normal_velocity > 0)
    ratio = jnp.where(slipping, (ux * nx + uy * ny) / jnp.where(slipping, normal_velocity, 1.0), 0.0)
    slip = (
        ratio * (lam * (axx * bx + axy * by) + wx),
        ratio * (lam * (axy * bx + ayy * by) + wy),
        ratio * lam * b * (cx * by - cy * bx),
    )
    twist = [jnp.where(sticking, st, jnp.where(slipping, sl, 0.0)) for st, sl in zip(stick, slip)]
    return jnp.stack(twist, axis=-1) * jnp.asarray(s)[..., None]




def compose(names: Sequence[str]) -> Callable[[dict[str, Params], PushInputs], jax.Array]:
    """The pushing model augmented by the named effects (applied in library order).

    Args:
      names: effect names from :data:`EFFECT_NAMES`; empty gives the plain Lynch model.

    Returns:
      ``predict(params_by_effect, inputs) -> [..., 3]`` twist of the nominal centre of mass (dx m,
      dy m, dtheta rad, world axes) over the window; ``params_by_effect`` holds one parameter dict
      per composed effect (see :func:`init_params`).
    """
    names = check_names(names)
    general = any(EFFECTS[name].general_solver for name in names)
    solvers = [name for name in names if EFFECTS[name].solve is not None]

    def predict(params_by_effect: dict[str, Params], inputs: PushInputs) -> jax.Array:
        missing = [name for name in names if name not in params_by_effect]
        if missing:
            raise ValueError(f"params_by_effect: missing parameters of {', '.join(missing)}")
        contact = jnp.asarray(inputs.contact)
        batch = jnp.broadcast_shapes(contact.shape[:-1], jnp.shape(inputs.normal)[:-1],
                                     jnp.shape(inputs.action)[:-1], jnp.shape(inputs.l), jnp.shape(inputs.mu),
                                     jnp.shape(inputs.s), jnp.shape(inputs.object_yaw))
        one = jnp.ones(batch, contact.dtype)
        state = ModelState(
            contact=contact * one[..., None], normal=jnp.asarray(inputs.normal) * one[..., None],
            action=jnp.asarray(inputs.action) * one[..., None], l=inputs.l * one, mu=inputs.mu * one,
            s=inputs.s * one, centre=jnp.zeros(batch + (2,), contact.dtype),
            metric=(one, 0 * one, one), drift_force=jnp.zeros(batch + (2,), contact.dtype))
        for name in names:
            if EFFECTS[name].modify is not None:
                state = EFFECTS[name].modify(params_by_effect[name], state, inputs)
        if solvers:
            twist = EFFECTS[solvers[0]].solve(params_by_effect[solvers[0]], state, inputs)
        elif general:
            twist = limit_surface_predict(state.contact, state.normal, state.action, state.l, state.mu, state.s,
                                          state.metric, state.drift_force)
        else:
            twist = lynch.predict(state.contact, state.normal, state.action, state.l, state.mu, state.s)
        # The twist is about the centre of friction; the nominal centre of mass is at -centre from it.
        omega = twist[..., 2]
        twist = jnp.stack([twist[..., 0] + omega * state.centre[..., 1],
                           twist[..., 1] - omega * state.centre[..., 0], omega], axis=-1)
        # Corrections (the slide after the pusher stops) start from the twist of the push itself and add up: a
        # slide is driven by the speed the push gave the object, not by another correction's slide.
        pushed = twist
        for name in names:
            if EFFECTS[name].correct is not None:
                twist = twist + (EFFECTS[name].correct(params_by_effect[name], pushed, state, inputs) - pushed)
        return twist

    return predict
