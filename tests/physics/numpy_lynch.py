"""Independent NumPy reference of the Lynch pushing model, written from the equations.

Deliberately formulated differently from ``pushjax.physics.lynch``: the normal is normalised, the
friction cone uses ``arctan``/``cos``/``sin``, both motion-cone boundaries are built, cone
membership and the slipping side are decided by explicit angle comparisons, and the object motion
uses the two-stage formulas with ``dtheta = (c_x v_y - c_y v_x) / l^2``.
Shapes and units as in ``pushjax.physics.lynch``; computes in the dtype of its inputs.
"""

import numpy as np

NOT_PUSHING, STICKING, SLIPPING_LEFT, SLIPPING_RIGHT = 0, 1, 2, 3


def _rotate(vectors, angle):
    cos, sin = np.cos(angle)[..., None], np.sin(angle)[..., None]
    x, y = vectors[..., :1], vectors[..., 1:]
    return np.concatenate([cos * x - sin * y, sin * x + cos * y], axis=-1)


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _angle_from(reference, vectors):
    """Signed angle in (-pi, pi] from ``reference`` to ``vectors``."""
    return np.arctan2(_cross(reference, vectors), _dot(reference, vectors))


def unit_normal(normal):
    """normal / |normal|, and 0 where |normal| = 0."""
    normal = np.asarray(normal)
    norm = np.linalg.norm(normal, axis=-1, keepdims=True)
    return np.divide(normal, norm, out=np.zeros_like(normal), where=norm > 0)


def motion_cone(contact, normal, l, mu):
    """Boundary contact velocities (v_pl, v_pr) [..., 2] of the friction-cone edges R(+-alpha) n."""
    contact, n = np.asarray(contact), unit_normal(normal)
    alpha = np.arctan(np.asarray(mu))
    k_cross_c = np.stack([-contact[..., 1], contact[..., 0]], axis=-1)
    boundaries = []
    for angle in (alpha, -alpha):
        force = _rotate(n, angle)
        torque = _cross(contact, force)[..., None]
        boundaries.append(np.asarray(l)[..., None] ** 2 * force + torque * k_cross_c)
    return tuple(boundaries)


def contact_mode(contact, normal, action, l, mu):
    """NOT_PUSHING, STICKING, SLIPPING_LEFT or SLIPPING_RIGHT per push."""
    n, action = unit_normal(normal), np.asarray(action)
    v_left, v_right = motion_cone(contact, normal, l, mu)
    # Angles measured from n; the motion cone [phi_r, phi_l] never contains -n, so no wrap-around.
    phi_u = _angle_from(n, action)
    phi_l = _angle_from(n, v_left)
    phi_r = _angle_from(n, v_right)
    mode = np.where(phi_u > phi_l, SLIPPING_LEFT, SLIPPING_RIGHT)
    mode = np.where((phi_r <= phi_u) & (phi_u <= phi_l), STICKING, mode)
    return np.where(_dot(action, n) > 0, mode, NOT_PUSHING)


def effective_push_velocity(contact, normal, action, l, mu):
    """Returns (v_p [..., 2], sticking [...] bool)."""
    n, action = unit_normal(normal), np.asarray(action)
    v_left, v_right = motion_cone(contact, normal, l, mu)
    mode = contact_mode(contact, normal, action, l, mu)
    v_boundary = np.where((mode == SLIPPING_RIGHT)[..., None], v_right, v_left)
    u_n, v_boundary_n = _dot(action, n), _dot(v_boundary, n)
    # A boundary velocity pointing out of the object cannot carry the push: v_p = 0.
    valid = (mode >= SLIPPING_LEFT) & (v_boundary_n > 0)
    ratio = np.divide(u_n, v_boundary_n, out=np.zeros_like(u_n), where=valid)
    sticking = mode == STICKING
    v_p = np.where(sticking[..., None], action, ratio[..., None] * v_boundary)
    return v_p, sticking


def object_velocity(contact, v_p, l):
    """Returns (dx, dy, dtheta) [..., 3]."""
    cx, cy = contact[..., 0], contact[..., 1]
    vpx, vpy = v_p[..., 0], v_p[..., 1]
    l2 = np.asarray(l) ** 2
    denominator = l2 + cx**2 + cy**2
    vx = ((l2 + cx**2) * vpx + cx * cy * vpy) / denominator
    vy = (cx * cy * vpx + (l2 + cy**2) * vpy) / denominator
    dtheta = (cx * vy - cy * vx) / l2
    return np.stack([vx, vy, dtheta], axis=-1)


def predict(contact, normal, action, l, mu, s=1.0):
    """Returns (dx, dy, dtheta) [..., 3]."""
    v_p, _ = effective_push_velocity(contact, normal, action, l, mu)
    return object_velocity(np.asarray(contact), np.asarray(s)[..., None] * v_p, l)
