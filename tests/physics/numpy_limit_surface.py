"""Independent NumPy/SciPy reference of the exact limit-surface pushing model, one push at a time.

Written from the equations of ``pushjax.physics.limit_surface`` but solved differently: no Newton
iterations and a different parametrisation of the slipping problem.

* Sticking: the twists that move the contact point with the pusher are rotations at rate ``t`` about
  the contact added to the pusher's translation; the dissipation along that line is convex, so its
  derivative (the wrench's component along the line) is monotone and ``scipy.optimize.brentq`` finds
  its zero in a bracket found by doubling.
* Slipping: the contact velocity is ``n + sigma (k x n)`` (normal velocity fixed at 1, unit normal);
  for each slip ``sigma`` the sticking problem gives a contact force, whose angle turns monotonically
  with ``sigma`` (the force is the gradient of the convex reduced dissipation); ``brentq`` finds the
  slip at which that angle is the friction-cone edge's. The twist is then scaled to the pusher's
  normal velocity. No root (the edge would need a non-positive normal velocity): no motion.

Angles (``arctan2``, ``arctan(mu)``) decide cone membership and the slipping side. Shapes and units as
in ``pushjax.physics.limit_surface``; float64 throughout.
"""

import numpy as np
from scipy import optimize


def dissipation_and_wrench(twist, points, weights, rho):
    """D(V) = sum_k p_k sqrt(|v_k|^2 + (rho w)^2) and its gradient (the friction wrench)."""
    p = np.asarray(weights, float) / np.sum(weights)
    points = np.asarray(points, float)
    vx, vy, w = twist
    x, y = points[:, 0], points[:, 1]
    velocity_x, velocity_y = vx - w * y, vy + w * x
    speed = np.sqrt(velocity_x**2 + velocity_y**2 + (rho * w) ** 2)
    share = p / speed
    # d speed / dV: velocity / speed for v, (r x velocity + rho^2 w) / speed for w.
    wrench = np.array([share @ velocity_x, share @ velocity_y, share @ (x * velocity_y - y * velocity_x + rho * rho * w)])
    return p @ speed, wrench


def _bracket_root(function, start=1.0):
    """(lo, hi) with function(lo) < 0 < function(hi) for an increasing function, by doubling."""
    lo, hi = -start, start
    for _ in range(45):
        if function(lo) < 0:
            break
        lo *= 2
    for _ in range(45):
        if function(hi) > 0:
            break
        hi *= 2
    return lo, hi


def stick(contact, contact_velocity, points, weights, rho, drift):
    """Sticking twist (origin) and pusher force for a contact moving with ``contact_velocity``."""
    cx, cy = contact
    about_contact = np.array([cy, -cx, 1.0])  # twist of a unit rotation about the contact

    def twist(t):
        return np.array([contact_velocity[0], contact_velocity[1], 0.0]) + t * about_contact

    def slope(t):  # d/dt [D(V(t)) - g . v(t)]
        return dissipation_and_wrench(twist(t), points, weights, rho)[1] @ about_contact - drift @ about_contact[:2]

    scale = np.linalg.norm(contact_velocity) / max(np.max(np.linalg.norm(np.asarray(points) - contact, axis=-1)), 1e-9)
    lo, hi = _bracket_root(slope, scale)
    t = optimize.brentq(slope, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=500)
    solution = twist(t)
    force = dissipation_and_wrench(solution, points, weights, rho)[1][:2] - drift
    return solution, force


def solve(contact, normal, action, mu, points, weights, rho, s=1.0, drift=None):
    """(twist [3], force [2], mode) of one push; mode is "none", "stick" or "slip"."""
    contact, normal, action = (np.asarray(x, float) for x in (contact, normal, action))
    drift = np.zeros(2) if drift is None else np.asarray(drift, float)
    nothing = np.zeros(3), np.zeros(2), "none"
    length = np.linalg.norm(normal)
    if length == 0 or np.linalg.norm(action) == 0:
        return nothing
    n = normal / length
    if action @ n <= 0:
        return nothing
    twist, force = stick(contact, action, points, weights, rho, drift)
    angle = np.arctan2(n[0] * force[1] - n[1] * force[0], n @ force)  # of the force from n
    half_cone = np.arctan(mu)
    if abs(angle) <= half_cone:
        return s * twist, force, "stick"
    edge_angle = np.arctan2(n[1], n[0]) + np.sign(angle) * half_cone
    tangent = np.array([-n[1], n[0]])

    def angle_error(sigma):
        _, f = stick(contact, n + sigma * tangent, points, weights, rho, drift)
        return np.angle(np.exp(1j * (np.arctan2(f[1], f[0]) - edge_angle)))

    try:
        lo, hi = _bracket_root(angle_error, 1.0)
        if not (angle_error(lo) < 0 < angle_error(hi)):
            return nothing
        sigma = optimize.brentq(angle_error, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=500)
    except (ValueError, OverflowError):
        return nothing
    if abs(angle_error(sigma)) > 1e-6:  # converged onto the wrap-around at the opposite edge
        return nothing
    twist, force = stick(contact, n + sigma * tangent, points, weights, rho, drift)
    return s * (action @ n) * twist, force, "slip"
