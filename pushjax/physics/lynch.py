"""Differentiable quasi-static pushing model of Lynch, Maekawa & Tanie (1992).

A point pusher in contact with a planar object that slides on a support surface. The support
friction is modelled by an ellipsoidal limit surface with ratio ``l = m_max / f_max`` between the
maximal friction torque and force; the pusher-object friction by a Coulomb cone with coefficient
``mu``. Following Kloss, Schaal & Bohg (Sec. III-A), the prediction has two stages:

1. :func:`effective_push_velocity` decides whether the contact sticks or slips and returns the part
   ``v_p`` of the pusher motion ``u`` that is transmitted to the object.
2. :func:`object_velocity` maps ``v_p`` to the object twist ``(dx, dy, dtheta)``.

:func:`predict` chains both and scales ``v_p`` by a contact indicator ``s``. Its derivative is the exact one;
:func:`with_push_gate_gradient` adds a training signal where a push does not push (see there).

Conventions shared by all functions:

* Points and directions are 2-vectors in the last axis, expressed in any frame whose origin is the
  object's centre of mass; leading batch axes broadcast against each other (NumPy rules).
* The model is unit-agnostic: ``contact``, ``action``, ``l`` and the translational outputs share one
  length unit (e.g. m), ``dtheta`` is in radians. Quantities are displacements per step or
  velocities alike, because the model is positively homogeneous in ``action``.
* ``normal`` points INTO the object. Its length does not matter: every quantity is invariant to
  scaling the normal, so it is never explicitly normalised (which would cost a square root and a
  branch); keep ``|normal|`` within about 1e-6 to 1e6 so that float32 products stay in range.
  ``|normal| = 0`` means "no contact" and yields zero motion.
* A point pusher cannot pull: when ``action . normal <= 0`` the pusher separates from (or slides
  along) the surface and ``v_p = 0``.
* Slipping follows the motion-cone boundary on the side where ``u`` leaves the cone, which is the
  boundary closer to ``u`` in angle (proved when both boundary velocities point into the object;
  no counter-example otherwise among 2e6 random extreme pushes). For large ``mu`` with the contact
  far from the centre of mass one boundary velocity can point out of the object
  (``v_pb . normal <= 0``). At most one can, as ``v_pl . n + v_pr . n = 2 (l^2 |n|^2 + (c x n)^2)``,
  and the cone then covers that whole side of the pushing half-plane, so slipping never uses it.
  The remaining ``v_pb . normal <= 0`` guard (``v_p = 0``) only keeps invalid input (``l = 0``)
  finite.
* Requires ``l > 0`` and ``mu >= 0``. The jitted functions never branch on values; call
  :func:`check_inputs` on concrete arrays (outside ``jax.jit``) to validate user input (which also
  requires unit normals, so that a zero normal does not pass for a push). They do check
  shapes and dtypes (real numbers, points with a trailing axis of 2, batch shapes that broadcast) when
  traced, which is static information: a ``ValueError`` names the argument, under ``jax.jit``,
  ``jax.vmap`` and ``jax.grad`` alike, at no run-time cost.

All branches are ``jnp.where`` selections whose unselected sides stay finite (the "double where"
pattern), so ``jax.grad``/``jax.jacfwd`` are finite everywhere, including ``normal = 0``,
``action = 0``, ``contact = 0``, ``s = 0`` and pushes exactly on a motion-cone boundary. The
computation is done in the (promoted) input dtype; float32 inputs stay float32.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["check_inputs", "effective_push_velocity", "object_velocity", "predict", "with_push_gate_gradient"]


NORMAL_LENGTH_TOLERANCE = 1e-3
"""How far from 1 the length of a normal given to :func:`check_inputs` may be."""

_VECTOR_SIZES = {"contact": 2, "normal": 2, "action": 2, "v_p": 2, "motion": 3}
"""The arguments that are vectors in the last axis, and their sizes; all others are one number per push."""


def _check_shapes_and_dtypes(arrays: dict) -> None:
    """Raises ``ValueError`` naming the first of `arrays` (name -> array) that is not real numbers of the right shape.

    Reads only ``.shape`` and ``.dtype``, so it works on tracers (``jax.jit``, ``jax.vmap``, ``jax.grad``) when
    a function is traced and costs nothing at run time. Vectors (`_VECTOR_SIZES`) are [..., size], the other
    arguments [...], and the batch shapes [...] must broadcast against each other.
    """
    batch_shapes = {}
    for name, value in arrays.items():
        if not (jnp.issubdtype(value.dtype, jnp.floating) or jnp.issubdtype(value.dtype, jnp.integer)):
            raise ValueError(f"{name}: expected a real numeric array, got dtype {value.dtype}")
        if name in _VECTOR_SIZES:
            size = _VECTOR_SIZES[name]
            if value.ndim == 0 or value.shape[-1] != size:
                raise ValueError(f"{name}: expected shape [..., {size}], got {value.shape}")
            batch_shapes[name] = value.shape[:-1]
        else:
            batch_shapes[name] = value.shape
    try:
        np.broadcast_shapes(*batch_shapes.values())
    except ValueError:
        raise ValueError(
            f"{', '.join(batch_shapes)}: batch shapes do not broadcast: "
            + ", ".join(f"{name} {shape}" for name, shape in batch_shapes.items())
        ) from None


def _split_xy(vectors: jax.Array, dtype) -> tuple[jax.Array, jax.Array]:
    vectors = jnp.asarray(vectors, dtype)
    return vectors[..., 0], vectors[..., 1]


# Stage 1 without angles or the second boundary. The map from contact force to contact-point
# velocity, A f = l^2 f + (c x f) (k x c), is symmetric positive definite with adjugate
# P u = l^2 u + (c . u) c. So u lies in the motion cone spanned by v_pl = A f_l and v_pr = A f_r
# exactly when the force P u (a positive multiple of A^-1 u) lies in the friction cone, and P u
# leaves the friction cone on the side where u leaves the motion cone. Every quantity below is
# invariant to the length of n, which therefore is never normalised.


def _push_force(cx, cy, ux, uy, l):
    """P u: the contact force direction whose contact velocity is parallel to u."""
    l2 = l * l
    c_dot_u = cx * ux + cy * uy
    return l2 * ux + c_dot_u * cx, l2 * uy + c_dot_u * cy


def _slip_boundary(cx, cy, nx, ny, ux, uy, l, mu):
    """Friction-cone boundary on u's side: force f_b [2], torque c x f_b, and v_pb . n."""
    force_x, force_y = _push_force(cx, cy, ux, uy, l)
    # R(+-alpha) n up to the factor cos(alpha), which cancels like |n|: f_b = n +- mu (k x n),
    # with + (the counter-clockwise boundary f_l) when P u is counter-clockwise of n.
    side_mu = jnp.where(nx * force_y - ny * force_x > 0, mu, -mu)
    boundary_x, boundary_y = nx - side_mu * ny, ny + side_mu * nx
    c_cross_n = cx * ny - cy * nx
    torque = c_cross_n + side_mu * (cx * nx + cy * ny)
    # v_pb . n = l^2 (f_b . n) + (c x f_b) ((k x c) . n), with f_b . n = |n|^2, (k x c) . n = c x n.
    velocity_dot_n = l * l * (nx * nx + ny * ny) + torque * c_cross_n
    return boundary_x, boundary_y, torque, velocity_dot_n


def _contact_mode(cx, cy, nx, ny, ux, uy, l, mu):
    """(sticking, slipping) bool arrays; neither when not pushing (or v_pb . n <= 0, l = 0 only)."""
    force_x, force_y = _push_force(cx, cy, ux, uy, l)
    pushing = ux * nx + uy * ny > 0
    # P u inside the friction cone: |n x P u| <= mu (n . P u).
    inside = jnp.abs(nx * force_y - ny * force_x) <= mu * (nx * force_x + ny * force_y)
    sticking = pushing & inside
    *_, boundary_velocity_dot_n = _slip_boundary(cx, cy, nx, ny, ux, uy, l, mu)
    return sticking, pushing & ~sticking & (boundary_velocity_dot_n > 0)


def _twist_factors(cx, cy, nx, ny, ux, uy, l, mu, s, sticking, slipping):
    """Twist = numerator / denominator * direction, Stage 2 applied to Stage 1 in closed form.

    With P A = l^2 (l^2 + |c|^2) I:
      sticking: twist = s (P u, c x u) / (l^2 + |c|^2)
      slipping: twist = s (u . n) / (v_pb . n) (l^2 f_b, c x f_b)
    i.e. the object translates along the pushing force, as the ellipsoidal limit surface says.
    """
    l2 = l * l
    boundary_x, boundary_y, torque, boundary_velocity_dot_n = _slip_boundary(
        cx, cy, nx, ny, ux, uy, l, mu
    )
    force_x, force_y = _push_force(cx, cy, ux, uy, l)
    stick_denominator = l2 + cx * cx + cy * cy  # zero only for the invalid l = 0, c = 0
    numerator = s * jnp.where(sticking, 1, jnp.where(slipping, ux * nx + uy * ny, 0))
    denominator = jnp.where(
        sticking,
        jnp.where(stick_denominator > 0, stick_denominator, 1),
        jnp.where(slipping, boundary_velocity_dot_n, 1),
    )
    direction = (
        jnp.where(sticking, force_x, l2 * boundary_x),
        jnp.where(sticking, force_y, l2 * boundary_y),
        jnp.where(sticking, cx * uy - cy * ux, torque),
    )
    return numerator, denominator, direction


@jax.custom_jvp
def _twist(cx, cy, nx, ny, ux, uy, l, mu, s):
    """(dx, dy, dtheta) of :func:`predict` on split x/y components."""
    sticking, slipping = _contact_mode(cx, cy, nx, ny, ux, uy, l, mu)
    numerator, denominator, direction = _twist_factors(
        cx, cy, nx, ny, ux, uy, l, mu, s, sticking, slipping
    )
    # One division per component keeps the forward pass a single fused loop on XLA:CPU.
    return tuple(numerator * component / denominator for component in direction)


@_twist.defjvp
def _twist_jvp(primals, tangents):
    # The derivative autodiff gives (the contact mode is piecewise constant), arranged for XLA:CPU,
    # which emits one loop per gradient output and would recompute or materialise every shared
    # term. The stick/slip decision and the division are evaluated once, on an optimisation-barrier
    # copy of the inputs, into a single array: 1 / denominator, negated when slipping, 0 when not
    # pushing. All other terms are cheap to recompute per output. This halves the gradient's cost.
    opaque = jax.lax.optimization_barrier(primals)
    sticking, slipping = _contact_mode(*opaque[:-1])
    _, denominator, _ = _twist_factors(*opaque, sticking, slipping)
    signed_inverse = jnp.where(sticking, 1, jnp.where(slipping, -1, 0)) / denominator
    sticking, slipping = signed_inverse > 0, signed_inverse < 0
    (numerator, _, direction), (d_numerator, d_denominator, d_direction) = jax.jvp(
        lambda *args: _twist_factors(*args, sticking, slipping), primals, tangents
    )
    inverse = jnp.abs(signed_inverse)
    scale = numerator * inverse
    d_scale = (d_numerator - scale * d_denominator) * inverse
    twist = tuple(scale * component for component in direction)
    d_twist = tuple(
        d_scale * component + scale * d_component
        for component, d_component in zip(direction, d_direction)
    )
    return twist, d_twist


def _object_velocity_xy(cx, cy, vpx, vpy, l):
    """Stage 2 on split x/y components; see :func:`object_velocity`."""
    l2 = l * l
    denominator = l2 + cx * cx + cy * cy
    # Zero only for l = 0 and c = 0 (invalid input); keeps the output finite there.
    inverse = 1 / jnp.where(denominator > 0, denominator, 1)
    cross = cx * cy
    vx = ((l2 + cx * cx) * vpx + cross * vpy) * inverse
    vy = (cross * vpx + (l2 + cy * cy) * vpy) * inverse
    # (c_x v_y - c_y v_x) / l^2 simplifies to (c_x v_py - c_y v_px) / (l^2 + |c|^2).
    dtheta = (cx * vpy - cy * vpx) * inverse
    return jnp.stack([vx, vy, dtheta], axis=-1)


@jax.jit
def effective_push_velocity(
    contact: jax.Array, normal: jax.Array, action: jax.Array, l: jax.Array, mu: jax.Array
) -> tuple[jax.Array, jax.Array]:
    """Velocity of the contact point on the object, and whether the contact sticks.

    Args:
      contact: [..., 2] contact point relative to the object's centre of mass [length].
      normal: [..., 2] surface normal at the contact, pointing into the object; any length,
        zero means no contact.
      action: [..., 2] pusher motion u [length (per step)].
      l: [...] limit-surface ratio max torque / max force [length], > 0.
      mu: [...] pusher-object friction coefficient [-], >= 0.

    Returns:
      v_p: [..., 2] effective push velocity [same unit as ``action``]; equals ``action`` when
        sticking, its projection along a motion-cone boundary when slipping, 0 when not pushing.
      sticking: [...] bool, True where the pusher pushes and the contact sticks.
    """
    contact, normal, action, l, mu = map(jnp.asarray, (contact, normal, action, l, mu))
    _check_shapes_and_dtypes({"contact": contact, "normal": normal, "action": action, "l": l, "mu": mu})
    dtype = jnp.result_type(contact, normal, action, l, mu, float)
    cx, cy = _split_xy(contact, dtype)
    nx, ny = _split_xy(normal, dtype)
    ux, uy = _split_xy(action, dtype)
    l, mu = jnp.asarray(l, dtype), jnp.asarray(mu, dtype)
    sticking, slipping = _contact_mode(cx, cy, nx, ny, ux, uy, l, mu)
    boundary_x, boundary_y, torque, boundary_velocity_dot_n = _slip_boundary(
        cx, cy, nx, ny, ux, uy, l, mu
    )
    # Slipping moves the contact point along v_pb = A f_b with the pusher's normal velocity.
    ratio = jnp.where(
        slipping, (ux * nx + uy * ny) / jnp.where(slipping, boundary_velocity_dot_n, 1), 0
    )
    l2 = l * l
    vpx = jnp.where(sticking, ux, ratio * (l2 * boundary_x - torque * cy))
    vpy = jnp.where(sticking, uy, ratio * (l2 * boundary_y + torque * cx))
    return jnp.stack([vpx, vpy], axis=-1), sticking


@jax.jit
def object_velocity(contact: jax.Array, v_p: jax.Array, l: jax.Array) -> jax.Array:
    """Object motion caused by moving the contact point with ``v_p`` (quasi-static).

    Args:
      contact: [..., 2] contact point relative to the object's centre of mass [length].
      v_p: [..., 2] effective push velocity [length (per step)].
      l: [...] limit-surface ratio max torque / max force [length], > 0.

    Returns:
      [..., 3] object twist ``(dx, dy, dtheta)``: translation of the centre of mass [length (per
      step)] and rotation [rad (per step)], in the frame of ``contact``.
    """
    contact, v_p, l = map(jnp.asarray, (contact, v_p, l))
    _check_shapes_and_dtypes({"contact": contact, "v_p": v_p, "l": l})
    dtype = jnp.result_type(contact, v_p, l, float)
    cx, cy = _split_xy(contact, dtype)
    vpx, vpy = _split_xy(v_p, dtype)
    return _object_velocity_xy(cx, cy, vpx, vpy, jnp.asarray(l, dtype))


@jax.jit
def predict(
    contact: jax.Array,
    normal: jax.Array,
    action: jax.Array,
    l: jax.Array,
    mu: jax.Array,
    s: jax.Array = 1.0,
) -> jax.Array:
    """Object motion caused by a push: ``object_velocity(contact, s * v_p, l)``.

    Args:
      contact: [..., 2] contact point relative to the object's centre of mass [length].
      normal: [..., 2] surface normal at the contact, pointing into the object; any length,
        zero means no contact.
      action: [..., 2] pusher motion u [length (per step)].
      l: [...] limit-surface ratio max torque / max force [length], > 0.
      mu: [...] pusher-object friction coefficient [-], >= 0.
      s: [...] contact indicator in [0, 1] scaling the effective push velocity.

    Returns:
      [..., 3] object twist ``(dx, dy, dtheta)`` [length (per step), length (per step), rad (per
      step)].
    """
    contact, normal, action, l, mu, s = map(jnp.asarray, (contact, normal, action, l, mu, s))
    _check_shapes_and_dtypes({"contact": contact, "normal": normal, "action": action, "l": l, "mu": mu, "s": s})
    dtype = jnp.result_type(contact, normal, action, l, mu, s, float)
    cx, cy = _split_xy(contact, dtype)
    nx, ny = _split_xy(normal, dtype)
    ux, uy = _split_xy(action, dtype)
    twist = _twist(
        cx, cy, nx, ny, ux, uy,
        jnp.asarray(l, dtype), jnp.asarray(mu, dtype), jnp.asarray(s, dtype),
    )
    return jnp.stack(twist, axis=-1)


@jax.custom_jvp
def _straight_through_push_gate(motion, cx, cy, nx, ny, ux, uy, l, mu, s):
    """`motion` itself; the tangent adds the surrogate of :func:`with_push_gate_gradient`."""
    return motion


@_straight_through_push_gate.defjvp
def _straight_through_push_gate_jvp(primals, tangents):
    motion, cx, cy, nx, ny, ux, uy, l, mu, s = primals
    d_motion, _, _, d_nx, d_ny, d_ux, d_uy, *_ = tangents
    normal_push = ux * nx + uy * ny  # |n| (u . n / |n|): the pusher's speed into the surface, times |n|
    normal_squared = nx * nx + ny * ny
    action_squared = ux * ux + uy * uy
    # The gate normal: perpendicular to u (length |u|), on the side of n; n turned towards u reaches it first.
    side = jnp.where(ux * ny - uy * nx >= 0, 1, -1)
    gate_x, gate_y = -side * uy, side * ux
    boundary_x, boundary_y, torque, boundary_velocity_dot_n = _slip_boundary(
        cx, cy, gate_x, gate_y, ux, uy, l, mu
    )
    gated = (normal_push <= 0) & (normal_squared > 0) & (action_squared > 0) & (boundary_velocity_dot_n > 0)
    safe_normal_squared = jnp.where(gated, normal_squared, 1)
    # |n| times the tangent of u . n / |n| at fixed |n|: d(u . n) with the part of dn along n removed, so the
    # surrogate, like the model, does not depend on the normal's length and only turns the normal.
    d_normal_push = (
        nx * d_ux + ny * d_uy + ux * d_nx + uy * d_ny
        - normal_push * (nx * d_nx + ny * d_ny) / safe_normal_squared
    )
    # d(u . n) / (v_pb . n) (l^2 f_b, c x f_b) at the gate normal scaled to |n| (the factor is homogeneous of
    # degree -1 in the normal, hence |u| / |n|): the slipping twist's derivative just past the gate.
    length_ratio = jnp.sqrt(jnp.where(gated, action_squared / safe_normal_squared, 1))
    ratio = jnp.where(
        gated, s * d_normal_push * length_ratio / jnp.where(gated, boundary_velocity_dot_n, 1), 0
    )
    surrogate = jnp.stack([ratio * l * l * boundary_x, ratio * l * l * boundary_y, ratio * torque], axis=-1)
    return motion, d_motion + surrogate.astype(motion.dtype)


@jax.jit
def with_push_gate_gradient(
    motion: jax.Array,
    contact: jax.Array,
    normal: jax.Array,
    action: jax.Array,
    l: jax.Array,
    mu: jax.Array,
    s: jax.Array = 1.0,
) -> jax.Array:
    """`motion`, bit for bit, with a straight-through derivative through the push gate of Lynch's stage 1.

    A point pusher cannot pull, so the model gives no motion, and no derivative, where ``u . n <= 0``
    (``u = action``, ``n = normal``): a learned normal that faces away from the push, or along it, gets no
    signal from a loss on the motion and is never turned back. Past the gate the push slips, and the twist
    ``s relu(u . n) / (v_pb . n) (l^2 f_b, c x f_b)`` grows linearly in ``u . n`` from zero. Where
    ``u . n <= 0``, this function adds to the derivative of `motion` that slipping derivative with relu's
    derivative taken as 1 (straight-through), evaluated where the normal would cross the gate:
    ``s d(u . n) / (v_pb . n) (l^2 f_b, c x f_b)`` at the normal turned towards ``u`` until perpendicular to
    it (length kept), with the friction-cone boundary ``f_b`` on the side where ``u`` leaves the motion cone
    there. The normal's part of ``d(u . n)`` is turned perpendicular to ``n``, so that, like the model, the
    surrogate does not depend on the normal's length and only turns it: towards ``u`` when the loss asks for
    the motion that crossing the gate would start, away otherwise. At the gate it equals the exact derivative
    from the slipping side, so the derivative is continuous there. Elsewhere (pushing, ``normal = 0``,
    ``action = 0``, or ``v_pb . n <= 0`` at the gate) the derivative is the one of `motion`; it is finite
    everywhere.

    It is meant for training (the hybrid heads wrap their physics in it): the surrogate derivative is not the
    model's, so code that needs the exact derivative (fitting effects, Jacobian tests) calls :func:`predict`
    alone. Forward values never change, so evaluation is unaffected whichever is used.

    Args:
      motion: [..., 3] the twist ``(dx, dy, dtheta)`` predicted for this push, usually ``predict(contact,
        normal, action, l, mu, s)`` [length (per step), length (per step), rad (per step)].
      contact: [..., 2] contact point relative to the object's centre of mass [length].
      normal: [..., 2] surface normal at the contact, pointing into the object; any length,
        zero means no contact.
      action: [..., 2] pusher motion u [length (per step)].
      l: [...] limit-surface ratio max torque / max force [length], > 0.
      mu: [...] pusher-object friction coefficient [-], >= 0.
      s: [...] contact indicator in [0, 1] scaling the effective push velocity.

    Returns:
      [..., 3] `motion`, with the derivative described above.
    """
    motion, contact, normal, action, l, mu, s = map(jnp.asarray, (motion, contact, normal, action, l, mu, s))
    _check_shapes_and_dtypes(
        {"motion": motion, "contact": contact, "normal": normal, "action": action, "l": l, "mu": mu, "s": s}
    )
    batch_shape = jnp.broadcast_shapes(
        motion.shape[:-1], contact.shape[:-1], normal.shape[:-1], action.shape[:-1], l.shape, mu.shape, s.shape
    )
    dtype = jnp.result_type(contact, normal, action, l, mu, s, float)
    cx, cy = _split_xy(contact, dtype)
    nx, ny = _split_xy(normal, dtype)
    ux, uy = _split_xy(action, dtype)
    return _straight_through_push_gate(
        jnp.broadcast_to(motion, (*batch_shape, 3)), cx, cy, nx, ny, ux, uy,
        jnp.asarray(l, dtype), jnp.asarray(mu, dtype), jnp.asarray(s, dtype),
    )


def check_inputs(contact, normal, action, l, mu, s=1.0) -> None:
    """Validates concrete model inputs; raises ``ValueError`` naming the offending argument.

    Meant for user-facing entry points, outside ``jax.jit`` (it converts to NumPy, so it cannot see
    tracers); the jitted model functions themselves never check values. Argument meanings and
    shapes as in :func:`predict`.

    The jitted functions take a normal of any length (and a zero normal as "no contact"); a user's
    input must hold unit normals (length 1 within `NORMAL_LENGTH_TOLERANCE`), so that a zero
    normal, which silently predicts no motion, or an unnormalised one is caught here.

    Raises:
      ValueError: if ``contact``, ``normal`` or ``action`` does not have a trailing axis of size 2,
        the batch shapes do not broadcast, any value is NaN or infinite, a normal is not a unit
        vector, ``l <= 0``, ``mu < 0`` or ``s`` lies outside [0, 1].
    """
    arrays = {
        name: np.asarray(value)
        for name, value in {"contact": contact, "normal": normal, "action": action, "l": l, "mu": mu, "s": s}.items()
    }
    _check_shapes_and_dtypes(arrays)
    for name, value in arrays.items():
        if not np.all(np.isfinite(value)):
            raise ValueError(f"{name}: expected finite values, got NaN or infinity")
    lengths = np.linalg.norm(arrays["normal"], axis=-1)
    off = lengths[np.abs(lengths - 1) > NORMAL_LENGTH_TOLERANCE]
    if off.size:
        zero = " (a zero normal predicts no motion)" if off[0] == 0 else ""
        raise ValueError(f"normal: expected unit vectors (length 1 within {NORMAL_LENGTH_TOLERANCE:g}), got length "
                         f"{off[0]:.6g}{zero}")
    if np.any(arrays["l"] <= 0):
        raise ValueError("l: expected limit-surface ratio > 0")
    if np.any(arrays["mu"] < 0):
        raise ValueError("mu: expected friction coefficient >= 0")
    if np.any((arrays["s"] < 0) | (arrays["s"] > 1)):
        raise ValueError("s: expected contact indicator in [0, 1]")
