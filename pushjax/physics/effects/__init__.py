"""Physical effects that the plain Lynch model leaves out, as differentiable augmentations of it.

Every effect is a pure function of named parameters (a dict of arrays, SI units) that start at exact
"no effect" values (all zeros), so a composed model with :func:`init_params` predicts what
:func:`pushjax.physics.lynch.predict` predicts. :func:`compose` builds the augmented model

    predict(params_by_effect, inputs: PushInputs) -> [..., 3] twist (dx m, dy m, dtheta rad)

which is jit-, grad- and vmap-friendly, array in and array out, like ``lynch.predict``.

The model (shared by all effects). The support friction is a generalised ellipsoidal limit surface
``F^T A F = 1`` for the wrench ``F = (f, torque)`` about the centre of friction ``O``, normalised to
the maximal friction force: ``A = diag(A_f, 1 / l^2)`` with the 2x2 force metric ``A_f`` (identity for
isotropic friction). The object's twist about ``O`` is ``V = kappa A F`` (maximal dissipation). The
pusher force ``f`` at the contact ``c`` (relative to ``O``) and an optional constant in-plane force
``g`` at ``O`` (fraction of the maximal friction force, e.g. gravity on a tilted table) make up
``F = (f + g, c x f)``. With ``J`` mapping the twist to the contact point's velocity and
``M = J A J^T = A_f + (k x c)(k x c)^T / l^2``:

* sticking: the contact point moves with the pusher, ``J V = u``. Solving with ``F`` on the limit
  surface gives ``V = A J^T M^-1 u + A Q sqrt(u^T M^-1 u) / sqrt(1 - q)`` with
  ``Q = (g, 0) - J^T M^-1 A_f g`` and ``q = g^T A_f g - (A_f g)^T M^-1 (A_f g)``. The first term is
  Lynch's sticking twist; the second, proportional to how far the object is pushed, turns the object
  about the contact point (``J A Q = 0``).
* slipping: ``f`` lies on the friction-cone boundary ``f_b = n +- mu (k x n)`` on the side where the
  sticking force leaves the cone; ``f = lambda f_b`` with ``F`` on the limit surface, and ``kappa``
  matches the pusher's normal velocity ``u . n``.

For ``A_f = I`` and ``g = 0`` this is exactly Lynch's model, and :func:`compose` calls
:func:`~pushjax.physics.lynch.predict` itself unless ``anisotropic_friction`` or ``table_tilt`` is
composed. The effects (the keys of :data:`EFFECTS`, applied in this order whatever the order asked):

``frame_offset``  {"offset": [2] m, object axes}
    The tracked (recorded) frame sits at ``offset`` from the frame the object's geometry is defined
    in, e.g. a motion-capture marker bias. Contacts were annotated on an outline placed ``offset``
    away from the true one, so the true outline is shifted by ``-R offset``: the contact moves along
    the side, the first contact comes earlier or later (the pusher's gap to the surface changes by the
    shift's normal part; a contact annotated beyond the window may come into it), and the reported
    motion is that of a point ``offset`` away from the centre. First order in the shift: the side is
    taken as straight at the annotated contact.
``cof_offset``  {"offset": [2] m, object axes}
    The centre of friction (of the support pressure) is at ``offset`` from the nominal centre of mass,
    e.g. a hidden weight that moves the centre of mass and with it the pressure centre. The limit
    surface is centred there; the contact geometry is unchanged.
``friction_ratio``  {"log_scale": [] -}
    The limit-surface ratio ``l = m_max / f_max`` is ``exp(log_scale)`` times the uniform-pressure
    value (non-uniform support pressure: rim-loaded plates spin harder, ``log_scale > 0``).
``anisotropic_friction``  {"log_metric": [2] -, object axes}
    Support friction differs along two object axes (a grain): ``A_f = R exp(S) R^T`` with the
    traceless symmetric ``S = [[a, b], [b, -a]]``, ``(a, b) = log_metric``, so that
    ``det A_f = 1``. The friction force limits along the principal axes differ by the ratio
    ``exp(sqrt(a^2 + b^2))``.
``pusher_friction``  {"log_scale": [] -}
    The pusher-object Coulomb coefficient is ``exp(log_scale)`` times the nominal ``mu``.
``table_tilt``  {"drift_force": [2] -, world axes}
    The support is tilted: gravity has the in-plane component ``m g sin(tilt)`` downhill, which
    relative to the maximal friction force ``mu_s m g cos(tilt)`` is ``drift_force``
    (``|drift_force| = tan(tilt) / mu_s``, pointing downhill). Below the friction angle the object
    stays put unless pushed; while pushed it drifts downhill in proportion to how far it slides.
``inertia``  {"inverse_deceleration": [] s^2/m, >= 0}
    Non-quasi-static motion: when the pusher stops, the object keeps sliding at the speed the push
    gave it, ``v = push_speed |V| / |u|`` (``|V|`` the motion of a point at distance ``l``),
    decelerated by Coulomb friction at ``a = 1 / inverse_deceleration`` (``= mu_s g``). Within the
    time ``t`` left after the stop it slides ``v t - a t^2 / 2`` until it stops after the decay length
    ``v^2 / (2 a)``, along its last motion: the dynamics after contact is lost.

``friction_field``  {"gradient": [2] 1/m, "curvature": [3] 1/m^2 (xx, xy, yy), world axes}
    The support friction varies smoothly over the table: ``log mu(p) = g . p + p^T H p / 2`` (a low-order
    field over the table position ``p`` of the centre of mass; a uniform change cancels in quasi-static
    pushing). Across the plate the coefficient changes by ``exp(grad log mu . r)``, which moves the centre of
    friction by the support's second moment times the gradient, ``(9/16) l^2 grad log mu(p)`` (a disc's
    moment, isotropic approximation), world axes: the same push at another place of the table turns the
    object differently.
``friction_speed``  {"inverse_deceleration": [] s^2/m, >= 0, "gain": [] per decade}
    The support coefficient depends on the sliding speed, ``mu(v) = mu_ref (1 + gain log10(v / 20 mm/s))``
    (clipped at ``0.1 mu_ref``, constant below 1 mm/s). In quasi-static pushing a uniform coefficient cancels;
    it shows in the slide after the pusher stops (as ``inertia``, which is ``gain = 0``), decelerated at
    ``a(v) = a_ref mu(v) / mu_ref`` for the speed ``v`` the push gave the object.
``pressure_gradient``  {"offset": [2] m, object axes}
    A support pressure that rises linearly across the plate (a warped plate, a hidden weight): it moves the
    centre of friction by ``offset`` and, about the new centre, leaves the mean squared radius
    ``E|r|^2 - |offset|^2``, so ``l`` shrinks to ``l sqrt(1 - |offset|^2 / ((9/8) l^2))`` (a disc's
    ``E|r|^2 = (9/8) l^2``). One mechanism, so the shift and ``l`` move together (unlike ``cof_offset`` plus
    ``friction_ratio``).

``leading_edge``  {"lever": [] m}
    The pusher presses on the object's side at a height ``h`` above the table, while the table's friction acts at the
    base: the moment of the pushing force tips the support pressure towards the leading edge. Moment balance about the
    base (quasi-static, vertical forces from gravity and the table only) moves the centre of pressure by
    ``h F / (m g) = mu_table h f``, with ``f`` the pusher's force over the maximal friction force ``mu_table m g``,
    world axes; ``lever = mu_table h`` (``mu_table t / 2`` for a plate of thickness ``t`` pushed at half its height,
    e.g. 2.2 mm for rect1 on polyurethane), the shift of a plate the pusher slides along (``|f| = 1``). ``f`` is the
    force of Lynch's ellipsoid on the state the other effects leave (:func:`leading_edge_shift`: along ``P u`` while
    the contact sticks, the friction cone's boundary while it slips), so the shift is first order in ``lever``.
    The centre of friction moves by the shift, the contact geometry stays (as ``cof_offset``, but the shift follows
    each push's force). A negative ``lever`` moves the load backwards, which no pusher's height gives.
``limit_surface``  {"rim": [] -, "feet": [] share in [0, 1]}
    The exact limit surface of the support instead of Lynch's ellipsoid (which matches the exact one only at
    pure translation and pure rotation): the quasi-static, maximal-dissipation twist of the support described by
    ``PushInputs.support_points``, ``support_weights`` (area weights of cells of the footprint,
    :func:`pushjax.geometry.support_cells`) and ``support_feet`` (the corners of the footprint's convex hull,
    :func:`pushjax.geometry.support_feet`), solved by :func:`pushjax.physics.limit_surface.predict`. Over the
    footprint the pressure is ``area_k exp(rim (|r_k|^2 / E|r|^2 - 1))``: ``rim > 0`` loads the rim (a plate resting
    on its edge spins harder), ``rim < 0`` the centre. A share ``feet`` of the load rests on the hull's corners
    instead (a base that is not flat, stiff feet: the outermost support an object can have, balanced under its
    centre of mass). A moved centre of pressure is ``cof_offset``, which moves this support with it. It replaces the
    ellipsoid, so its zero parameter is the exact surface of a uniform pressure, not Lynch's model; it cannot be
    composed with the effects that change the ellipsoid (:data:`EFFECTS`' ``excludes``: ``friction_ratio`` and
    ``pressure_gradient``, whose ``l`` it does not use, and ``anisotropic_friction``, which the exact surface does not
    model).

All branches are double-``where`` selections, so gradients are finite everywhere, including the
no-effect parameters, ``normal = 0``, ``action = 0`` and ``s = 0``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import flax.struct
import jax
import jax.numpy as jnp

from pushjax.physics import limit_surface as exact_limit_surface
from pushjax.physics import lynch

__all__ = [
    "EFFECTS",
    "EFFECT_NAMES",
    "ELLIPSOID_EFFECTS",
    "Effect",
    "ModelState",
    "PushInputs",
    "compatible",
    "compose",
    "init_params",
    "leading_edge_shift",
    "limit_surface_predict",
    "needs_support",
    "physical_params",
    "project_params",
    "support_pressure",
]

Params = dict[str, jax.Array]


@flax.struct.dataclass
class PushInputs:
    """Inputs of the augmented pushing model; leading batch axes broadcast against each other.

    Attributes:
      contact: [..., 2] contact point relative to the nominal centre of mass, world axes, m. With
        ``s = 0`` it may be the point the pusher would touch if it went on beyond the window.
      normal: [..., 2] unit surface normal at the contact pointing into the object, world axes;
        zero means that the pusher does not reach the object.
      action: [..., 2] pusher displacement after the first contact, world axes, m.
      pusher_motion: [..., 2] pusher displacement over the whole prediction window, m.
      gap: [...] distance the pusher travels along ``normal`` before it touches, m (negative when it
        starts penetrating the annotated outline, beyond the window's approach when ``s = 0``; 0
        without a normal).
      l: [...] nominal limit-surface ratio, m.
      mu: [...] nominal pusher-object friction coefficient.
      s: [...] contact indicator in [0, 1] (0 when the pusher does not touch within the window).
      object_yaw: [...] orientation of the object (tracked frame) in the world, rad.
      push_speed: [...] pusher speed when it stops in the window, or at the window's end, m/s.
      time_after_stop: [...] time from the pusher's stop to the window's end, s (0: still moving).
      object_position: [..., 2] position of the nominal centre of mass on the table at the window's start,
        world axes, m.
      support_points: [..., K, 2] points of the object's support relative to the nominal centre of mass, object
        axes, m: the footprint's cells (:func:`pushjax.geometry.support_cells`) and the corners of its convex hull
        (:func:`pushjax.geometry.support_feet`); None when unknown (``limit_surface`` needs them).
      support_weights: [..., K] their area weights (>= 0; zero for the hull's corners and padding); None with
        ``support_points``.
      support_feet: [..., K] the loads of the object resting on its hull's corners (>= 0, summing to 1; zero for the
        cells and padding); None: no corners among the points.
      patch_radius: [...] the radius of a support's patch, m (the solve's regularisation length).
    """

    contact: jax.Array
    normal: jax.Array
    action: jax.Array
    pusher_motion: jax.Array
    gap: jax.Array
    l: jax.Array
    mu: jax.Array
    s: jax.Array
    object_yaw: jax.Array
    push_speed: jax.Array
    time_after_stop: jax.Array
    object_position: jax.Array
    support_points: jax.Array | None = None
    support_weights: jax.Array | None = None
    patch_radius: jax.Array | None = None
    support_feet: jax.Array | None = None

    @classmethod
    def create(cls, contact, normal, action, l, mu, s=1.0, *, pusher_motion=None, gap=0.0,
               object_yaw=0.0, push_speed=0.0, time_after_stop=0.0, object_position=(0.0, 0.0),
               support_points=None, support_weights=None, patch_radius=None, support_feet=None) -> PushInputs:
        """Inputs from ``lynch.predict``'s arguments; the others default to a pusher in contact
        (``pusher_motion = action``, ``gap = 0``), object yaw 0 at the table's origin, a pusher that does
        not stop and an unknown support."""
        action = jnp.asarray(action)

        def optional(value):
            return None if value is None else jnp.asarray(value)

        return cls(
            contact=jnp.asarray(contact), normal=jnp.asarray(normal), action=action,
            pusher_motion=action if pusher_motion is None else jnp.asarray(pusher_motion),
            gap=jnp.asarray(gap), l=jnp.asarray(l), mu=jnp.asarray(mu), s=jnp.asarray(s),
            object_yaw=jnp.asarray(object_yaw), push_speed=jnp.asarray(push_speed),
            time_after_stop=jnp.asarray(time_after_stop), object_position=jnp.asarray(object_position),
            support_points=optional(support_points), support_weights=optional(support_weights),
            patch_radius=optional(patch_radius), support_feet=optional(support_feet),
        )


@flax.struct.dataclass
class ModelState:
    """What the effects change before the limit-surface solve (world axes, batch-shaped).

    Attributes:
      contact: [..., 2] contact relative to the centre of friction, m.
      normal, action, l, mu, s: as in :class:`PushInputs`.
      centre: [..., 2] centre of friction relative to the nominal centre of mass, m.
      metric: (A_xx, A_xy, A_yy) force metric of the limit surface, each [...].
      drift_force: [..., 2] constant in-plane force at the centre over the maximal friction force.
    """

    contact: jax.Array
    normal: jax.Array
    action: jax.Array
    l: jax.Array
    mu: jax.Array
    s: jax.Array
    centre: jax.Array
    metric: tuple[jax.Array, jax.Array, jax.Array]
    drift_force: jax.Array


def _identity(params: Params) -> Params:
    return params


@dataclasses.dataclass(frozen=True, kw_only=True)
class Effect:
    """One library effect (see the module docstring for the physics of each).

    Attributes:
      name: library name.
      init: the "no effect" parameters, {name: zeros of the parameter's shape}.
      typical: {name: typical magnitude}, for conditioning optimisers.
      modify: (params, state, inputs) -> state, applied before the solve, or None (the default).
      correct: (params, twist, state, inputs) -> twist, applied to the predicted twist of the push, or None (the
        default); with several, their changes add up (each sees the push's twist, not another's correction).
      project: params -> params inside the physically valid set (default: all parameters are valid).
      physical: params -> {readable name with unit: scalar}, the values to report.
      general_solver: whether the effect needs the generalised solver (not plain Lynch).
      solve: (params, state, inputs) -> twist about the centre of friction, replacing the ellipsoidal solve, or
        None (at most one composed effect has one).
      excludes: effects that cannot be composed with this one.
      per_object: whether the parameters describe one object (its support, a marker, a hidden weight) rather than
        the table, the pusher or the dynamics, so that they may differ between objects.
    """

    name: str
    init: Callable[[], Params]
    typical: dict[str, float]
    physical: Callable[[Params], dict[str, jax.Array]]
    modify: Callable[[Params, ModelState, PushInputs], ModelState] | None = None
    correct: Callable[[Params, jax.Array, ModelState, PushInputs], jax.Array] | None = None
    project: Callable[[Params], Params] = _identity
    general_solver: bool = False
    solve: Callable[[Params, ModelState, PushInputs], jax.Array] | None = None
    excludes: tuple[str, ...] = ()
    per_object: bool = False


def _rotate(vector: jax.Array, yaw: jax.Array) -> jax.Array:
    """[..., 2] vectors turned counter-clockwise by ``yaw`` [...] rad."""
    cos, sin = jnp.cos(yaw), jnp.sin(yaw)
    return jnp.stack([cos * vector[..., 0] - sin * vector[..., 1],
                      sin * vector[..., 0] + cos * vector[..., 1]], axis=-1)


def _dot(a: jax.Array, b: jax.Array) -> jax.Array:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def _safe_norm(vector: jax.Array) -> tuple[jax.Array, jax.Array]:
    """(|v|, |v| > 0) with a finite gradient at v = 0."""
    squared = _dot(vector, vector)
    positive = squared > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, squared, 1.0)), 0.0), positive


def _safe_sqrt(value: jax.Array) -> jax.Array:
    positive = value > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, value, 1.0)), 0.0)


# --------------------------------------------------------------------------------------------------
# The effects


def _frame_offset_modify(params, state, inputs):
    shift = -_rotate(params["offset"], inputs.object_yaw)  # true outline minus annotated outline
    length, touching = _safe_norm(state.normal)
    unit_normal = state.normal / jnp.where(touching, length, 1.0)[..., None]
    approach = _dot(inputs.pusher_motion, unit_normal)
    moving_in = approach > 0

    def contact_fraction(gap):
        return jnp.where(moving_in, jnp.clip(gap / jnp.where(moving_in, approach, 1.0), 0.0, 1.0), 0.0)

    delay = contact_fraction(inputs.gap + _dot(shift, unit_normal)) - contact_fraction(inputs.gap)
    slide = delay[..., None] * inputs.pusher_motion - shift
    along_side = slide - _dot(slide, unit_normal)[..., None] * unit_normal
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
    offset = _rotate(params["offset"], inputs.object_yaw)
    return state.replace(contact=state.contact - offset, centre=state.centre + offset)


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
    length, _ = _safe_norm(force)
    return {"drift_force": force * jnp.minimum(1.0, _MAX_DRIFT_FORCE / jnp.maximum(length, 1e-12))[..., None]}


def _table_tilt_physical(params):
    force = params["drift_force"]
    return {"drift_over_friction": jnp.hypot(force[..., 0], force[..., 1]),
            "downhill_azimuth_deg": jnp.degrees(jnp.arctan2(force[..., 1], force[..., 0]))}


def _slide_after_contact(twist, state, inputs, inverse_deceleration_at):
    """The twist plus the slide after the pusher stops, decelerated at ``1 / inverse_deceleration_at(speed)``."""
    motion, moving = _safe_norm(jnp.stack([_safe_norm(twist[..., :2])[0], state.l * twist[..., 2]], -1))
    push, pushed = _safe_norm(state.action)
    speed = inputs.push_speed * motion / jnp.where(pushed, push, 1.0)
    inverse_deceleration = inverse_deceleration_at(speed)
    time = inputs.time_after_stop
    # v^2 / (2 a) when the object stops within the window (v / a < t), else v t - a t^2 / 2; written with
    # 1 / a, which is 0 without effect.
    stops = speed * inverse_deceleration < time
    safe_inverse = jnp.where(inverse_deceleration > 0, inverse_deceleration, 1.0)
    slide = jnp.where(stops, 0.5 * speed * speed * inverse_deceleration, speed * time - time * time / (2 * safe_inverse))
    factor = jnp.where(moving & pushed, slide / jnp.where(moving, motion, 1.0), 0.0)
    return twist * (1.0 + factor[..., None])


def _inertia_correct(params, twist, state, inputs):
    return _slide_after_contact(twist, state, inputs, lambda speed: params["inverse_deceleration"])


def _speed_factor(gain, speed):
    """Support friction at ``speed`` [...] (m/s) over that at :data:`SPEED_REFERENCE`."""
    return jnp.maximum(1.0 + gain * jnp.log10(jnp.maximum(speed, SPEED_FLOOR) / SPEED_REFERENCE), 0.1)


def _friction_speed_correct(params, twist, state, inputs):
    return _slide_after_contact(twist, state, inputs,
                                lambda speed: params["inverse_deceleration"] / _speed_factor(params["gain"], speed))


def _friction_speed_project(params):
    return {"inverse_deceleration": jnp.maximum(params["inverse_deceleration"], 0.0), "gain": params["gain"]}


def _friction_speed_physical(params):
    return {**_inertia_physical(params), "gain_per_decade": params["gain"]}


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
    offset = _rotate(params["offset"], inputs.object_yaw)
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
    """How far the pushing force tips the support pressure towards the leading edge (see ``leading_edge``).

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


def _inertia_project(params):
    return {"inverse_deceleration": jnp.maximum(params["inverse_deceleration"], 0.0)}


def _inertia_physical(params):
    inverse = params["inverse_deceleration"]
    return {"inverse_deceleration_s2_per_m": inverse,
            "decay_length_mm_at_100_mm_s": 1e3 * 0.5 * 0.1 ** 2 * inverse}


def support_pressure(params: Params, points: jax.Array, area: jax.Array, feet: jax.Array | None = None) -> jax.Array:
    """[..., K] normalised support pressure of ``limit_surface`` (see the module docstring).

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
    world = _rotate(points, jnp.asarray(inputs.object_yaw)[..., None])
    return exact_limit_surface.predict(state.contact, state.normal, state.action, state.mu, world, pressure,
                                       inputs.patch_radius, state.s, state.drift_force,
                                       stick_iterations=LIMIT_SURFACE_ITERATIONS[0],
                                       slip_iterations=LIMIT_SURFACE_ITERATIONS[1])


def _limit_surface_physical(params):
    return {"rim": params["rim"], "feet": params["feet"]}


def _limit_surface_project(params):
    return {**params, "feet": jnp.clip(params["feet"], 0.0, 1.0)}


LIMIT_SURFACE_ITERATIONS = (5, 6)
"""Newton iterations (sticking, slipping) of ``limit_surface``'s solve: with the support cells' patches (radius about an
eighth of the plate's) the twists of the loop's windows agree with 20 iterations' to 1e-7 relative in float32 from 4
and 5 on; one more each for margin (fewer iterations are the fit's largest saving)."""
SPEED_REFERENCE = 0.02
"""Sliding speed (m/s) at which ``friction_speed``'s coefficient is the reference one (the MIT grid's 20 mm/s)."""
SPEED_FLOOR = 1e-3
"""Sliding speed (m/s) below which ``friction_speed``'s coefficient stops changing."""
SECOND_MOMENT = 9 / 16
"""Second moment of a plate's support per axis over l^2 (a uniform disc's: R^2 / 4 with l = 2 R / 3)."""
MEAN_SQUARE_RADIUS = 9 / 8
"""Mean squared distance of a plate's support from its centre over l^2 (a uniform disc's; 1.14 for a square)."""
_MAX_DRIFT_FORCE = 0.95
"""Largest in-plane force over the maximal friction force: beyond 1 the object slides away unpushed."""


def _zeros(**shapes):
    return lambda: {name: jnp.zeros(shape) for name, shape in shapes.items()}


EFFECTS: dict[str, Effect] = {
    effect.name: effect
    for effect in (
        Effect(name="frame_offset", init=_zeros(offset=(2,)), typical={"offset": 0.01}, modify=_frame_offset_modify,
               physical=_offset_physical, per_object=True),
        Effect(name="cof_offset", init=_zeros(offset=(2,)), typical={"offset": 0.01}, modify=_cof_offset_modify,
               physical=_offset_physical, per_object=True),
        Effect(name="friction_ratio", init=_zeros(log_scale=()), typical={"log_scale": 0.3},
               modify=_friction_ratio_modify, physical=lambda p: {"scale": jnp.exp(p["log_scale"])}, per_object=True),
        Effect(name="anisotropic_friction", init=_zeros(log_metric=(2,)), typical={"log_metric": 0.5},
               modify=_anisotropic_friction_modify, physical=_anisotropic_friction_physical, general_solver=True),
        Effect(name="pusher_friction", init=_zeros(log_scale=()), typical={"log_scale": 0.5},
               modify=_pusher_friction_modify, physical=lambda p: {"mu_scale": jnp.exp(p["log_scale"])}),
        Effect(name="table_tilt", init=_zeros(drift_force=(2,)), typical={"drift_force": 0.2},
               modify=_table_tilt_modify, project=_table_tilt_project, physical=_table_tilt_physical,
               general_solver=True),
        Effect(name="inertia", init=_zeros(inverse_deceleration=()), typical={"inverse_deceleration": 0.3},
               correct=_inertia_correct, project=_inertia_project, physical=_inertia_physical),
        Effect(name="friction_field", init=_zeros(gradient=(2,), curvature=(3,)),
               typical={"gradient": 3.0, "curvature": 30.0}, modify=_friction_field_modify,
               physical=_friction_field_physical),
        Effect(name="friction_speed", init=_zeros(inverse_deceleration=(), gain=()),
               typical={"inverse_deceleration": 0.3, "gain": 0.3}, correct=_friction_speed_correct,
               project=_friction_speed_project, physical=_friction_speed_physical),
        Effect(name="pressure_gradient", init=_zeros(offset=(2,)), typical={"offset": 0.01},
               modify=_pressure_gradient_modify, physical=_pressure_gradient_physical, per_object=True),
        Effect(name="leading_edge", init=_zeros(lever=()), typical={"lever": 0.003}, modify=_leading_edge_modify,
               physical=lambda p: {"lever_mm": 1e3 * p["lever"]}),
        Effect(name="limit_surface", init=_zeros(rim=(), feet=()), typical={"rim": 1.0, "feet": 0.3},
               physical=_limit_surface_physical, project=_limit_surface_project, solve=_limit_surface_solve, excludes=("friction_ratio", "pressure_gradient", "anisotropic_friction"),
               per_object=True),
    )
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


def _check_names(names: Sequence[str]) -> tuple[str, ...]:
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
    return {name: EFFECTS[name].init() for name in _check_names(names)}


def project_params(params_by_effect: dict[str, Params]) -> dict[str, Params]:
    """Parameters moved into their valid set (e.g. ``inverse_deceleration >= 0``)."""
    return {name: EFFECTS[name].project(params) for name, params in params_by_effect.items()}


def physical_params(params_by_effect: dict[str, Params]) -> dict[str, dict[str, jax.Array]]:
    """Readable values (names carry units) of the parameters, {effect: {value name: value}}."""
    return {name: EFFECTS[name].physical(params) for name, params in params_by_effect.items()}


# --------------------------------------------------------------------------------------------------
# The generalised limit-surface solve


def limit_surface_predict(contact, normal, action, l, mu, s=1.0, metric=None, drift_force=None) -> jax.Array:
    """Object twist under a generalised ellipsoidal limit surface (see the module docstring).

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
    sigma = _safe_sqrt(ux * adj_ux + uy * adj_uy)  # sqrt(det u^T M^-1 u)
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


# --------------------------------------------------------------------------------------------------
# Composition


def compose(names: Sequence[str]) -> Callable[[dict[str, Params], PushInputs], jax.Array]:
    """The pushing model augmented by the named effects (applied in library order).

    Args:
      names: effect names from :data:`EFFECT_NAMES`; empty gives the plain Lynch model.

    Returns:
      ``predict(params_by_effect, inputs) -> [..., 3]`` twist of the nominal centre of mass (dx m,
      dy m, dtheta rad, world axes) over the window; ``params_by_effect`` holds one parameter dict
      per composed effect (see :func:`init_params`).
    """
    names = _check_names(names)
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
