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

The package: :mod:`~pushjax.physics.effects.types` (:class:`PushInputs`, :class:`ModelState`, :class:`Effect`), the
effects by what they change (:mod:`~pushjax.physics.effects.centre`: the contact and the centre of friction,
:mod:`~pushjax.physics.effects.forces`: the friction and the forces of the balance,
:mod:`~pushjax.physics.effects.slide`: the slide after the pusher stops, :mod:`~pushjax.physics.effects.exact_surface`:
the exact limit surface), the library in its order of application (:mod:`~pushjax.physics.effects.registry`) and the
solves (:mod:`~pushjax.physics.effects.solve`: the generalised ellipsoid and :func:`compose`). A new effect: its
functions and its :class:`Effect` in the module of what it changes, and its place in ``registry.EFFECTS``.
"""

from pushjax.friction import SPEED_FLOOR, SPEED_REFERENCE
from pushjax.physics.effects.centre import MEAN_SQUARE_RADIUS, SECOND_MOMENT, leading_edge_shift
from pushjax.physics.effects.exact_surface import LIMIT_SURFACE_ITERATIONS, support_pressure
from pushjax.physics.effects.registry import (EFFECT_NAMES, EFFECTS, ELLIPSOID_EFFECTS, compatible, init_params,
                                              needs_support, physical_params, project_params)
from pushjax.physics.effects.solve import compose, limit_surface_predict
from pushjax.physics.effects.types import Effect, ModelState, Params, PushInputs

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
