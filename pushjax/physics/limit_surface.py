"""The exact quasi-static limit surface of a support made of weighted points, differentiable.

Lynch's model (:mod:`pushjax.physics.lynch`) approximates the support friction by an ellipsoidal limit
surface matched at pure translation and pure rotation. This module solves the exact one for a planar
object resting on ``K`` support points ``r_k`` with pressure weights ``p_k`` (normalised to sum 1), each
a small disc patch of radius ``rho``. With the twist ``V = (v_x, v_y, omega)`` of the frame origin and the
velocity ``v_k = v + omega k x r_k`` of support point ``k``, the frictional dissipation, in units of the
total support friction force ``mu_s m g`` times velocity, is

    D(V) = sum_k p_k sqrt(|v_k|^2 + (rho omega)^2),

smooth, convex and positively homogeneous of degree 1 for ``rho > 0`` (``rho -> 0`` gives point
supports). The friction wrench is ``grad D(V)`` (maximal dissipation): force in units of ``mu_s m g``,
torque in those units times the length unit. A constant in-plane drift force ``g`` at the origin (in
the same units, strictly inside the limit surface, e.g. ``|g| < 1`` with the origin at the supports'
weighted centroid) replaces ``D`` by ``D(V) - g . v``.

A point pusher at ``c`` with inward normal ``n``, Coulomb coefficient ``mu`` and motion ``u``:

* sticking: the contact point moves with the pusher, ``J V = u`` with ``J V = v + omega k x c``. The
  twists doing so are ``V(t) = (u - t k x c, t)`` (rotation about the contact at rate ``t``), and
  quasi-static equilibrium with the least dissipation is ``min_t D(V(t)) - g . v(t)``, a convex 1-D
  problem. The pusher force is ``lambda = grad_v D - g``; the contact sticks if ``lambda`` lies in the
  friction cone ``|n x lambda| <= mu (n . lambda)`` and the pusher pushes (``u . n > 0``).
* slipping: the force lies on the cone boundary ``f_b = n +- mu (k x n)`` on the side where the
  sticking force left the cone, so ``grad D(V) - G = nu (f_b, c x f_b)``, ``nu > 0``. The twist's
  direction is ``argmin D(V) - g . v`` subject to ``f_b . J V = 1`` (a convex 2-D problem; its
  multiplier is ``nu = D - g . v > 0``); its length makes the contact's normal velocity equal the
  pusher's, and there is no motion if that normal velocity is not positive (as in ``lynch``).

How it differs from Lynch's ellipsoid (tested in ``tests/physics/test_limit_surface.py``): the torque
intercept (pure rotation about the supports' weighted geometric median, zero force) is
``m_max = sum_k p_k sqrt(|r_k - median|^2 + rho^2)``, which is where the ellipsoid with ``l = m_max`` agrees;
near pure translation along ``x`` the exact surface is the ellipsoid with ``l_eff^2 = Var(x_k) + rho^2`` (the
supports' second moment along the motion), smaller: a uniform disc of radius R has
``m_max = 2R/3`` but ``l_eff = R/2``, so a slightly off-centre push at the rim turns it about 16 % more than
Lynch's model says. The stick/slip switch is continuous in the twist and the force, not in their derivatives.
:func:`dissipation` evaluates ``D`` and the wrench for given twists.

Both problems are written with the contact-point velocity ``a = a_0 + sigma e`` (``e`` a unit vector,
``sigma`` the tangential slip; ``a = u / |u|`` fixed when sticking) and the rotation rate ``t``, so that
``z_k = (a - t k x d_k, rho t)`` with ``d_k = r_k - c`` is the (3-vector) velocity of patch ``k`` and
``D = sum_k p_k |z_k|``. They are solved by Newton's method with a fixed number of iterations, started
from the ellipsoidal (Lynch) solution about the supports' centroid, and safeguarded: a step is
shortened so that no patch velocity ``z_k`` changes by more than :data:`STEP_LIMIT` times its length
(beyond that the linearised unit vector ``z_k / |z_k|``, i.e. the Newton model, is meaningless; this
keeps Newton from overshooting the sharp kinks of small patches). Derivatives are implicit (a
``jax.custom_jvp`` on the solve from its optimality condition ``grad_x f = 0``), never through the
iterations.

Conventions as in :mod:`pushjax.physics.lynch`: points and directions are 2-vectors in the last axis,
relative to a common origin, in any frame; leading batch axes broadcast (support arrays carry a
support axis ``K`` before that). ``normal`` points into the object, any length, zero means no contact.
A point pusher cannot pull: ``u . n <= 0`` gives zero motion. The model is homogeneous of degree 1 in
``action`` and unit-agnostic (one length unit for points, actions, the patch radius and the
translations; radians). Computations use the promoted input dtype (float32 stays float32).
Requirements (not checked inside jit): ``patch_radius > 0``, ``mu >= 0``, weights ``>= 0`` with a
positive sum, drift force strictly inside the limit surface. Zero weights are padding.

All branches are double-``where`` selections, so ``jax.grad`` is finite everywhere, including no
contact, ``action = 0``, ``s = 0``, a contact on a support point and zero-weight supports.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["ITERATIONS", "STEP_LIMIT", "Solution", "dissipation", "predict", "solve"]

ITERATIONS = {"stick": 7, "slip": 8}
"""Default Newton iterations of the sticking (1-D) and slipping (2-D) solves.

Measured in float64 on 1000 random pushes per case (uniform disc grids of radius R with K = 24 and 64 points
and random weights, contacts at 0.3-1.5 R, mu in [0, 1.5], with and without a drift force of 0.36), largest
relative twist error against 60 iterations: with the patch radius about half the grid spacing (rho ~ R / 10),
the sticking solve reaches 1e-9 after 5 iterations and 1e-15 after 6, the slipping solve 1e-7 after 5 and
1e-13 after 6 (float32's precision one iteration earlier). Smaller patches sharpen the kinks and cost more:
rho = R / 50 needs 8 (sticking) and 10 (slipping) iterations for 1e-15 (the defaults give about 1e-8 and
1e-6 there), rho = R / 500 about 12. Pass larger counts for small patches; :attr:`Solution.residual` tells
whether a solve converged. In float32 with rho ~ R / 10, 5 / 6 iterations already agree with 40 to float32's
precision (1e-7 of the twist on 10^4 pushes, K = 24), which saves about a third of the time.
"""

STEP_LIMIT = 0.99
"""Largest relative change ``|dz_k| / |z_k|`` of any patch velocity in one Newton step.

Just below 1: a step may then nearly reach a kink's centre (1 would land on it for a lone pseudo-Huber term)
but never jump across it. On 500 random pushes with drift (K = 24), 12 iterations of both solves reach
2e-16 / 6e-16 / 5e-16 for rho = R/5, R/50, R/500 with 0.99, against 4e-16 / 4e-16 / 3e-9 with 0.9,
1e-11 / 5e-3 with 1.5 at the two small patches, and no convergence with 3.
"""


class Solution(NamedTuple):
    """What :func:`solve` returns; batch shape [...] of the broadcast inputs.

    Attributes:
      twist: [..., 3] twist of the frame origin (dx, dy, dtheta) [length, length, rad (per step)],
        scaled by ``s``; zero where the pusher does not push.
      force: [..., 2] pusher force on the object in units of the total support friction force
        ``mu_s m g`` (independent of ``s`` and of the size of ``action``); zero where not pushing.
      sticking: [...] bool, the contact sticks (and the pusher pushes).
      slipping: [...] bool, the contact slips (and the pusher pushes with positive normal velocity).
      residual: [...] optimality residual of the solve that gave the result, the largest gradient component of
        its objective with the torque divided by the support's length scale ``l`` (units of ``mu_s m g``; 0
        where not pushing; no derivative). About 1e-15 (float64) or 1e-7 (float32) when converged; a larger
        value asks for more iterations (small patches, see :data:`ITERATIONS`).
    """

    twist: jax.Array
    force: jax.Array
    sticking: jax.Array
    slipping: jax.Array
    residual: jax.Array


def _check_shapes(arrays: dict) -> tuple[int, ...]:
    """Batch shape of the inputs; ``ValueError`` naming the first with a wrong shape or dtype."""
    trailing = {"contact": 1, "normal": 1, "action": 1, "drift_force": 1, "support_points": 2,
                "support_weights": 1}
    batch_shapes = {}
    supports = None
    for name, value in arrays.items():
        if not (jnp.issubdtype(value.dtype, jnp.floating) or jnp.issubdtype(value.dtype, jnp.integer)):
            raise ValueError(f"{name}: expected a real numeric array, got dtype {value.dtype}")
        axes = trailing.get(name, 0)
        if value.ndim < axes:
            raise ValueError(f"{name}: expected at least {axes} axes, got shape {value.shape}")
        if name in ("contact", "normal", "action", "drift_force", "support_points") and value.shape[-1] != 2:
            raise ValueError(f"{name}: expected shape [..., 2], got {value.shape}")
        if name == "support_points":
            supports = value.shape[-2]
        if name == "support_weights" and supports is not None and value.shape[-1] not in (supports, 1):
            raise ValueError(f"support_weights: expected shape [..., {supports}] to match support_points "
                             f"{arrays['support_points'].shape}, got {value.shape}")
        batch_shapes[name] = value.shape[:value.ndim - axes]
    try:
        return tuple(np.broadcast_shapes(*batch_shapes.values()))
    except ValueError:
        raise ValueError(", ".join(batch_shapes) + ": batch shapes do not broadcast: "
                         + ", ".join(f"{name} {shape}" for name, shape in batch_shapes.items())) from None


def _safe_norm(x, y):
    squared = x * x + y * y
    positive = squared > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, squared, 1)), 0), positive


def _sum(x):
    return jnp.sum(x, axis=-1)


# --------------------------------------------------------------------------------------------------
# The convex problem in x = (sigma, t):
#   f(x) = sum_k p_k |z_k| - beta . x,  z_k = (a0 + sigma e - t k x d_k, rho t),
# with k x d = (-d_y, d_x). Its gradient and Hessian, per push (arrays [...]; supports [..., K]).


class _Problem(NamedTuple):
    a0x: jax.Array
    a0y: jax.Array
    ex: jax.Array
    ey: jax.Array
    beta_sigma: jax.Array
    beta_t: jax.Array
    dx: jax.Array  # [..., K]
    dy: jax.Array  # [..., K]
    p: jax.Array  # [..., K]
    rho: jax.Array


def _patch_velocities(problem, sigma, t):
    ax = problem.a0x + sigma * problem.ex
    ay = problem.a0y + sigma * problem.ey
    z1 = ax[..., None] - t[..., None] * problem.dy
    z2 = ay[..., None] + t[..., None] * problem.dx
    z3 = (problem.rho * t)[..., None]
    # |z| > 0 for rho > 0 whenever the contact moves; the floor only keeps rho = 0 finite.
    inverse = jax.lax.rsqrt(jnp.maximum(z1 * z1 + z2 * z2 + z3 * z3, jnp.finfo(z1.dtype).tiny * 1e4))
    return z1, z2, z3, inverse


def _derivatives(problem, sigma, t, two_d):
    """Gradient (g_sigma, g_t), Hessian (h_ss, h_st, h_tt) of f, and the patch data for the step limit."""
    z1, z2, z3, inverse = _patch_velocities(problem, sigma, t)
    weight = problem.p * inverse
    rho = problem.rho[..., None]
    z_y2 = -z1 * problem.dy + z2 * problem.dx + z3 * rho  # z . dz/dt
    y2_squared = problem.dx * problem.dx + problem.dy * problem.dy + rho * rho
    unit_y2 = z_y2 * inverse
    g_t = _sum(weight * z_y2) - problem.beta_t
    h_tt = _sum(weight * (y2_squared - unit_y2 * unit_y2))
    if not two_d:
        zero = jnp.zeros_like(g_t)
        return (zero, g_t), (jnp.ones_like(g_t), zero, h_tt), inverse
    ex, ey = problem.ex[..., None], problem.ey[..., None]
    z_y1 = z1 * ex + z2 * ey  # z . dz/dsigma, |dz/dsigma| = |e| = 1
    unit_y1 = z_y1 * inverse
    g_sigma = _sum(weight * z_y1) - problem.beta_sigma
    h_ss = _sum(weight * (1 - unit_y1 * unit_y1))
    h_st = _sum(weight * (-ex * problem.dy + ey * problem.dx - unit_y1 * unit_y2))
    return (g_sigma, g_t), (h_ss, h_st, h_tt), inverse


def _newton_step(gradient, hessian):
    (g_s, g_t), (h_ss, h_st, h_tt) = gradient, hessian
    det = h_ss * h_tt - h_st * h_st
    safe = det > 0
    inverse_det = 1 / jnp.where(safe, det, 1)
    step_sigma = jnp.where(safe, -(h_tt * g_s - h_st * g_t) * inverse_det, 0)
    step_t = jnp.where(safe, -(h_ss * g_t - h_st * g_s) * inverse_det, 0)
    return step_sigma, step_t


def _iterate(problem, x0, two_d, iterations):
    """Safeguarded Newton from x0 = (sigma, t), a fixed number of iterations."""

    def body(_, x):
        sigma, t = x
        gradient, hessian, inverse = _derivatives(problem, sigma, t, two_d)
        step_sigma, step_t = _newton_step(gradient, hessian)
        # Change of each patch velocity z_k along the step, relative to |z_k|.
        dz1 = step_sigma[..., None] * problem.ex[..., None] - step_t[..., None] * problem.dy
        dz2 = step_sigma[..., None] * problem.ey[..., None] + step_t[..., None] * problem.dx
        dz3 = (problem.rho * step_t)[..., None]
        relative = (dz1 * dz1 + dz2 * dz2 + dz3 * dz3) * inverse * inverse
        largest = jnp.max(jnp.where(problem.p > 0, relative, 0), axis=-1)
        limit = STEP_LIMIT * STEP_LIMIT
        factor = jnp.where(largest > limit, STEP_LIMIT * jax.lax.rsqrt(jnp.where(largest > limit, largest, 1)), 1)
        return sigma + factor * step_sigma, t + factor * step_t

    return jax.lax.fori_loop(0, iterations, body, x0)


@functools.partial(jax.custom_jvp, nondiff_argnums=(0, 1))
def _solve_x(two_d, iterations, problem, sigma0, t0):
    return _iterate(problem, (sigma0, t0), two_d, iterations)


@_solve_x.defjvp
def _solve_x_jvp(two_d, iterations, primals, tangents):
    problem, sigma0, t0 = primals
    x = _solve_x(two_d, iterations, problem, sigma0, t0)
    x = jax.lax.stop_gradient(x)
    # Implicit function theorem on grad_x f(x, problem) = 0: dx = -H^-1 d(grad_x f)/d(problem) dproblem.
    def gradient_and_hessian(q):
        gradient, hessian, _ = _derivatives(q, *x, two_d)
        return gradient, hessian

    _, d_gradient, hessian = jax.jvp(gradient_and_hessian, (problem,), (tangents[0],), has_aux=True)
    step = _newton_step(d_gradient, hessian)
    return x, step


# --------------------------------------------------------------------------------------------------
# Public functions


def dissipation(twist, support_points, support_weights, patch_radius):
    """D(V) and its gradient, the friction wrench, for given twists (not jitted; V != 0, where D has its kink).

    Args:
      twist: [..., 3] (v_x, v_y, omega) of the frame origin.
      support_points: [..., K, 2] support points relative to the origin [length].
      support_weights: [..., K] weights >= 0 (normalised inside).
      patch_radius: [...] patch radius rho [length].

    Returns:
      (D [...] in units of mu_s m g times velocity, wrench [..., 3] = grad D: force [units of mu_s m g],
      torque [units of mu_s m g times length]).
    """
    twist, points, weights, rho = map(jnp.asarray, (twist, support_points, support_weights, patch_radius))
    p = weights / jnp.sum(weights, axis=-1, keepdims=True)
    omega = twist[..., 2:3]
    z1 = twist[..., 0:1] - omega * points[..., 1]
    z2 = twist[..., 1:2] + omega * points[..., 0]
    z3 = omega * jnp.asarray(rho)[..., None]
    norm = jnp.sqrt(z1 * z1 + z2 * z2 + z3 * z3)
    weight = p / norm
    wrench = jnp.stack([_sum(weight * z1), _sum(weight * z2),
                        _sum(weight * (-points[..., 1] * z1 + points[..., 0] * z2 + jnp.asarray(rho)[..., None] * z3))],
                       axis=-1)
    return _sum(p * norm), wrench


class _Pushes(NamedTuple):
    """The pushes of :func:`solve`, broadcast to the batch shape [...] and one dtype.

    The normal ``(nx, ny)`` is the unit normal (``(1, 0)`` without contact), ``(unit_ux, unit_uy)`` the action's
    direction (the normal without motion); ``normal_push = u . n``; ``pushing`` whether the pusher pushes;
    ``(dx, dy)`` [..., K] the supports relative to the contact, ``p`` [..., K] their normalised weights, ``beta_t``
    the drift force's linear coefficient of the rotation rate, ``g . (c_y, -c_x)``.
    """

    cx: jax.Array
    cy: jax.Array
    nx: jax.Array
    ny: jax.Array
    ux: jax.Array
    uy: jax.Array
    unit_ux: jax.Array
    unit_uy: jax.Array
    action_length: jax.Array
    normal_push: jax.Array
    pushing: jax.Array
    gx: jax.Array
    gy: jax.Array
    mu: jax.Array
    rho: jax.Array
    s: jax.Array
    rx: jax.Array
    ry: jax.Array
    p: jax.Array
    dx: jax.Array
    dy: jax.Array
    beta_t: jax.Array


def _pushes(contact, normal, action, mu, support_points, support_weights, patch_radius, s,
            drift_force) -> tuple[_Pushes, jnp.dtype]:
    """The inputs of :func:`solve` checked, broadcast and made unit where the solve needs it; and their dtype."""
    contact, normal, action, mu, points, weights, rho, s = map(
        jnp.asarray, (contact, normal, action, mu, support_points, support_weights, patch_radius, s))
    drift = jnp.zeros(2) if drift_force is None else jnp.asarray(drift_force)
    batch = _check_shapes({"contact": contact, "normal": normal, "action": action, "mu": mu,
                           "support_points": points, "support_weights": weights, "patch_radius": rho, "s": s,
                           "drift_force": drift})
    dtype = jnp.result_type(contact, normal, action, mu, points, weights, rho, s, drift, float)
    supports = points.shape[-2]

    def vector(value):
        value = jnp.broadcast_to(jnp.asarray(value, dtype), (*batch, 2))
        return value[..., 0], value[..., 1]

    def scalar(value):
        return jnp.broadcast_to(jnp.asarray(value, dtype), batch)

    cx, cy = vector(contact)
    nx, ny = vector(normal)
    ux, uy = vector(action)
    gx, gy = vector(drift)
    mu, rho, s = scalar(mu), scalar(rho), scalar(s)
    points = jnp.broadcast_to(jnp.asarray(points, dtype), (*batch, supports, 2))
    rx, ry = points[..., 0], points[..., 1]
    weights = jnp.broadcast_to(jnp.asarray(weights, dtype), (*batch, supports))
    total = _sum(weights)
    p = weights / jnp.where(total > 0, total, 1)[..., None]

    # Unit normal and unit action; safe stand-ins where they vanish (the result is masked there).
    normal_length, has_normal = _safe_norm(nx, ny)
    nx = jnp.where(has_normal, nx / jnp.where(has_normal, normal_length, 1), 1)
    ny = jnp.where(has_normal, ny / jnp.where(has_normal, normal_length, 1), 0)
    action_length, moving = _safe_norm(ux, uy)
    unit_ux = jnp.where(moving, ux / jnp.where(moving, action_length, 1), nx)
    unit_uy = jnp.where(moving, uy / jnp.where(moving, action_length, 1), ny)
    normal_push = ux * nx + uy * ny  # u . n with the unit normal
    pushing = has_normal & moving & (normal_push > 0)
    dx, dy = rx - cx[..., None], ry - cy[..., None]
    # G . V(t) = g . (a - t k x c): linear coefficient of t is g . (c_y, -c_x); of sigma, g . e.
    beta_t = gx * cy - gy * cx
    return _Pushes(cx, cy, nx, ny, ux, uy, unit_ux, unit_uy, action_length, normal_push, pushing, gx, gy, mu, rho, s,
                   rx, ry, p, dx, dy, beta_t), dtype


class _Ellipsoid(NamedTuple):
    """The ellipsoid about the supports' weighted centroid that gives the solves' initial guesses: the centroid, its
    ``l^2 = E|r - centroid|^2 / 2 + rho^2`` (the effective l of small rotations) and the contact relative to it."""

    centroid_x: jax.Array
    centroid_y: jax.Array
    l2: jax.Array
    ccx: jax.Array
    ccy: jax.Array


def _ellipsoid(q: _Pushes, dtype) -> _Ellipsoid:
    centroid_x, centroid_y = _sum(q.p * q.rx), _sum(q.p * q.ry)
    l2 = 0.5 * _sum(q.p * ((q.rx - centroid_x[..., None]) ** 2 + (q.ry - centroid_y[..., None]) ** 2)) + q.rho * q.rho
    # Positive also for the invalid rho = 0 with a single support (keeps the guesses finite there).
    l2 = jax.lax.stop_gradient(jnp.maximum(l2, jnp.finfo(dtype).eps * (q.cx * q.cx + q.cy * q.cy + 1e-6)))
    return _Ellipsoid(centroid_x, centroid_y, l2, q.cx - centroid_x, q.cy - centroid_y)


def _stick(q: _Pushes, guess: _Ellipsoid, iterations: int):
    """The sticking solve, 1-D in the rotation rate t with the contact moving as the pusher (a = u / |u|).

    Returns (t, pusher force x, y, the objective's derivative in t (its residual), whether the contact sticks).
    """
    zero = jnp.zeros_like(q.cx)
    # Guess: the minimiser on the ellipsoid, where the dissipation along the line is one hyperbola
    # sqrt(alpha t^2 + 2 beta t + 1) (centroid velocity u - t k x c') plus the drift term -g . v = -beta_t t:
    # t = t_c + h tau / sqrt(1 - tau^2), tau = beta_t / sqrt(alpha), t_c = -beta / alpha,
    # h^2 = (1 - beta^2 / alpha) / alpha.
    problem = _Problem(q.unit_ux, q.unit_uy, zero, zero, zero, q.beta_t, q.dx, q.dy, q.p, q.rho)
    ccx, ccy = guess.ccx, guess.ccy
    alpha = guess.l2 + ccx * ccx + ccy * ccy
    beta = ccy * q.unit_ux - ccx * q.unit_uy  # -(c' x u)
    tau = jnp.clip(q.beta_t / jnp.sqrt(alpha), -0.95, 0.95)
    t0 = -beta / alpha + jnp.sqrt(jnp.maximum(1 - beta * beta / alpha, 0) / alpha) * tau / jnp.sqrt(1 - tau * tau)
    t0 = jax.lax.stop_gradient(t0)
    _, t_stick = _solve_x(False, iterations, problem, zero, t0)
    z1, z2, z3, inverse = _patch_velocities(problem, zero, t_stick)
    force_x = _sum(q.p * z1 * inverse) - q.gx
    force_y = _sum(q.p * z2 * inverse) - q.gy
    torque = _sum(q.p * (-z1 * q.dy + z2 * q.dx + z3 * q.rho[..., None]) * inverse) - q.beta_t  # d objective / dt
    inside = jnp.abs(q.nx * force_y - q.ny * force_x) <= q.mu * (q.nx * force_x + q.ny * force_y)
    return t_stick, force_x, force_y, torque, q.pushing & inside


class _Slip(NamedTuple):
    """The slipping solve's result: the tangent ``(ex, ey)``, the contact velocity ``(ax, ay)`` and rotation rate
    ``t`` with ``f_b . J V = 1``, the contact's normal velocity, whether it slips, the pusher force and the
    objective's derivative in t."""

    ex: jax.Array
    ey: jax.Array
    ax: jax.Array
    ay: jax.Array
    t: jax.Array
    normal_velocity: jax.Array
    slipping: jax.Array
    force_x: jax.Array
    force_y: jax.Array
    torque: jax.Array


def _slip(q: _Pushes, guess: _Ellipsoid, stick_force_x, stick_force_y, sticking, iterations: int, dtype) -> _Slip:
    """The slipping solve: f_b on the side where the sticking force leaves the cone; f_b . J V = 1, 2-D in
    (sigma, t)."""
    nx, ny, gx, gy = q.nx, q.ny, q.gx, q.gy
    side_mu = jnp.where(nx * stick_force_y - ny * stick_force_x > 0, q.mu, -q.mu)
    bx, by = nx - side_mu * ny, ny + side_mu * nx
    b2 = bx * bx + by * by  # >= 1
    b_length = jnp.sqrt(b2)
    a0x, a0y = bx / b2, by / b2
    ex, ey = -by / b_length, bx / b_length
    problem = _Problem(a0x, a0y, ex, ey, gx * ex + gy * ey, q.beta_t, q.dx, q.dy, q.p, q.rho)
    # Guess: the ellipsoid's slipping twist. About the centroid the wrench (lambda f_b + g, lambda m_b + m_g)
    # (m_b = c' x f_b, m_g = -centroid x g) lies on |f|^2 + m^2 / l^2 = 1, and the twist is (f, m / l^2);
    # scaled to f_b . J V = 1.
    ccx, ccy, l2 = guess.ccx, guess.ccy, guess.l2
    m_b = ccx * by - ccy * bx
    m_g = guess.centroid_y * gx - guess.centroid_x * gy
    quadratic = b2 + m_b * m_b / l2
    linear = bx * gx + by * gy + m_b * m_g / l2
    constant = gx * gx + gy * gy + m_g * m_g / l2 - 1
    lam = (-linear + jnp.sqrt(jnp.maximum(linear * linear - quadratic * constant, 0))) / quadratic
    omega = (lam * m_b + m_g) / l2
    velocity_x, velocity_y = lam * bx + gx - omega * ccy, lam * by + gy + omega * ccx  # contact velocity
    kappa = 1 / jnp.maximum(velocity_x * bx + velocity_y * by, jnp.finfo(dtype).tiny * 1e8)
    sigma0 = jax.lax.stop_gradient(kappa * (velocity_x * ex + velocity_y * ey))
    slip_t0 = jax.lax.stop_gradient(kappa * omega)
    sigma, t_slip = _solve_x(True, iterations, problem, sigma0, slip_t0)
    slip_ax, slip_ay = a0x + sigma * ex, a0y + sigma * ey
    normal_velocity = slip_ax * nx + slip_ay * ny
    slipping = q.pushing & ~sticking & (normal_velocity > 0)
    z1s, z2s, z3s, inverse_s = _patch_velocities(problem, sigma, t_slip)
    slip_force_x = _sum(q.p * z1s * inverse_s) - gx
    slip_force_y = _sum(q.p * z2s * inverse_s) - gy
    slip_torque = _sum(q.p * (-z1s * q.dy + z2s * q.dx + z3s * q.rho[..., None]) * inverse_s) - q.beta_t
    return _Slip(ex, ey, slip_ax, slip_ay, t_slip, normal_velocity, slipping, slip_force_x, slip_force_y, slip_torque)


@functools.partial(jax.jit, static_argnames=("stick_iterations", "slip_iterations"))
def solve(contact, normal, action, mu, support_points, support_weights, patch_radius, s=1.0, drift_force=None,
          *, stick_iterations: int = ITERATIONS["stick"], slip_iterations: int = ITERATIONS["slip"]) -> Solution:
    """Twist, pusher force and contact mode of a push on the exact limit surface.

    Args:
      contact: [..., 2] contact point, relative to the origin of ``support_points`` [length].
      normal: [..., 2] surface normal at the contact, into the object; any length, zero = no contact.
      action: [..., 2] pusher motion u [length (per step)].
      mu: [...] pusher-object friction coefficient, >= 0.
      support_points: [..., K, 2] support points r_k (same frame and origin as ``contact``) [length].
      support_weights: [..., K] pressure weights p_k >= 0, normalised inside; zeros are padding.
      patch_radius: [...] radius rho > 0 of each support's disc patch [length].
      s: [...] contact indicator in [0, 1], scales the twist.
      drift_force: [..., 2] constant in-plane force at the origin in units of the total support friction
        force (strictly inside the limit surface); None for none.
      stick_iterations, slip_iterations: Newton iterations (static).

    Returns:
      :class:`Solution` (twist [..., 3], force [..., 2], sticking [...], slipping [...], residual [...]).
    """
    q, dtype = _pushes(contact, normal, action, mu, support_points, support_weights, patch_radius, s, drift_force)
    guess = _ellipsoid(q, dtype)
    t_stick, force_x, force_y, stick_torque, sticking = _stick(q, guess, stick_iterations)
    slip = _slip(q, guess, force_x, force_y, sticking, slip_iterations, dtype)
    slipping = slip.slipping

    # Twist: contact velocity a and rotation t give v = a - t k x c = a + t (c_y, -c_x).
    ratio = jnp.where(slipping, q.normal_push / jnp.where(slipping, slip.normal_velocity, 1), 0)
    stick_scale = jnp.where(sticking, q.action_length, 0)
    twist = jnp.stack([
        stick_scale * (q.unit_ux + t_stick * q.cy) + ratio * (slip.ax + slip.t * q.cy),
        stick_scale * (q.unit_uy - t_stick * q.cx) + ratio * (slip.ay - slip.t * q.cx),
        stick_scale * t_stick + ratio * slip.t,
    ], axis=-1) * q.s[..., None]
    force = jnp.stack([
        jnp.where(sticking, force_x, jnp.where(slipping, slip.force_x, 0)),
        jnp.where(sticking, force_y, jnp.where(slipping, slip.force_y, 0)),
    ], axis=-1)
    length = jnp.sqrt(guess.l2)
    residual = jnp.where(sticking, jnp.abs(stick_torque) / length, jnp.where(
        slipping, jnp.maximum(jnp.abs(slip.force_x * slip.ex + slip.force_y * slip.ey), jnp.abs(slip.torque) / length),
        0))
    return Solution(twist, force, sticking, slipping, jax.lax.stop_gradient(residual))


@functools.partial(jax.jit, static_argnames=("stick_iterations", "slip_iterations"))
def predict(contact, normal, action, mu, support_points, support_weights, patch_radius, s=1.0, drift_force=None,
            *, stick_iterations: int = ITERATIONS["stick"], slip_iterations: int = ITERATIONS["slip"]) -> jax.Array:
    """Object twist caused by a push on the exact limit surface: ``solve(...).twist``.

    Arguments as in :func:`solve`. Returns [..., 3] the twist (dx, dy, dtheta) of the frame origin
    [length, length, rad (per step)], with the conventions of :func:`pushjax.physics.lynch.predict`.
    """
    return solve(contact, normal, action, mu, support_points, support_weights, patch_radius, s, drift_force,
                 stick_iterations=stick_iterations, slip_iterations=slip_iterations).twist
