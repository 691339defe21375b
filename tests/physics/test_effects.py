"""Tests of the effect library: no-effect defaults, differentiability, and the physics of each effect."""

import itertools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.physics import effects, lynch
from pushjax.physics import limit_surface as exact_limit_surface


def _unit(angle):
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def _random_inputs(seed, count=5000, dtype=np.float32):
    """Pushes covering sticking, slipping both ways, pulling, far contacts, stops and no contact."""
    rng = np.random.default_rng(seed)
    l = rng.uniform(0.02, 0.06, count)
    contact = _unit(rng.uniform(-np.pi, np.pi, count)) * (l * rng.uniform(0, 2, count))[:, None]
    normal_angle = rng.uniform(-np.pi, np.pi, count)
    normal = _unit(normal_angle) * (rng.uniform(size=count) > 0.05)[:, None]
    action = _unit(normal_angle + rng.uniform(-1.1, 1.1, count) * np.pi / 2) * rng.uniform(1e-4, 0.02, count)[:, None]
    motion = action * rng.uniform(1, 1.5, count)[:, None]
    values = dict(contact=contact, normal=normal, action=action, l=l, mu=rng.uniform(0, 1.5, count),
                  s=(rng.uniform(size=count) > 0.1).astype(float), pusher_motion=motion,
                  gap=rng.uniform(-0.002, 0.005, count), object_yaw=rng.uniform(-np.pi, np.pi, count),
                  push_speed=rng.uniform(0.01, 0.5, count), time_after_stop=rng.uniform(0, 0.5, count)
                  * (rng.uniform(size=count) > 0.5), object_position=rng.uniform(-0.2, 0.2, (count, 2)))
    return effects.PushInputs(**{name: jnp.asarray(value, dtype) for name, value in values.items()})


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _lynch(inputs):
    return lynch.predict(inputs.contact, inputs.normal, inputs.action, inputs.l, inputs.mu, inputs.s)


def _random_params(seed):
    rng = np.random.default_rng(seed)
    return {
        "frame_offset": {"offset": jnp.asarray(rng.normal(0, 0.005, 2), jnp.float32)},
        "cof_offset": {"offset": jnp.asarray(rng.normal(0, 0.005, 2), jnp.float32)},
        "friction_ratio": {"log_scale": jnp.asarray(rng.normal(0, 0.3), jnp.float32)},
        "anisotropic_friction": {"log_metric": jnp.asarray(rng.normal(0, 0.4, 2), jnp.float32)},
        "pusher_friction": {"log_scale": jnp.asarray(rng.normal(0, 0.3), jnp.float32)},
        "table_tilt": {"drift_force": jnp.asarray(rng.normal(0, 0.2, 2), jnp.float32)},
        "inertia": {"inverse_deceleration": jnp.asarray(rng.uniform(0, 1), jnp.float32)},
        "friction_field": {"gradient": jnp.asarray(rng.normal(0, 1, 2), jnp.float32),
                           "curvature": jnp.asarray(rng.normal(0, 5, 3), jnp.float32)},
        "friction_speed": {"inverse_deceleration": jnp.asarray(rng.uniform(0, 1), jnp.float32),
                           "gain": jnp.asarray(rng.normal(0, 0.3), jnp.float32)},
        "pressure_gradient": {"offset": jnp.asarray(rng.normal(0, 0.005, 2), jnp.float32)},
        "leading_edge": {"lever": jnp.asarray(rng.uniform(0, 0.005), jnp.float32)},
    }


@pytest.mark.parametrize("names", [(), *[(name,) for name in effects.ELLIPSOID_EFFECTS], effects.ELLIPSOID_EFFECTS])
def test_no_effect_parameters_reproduce_lynch(names):
    inputs = _random_inputs(0)
    predicted = jax.jit(effects.compose(names))(effects.init_params(names), inputs)
    np.testing.assert_allclose(predicted, _lynch(inputs), rtol=0, atol=1e-7)


def test_generalised_solver_is_lynch_for_isotropic_friction_in_float64():
    with jax.enable_x64(True):
        inputs = _random_inputs(1, dtype=np.float64)
        expected = np.asarray(_lynch(inputs))
        predicted = np.asarray(effects.limit_surface_predict(inputs.contact, inputs.normal, inputs.action, inputs.l,
                                                             inputs.mu, inputs.s))
    np.testing.assert_allclose(predicted, expected, rtol=0, atol=1e-13 * np.abs(expected).max())


_ELLIPSOID_MODEL = effects.compose(effects.ELLIPSOID_EFFECTS)
_SQUARED_ERROR_GRADIENT = jax.jit(jax.grad(
    lambda params, inputs, target: jnp.sum((_ELLIPSOID_MODEL(params, inputs) - target) ** 2), argnums=(0, 1)))
"""d/d(params, inputs) of sum |model(params, inputs) - target|^2 for every ellipsoid effect at once: one program for
the two tests below (2000 pushes each), not their gradients eagerly, op by op."""


def test_gradients_are_finite_at_no_effect_and_degenerate_inputs():
    inputs = _random_inputs(2, count=2000)
    zero = jnp.zeros_like(inputs.normal)
    degenerate = [inputs, inputs.replace(normal=zero), inputs.replace(action=zero, pusher_motion=zero),
                  inputs.replace(s=jnp.zeros_like(inputs.s)), inputs.replace(contact=zero)]
    for case, params in itertools.product(degenerate, (effects.init_params(), _random_params(3))):
        gradient = _SQUARED_ERROR_GRADIENT(params, case, jnp.zeros((len(case.mu), 3)))
        assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree.leaves(gradient))


def test_gradient_at_no_effect_points_somewhere_for_every_effect():
    inputs = _random_inputs(4, count=2000)
    target = jax.jit(_ELLIPSOID_MODEL)(_random_params(5), inputs)
    gradient, _ = _SQUARED_ERROR_GRADIENT(effects.init_params(), inputs, target)
    for name in effects.ELLIPSOID_EFFECTS:
        assert any(np.any(np.asarray(leaf) != 0) for leaf in jax.tree.leaves(gradient[name])), name


def test_composition_order_does_not_matter_and_names_are_checked():
    inputs = _random_inputs(6, count=500)
    params = _random_params(7)
    forward = effects.compose(effects.ELLIPSOID_EFFECTS)(params, inputs)
    backward = effects.compose(effects.ELLIPSOID_EFFECTS[::-1])(params, inputs)
    np.testing.assert_array_equal(forward, backward)
    with pytest.raises(ValueError, match="unknown 'gravity'"):
        effects.compose(["gravity"])
    with pytest.raises(ValueError, match="missing parameters of cof_offset"):
        effects.compose(["cof_offset"])({}, inputs)


def test_vmaps_over_parameter_sets():
    inputs = _random_inputs(8, count=300)
    model = effects.compose(effects.ELLIPSOID_EFFECTS)
    stacked = jax.tree.map(lambda *leaves: jnp.stack(leaves), *(_random_params(seed) for seed in range(3)))
    batched = jax.jit(jax.vmap(model, in_axes=(0, None)))(stacked, inputs)
    one = jax.jit(model)  # one program for the three parameter sets, not each op by op
    for k in range(3):
        np.testing.assert_allclose(batched[k], one(_random_params(k), inputs), rtol=1e-5, atol=1e-7)


def test_friction_ratio_and_pusher_friction_scale_l_and_mu():
    inputs = _random_inputs(9)
    scale = np.float32(1.7)
    log = {"log_scale": jnp.log(scale)}
    np.testing.assert_allclose(
        effects.compose(["friction_ratio"])({"friction_ratio": log}, inputs),
        lynch.predict(inputs.contact, inputs.normal, inputs.action, inputs.l * scale, inputs.mu, inputs.s), atol=1e-7)
    np.testing.assert_allclose(
        effects.compose(["pusher_friction"])({"pusher_friction": log}, inputs),
        lynch.predict(inputs.contact, inputs.normal, inputs.action, inputs.l, inputs.mu * scale, inputs.s), atol=1e-7)


def test_push_through_the_centre_of_friction_translates_it_without_rotation():
    offset = np.array([0.01, -0.005])
    yaw = 0.7
    centre_world = np.array([np.cos(yaw) * offset[0] - np.sin(yaw) * offset[1],
                             np.sin(yaw) * offset[0] + np.cos(yaw) * offset[1]])
    normal = np.array([1.0, 0.0])
    contact = centre_world - 0.03 * normal
    inputs = effects.PushInputs.create(contact, normal, 0.01 * normal, 0.03, 0.3, object_yaw=yaw)
    twist = effects.compose(["cof_offset"])({"cof_offset": {"offset": jnp.asarray(offset)}}, inputs)
    np.testing.assert_allclose(twist, [0.01, 0.0, 0.0], atol=1e-8)
    # Without the offset the same push is off-centre and turns the object.
    assert abs(float(_lynch(inputs)[2])) > 0.01


def test_frame_offset_moves_the_contact_along_the_side_and_delays_it():
    # Flat side facing -x at x = -0.04 (object yaw 0): the pusher moves +x by 10 mm and touches after 2 mm.
    normal = np.array([1.0, 0.0])
    motion = np.array([0.01, 0.0])
    inputs = effects.PushInputs.create([-0.04, 0.01], normal, 0.8 * motion, 0.03, 10.0, pusher_motion=motion,
                                       gap=0.002)
    model = effects.compose(["frame_offset"])
    # The tracked frame sits at (-3, +4) mm in the geometry's frame, so the true outline is (+3, -4) mm
    # from the annotated one: the side is reached 3 mm later (after half the motion) and the contact lies
    # 4 mm further along +y from the true centre, which the reported point trails by (-3, +4) mm.
    twist = model({"frame_offset": {"offset": jnp.asarray([-0.003, 0.004])}}, inputs)
    centre_twist = lynch.predict(jnp.asarray([-0.04, 0.014]), normal, 0.5 * motion, 0.03, 10.0)
    omega = centre_twist[2]
    expected = centre_twist + jnp.asarray([omega * -0.004, omega * -0.003, 0.0])
    np.testing.assert_allclose(twist, expected, rtol=1e-6, atol=1e-9)
    # Moved the other way, the side is touched from the start: the whole motion pushes.
    closer = model({"frame_offset": {"offset": jnp.asarray([0.003, 0.0])}}, inputs)
    centre_twist = lynch.predict(jnp.asarray([-0.04, 0.01]), normal, motion, 0.03, 10.0)
    expected = centre_twist + jnp.asarray([0.0, centre_twist[2] * 0.003, 0.0])
    np.testing.assert_allclose(closer, expected, rtol=1e-6, atol=1e-9)


def test_frame_offset_brings_a_contact_beyond_the_window_into_it():
    # The annotated side is 12 mm ahead of a pusher that moves 10 mm: no contact (s = 0, no action), but
    # with the outline really 4 mm closer the pusher touches after 8 mm and pushes for 2 mm.
    normal = np.array([1.0, 0.0])
    motion = np.array([0.01, 0.0])
    inputs = effects.PushInputs.create([-0.04, 0.0], normal, np.zeros(2), 0.03, 10.0, s=0.0, pusher_motion=motion,
                                       gap=0.012)
    model = effects.compose(["frame_offset"])
    np.testing.assert_array_equal(model(effects.init_params(["frame_offset"]), inputs), 0.0)
    twist = model({"frame_offset": {"offset": jnp.asarray([0.004, 0.0])}}, inputs)
    centre_twist = lynch.predict(jnp.asarray([-0.04, 0.0]), normal, 0.2 * motion, 0.03, 10.0)
    np.testing.assert_allclose(twist, centre_twist, rtol=1e-6, atol=1e-9)
    assert float(twist[0]) > 0.0019


def test_anisotropic_friction_deflects_a_push_towards_the_weak_axis():
    # A frictionless push through the centre at 45 degrees to the object's axes, friction twice as strong
    # along y: the object translates along A_f n = (2, 1/2) / sqrt(2), deflected towards x, without turning.
    normal = _unit(np.pi / 4)
    inputs = effects.PushInputs.create(-0.03 * normal, normal, 0.01 * normal, 0.03, 0.0)
    log_metric = jnp.asarray([np.log(2.0), 0.0])  # A_xx = 2: x is the weak axis (f_max smaller along x)
    model = effects.compose(["anisotropic_friction"])
    twist = np.asarray(model({"anisotropic_friction": {"log_metric": log_metric}}, inputs))
    assert abs(twist[2]) < 1e-9
    np.testing.assert_allclose(twist[0] / twist[1], 4.0, rtol=1e-5)
    physical = effects.physical_params({"anisotropic_friction": {"log_metric": log_metric}})["anisotropic_friction"]
    np.testing.assert_allclose([physical["ratio"], physical["strong_axis_deg"]], [2.0, 90.0], rtol=1e-6)
    # Turning the object by 90 degrees turns the weak axis with it.
    turned = np.asarray(model({"anisotropic_friction": {"log_metric": log_metric}},
                              inputs.replace(object_yaw=jnp.asarray(np.pi / 2))))
    np.testing.assert_allclose(turned[1] / turned[0], 4.0, rtol=1e-5)


@pytest.mark.parametrize("seed", range(3))
def test_generalised_solver_satisfies_the_contact_and_limit_surface_conditions(seed):
    with jax.enable_x64(True):
        inputs = _random_inputs(seed, count=4000, dtype=np.float64)
        rng = np.random.default_rng(seed)
        s_matrix = rng.normal(0, 0.4, (len(inputs.l), 2))
        params = {"anisotropic_friction": {"log_metric": jnp.asarray(s_matrix[0])},
                  "table_tilt": {"drift_force": jnp.asarray(rng.normal(0, 0.25, 2))}}
        state = effects.ModelState(contact=inputs.contact, normal=inputs.normal, action=inputs.action, l=inputs.l,
                                   mu=inputs.mu, s=jnp.ones_like(inputs.s), centre=jnp.zeros_like(inputs.contact),
                                   metric=(jnp.ones_like(inputs.l), jnp.zeros_like(inputs.l), jnp.ones_like(inputs.l)),
                                   drift_force=jnp.zeros_like(inputs.contact))
        for name in ("anisotropic_friction", "table_tilt"):
            state = effects.EFFECTS[name].modify(params[name], state, inputs)
        twist = np.asarray(effects.limit_surface_predict(state.contact, state.normal, state.action, state.l, state.mu,
                                                         state.s, state.metric, state.drift_force))
    c, n, u, l, mu = (np.asarray(x) for x in (inputs.contact, inputs.normal, inputs.action, inputs.l, inputs.mu))
    metric = np.stack([np.stack([state.metric[0], state.metric[1]], -1),
                       np.stack([state.metric[1], state.metric[2]], -1)], -2)
    g = np.asarray(state.drift_force)
    contact_velocity = twist[:, :2] + twist[:, 2:3] * np.stack([-c[:, 1], c[:, 0]], -1)
    moving = np.linalg.norm(twist, axis=1) > 0
    assert moving.mean() > 0.5
    # The wrench F = (f + g, c x f) with V = kappa A F: recover kappa from the torque balance.
    force_direction = np.linalg.solve(metric, twist[:, :2, None])[..., 0]  # = kappa (f + g)
    torque = l ** 2 * twist[:, 2]  # = kappa (c x f)
    lever = _cross(c, g)
    valid = moving & (np.abs(lever) > 1e-3 * np.linalg.norm(c, axis=1) * np.linalg.norm(g, axis=1))
    kappa = (_cross(c, force_direction) - torque)[valid] / lever[valid]
    assert np.all(kappa > 0)
    f = force_direction[valid] / kappa[:, None] - g[valid]
    wrench_force = f + g[valid]
    on_surface = np.einsum("ni,nij,nj->n", wrench_force, metric[valid], wrench_force) + (
        _cross(c[valid], f) / l[valid]) ** 2
    np.testing.assert_allclose(on_surface, 1.0, atol=1e-6)
    # Friction cone: |n x f| <= mu n.f; sticking contacts follow the pusher, slipping ones its normal motion.
    n_valid = n[valid]
    assert np.all(np.abs(_cross(n_valid, f)) <= mu[valid] * np.sum(n_valid * f, 1) * (1 + 1e-6) + 1e-9)
    sticking = np.all(np.isclose(contact_velocity[valid], u[valid], rtol=0, atol=1e-9), axis=1)
    assert 0.2 < sticking.mean() < 0.9
    np.testing.assert_allclose(np.sum(contact_velocity[valid] * n_valid, 1), np.sum(u[valid] * n_valid, 1), atol=1e-9)


def test_table_tilt_needs_a_push_and_scales_with_it():
    inputs = _random_inputs(10, count=1000)
    params = {"table_tilt": {"drift_force": jnp.asarray([0.3, -0.1])}}
    model = effects.compose(["table_tilt"])
    still = model(params, inputs.replace(action=jnp.zeros_like(inputs.action)))
    np.testing.assert_array_equal(still, 0.0)
    np.testing.assert_allclose(model(params, inputs.replace(action=2 * inputs.action)), 2 * model(params, inputs),
                               rtol=1e-5, atol=1e-9)
    # A sticking push turns the object about the contact (the contact keeps following the pusher).
    push = effects.PushInputs.create([-0.03, 0.0], [1.0, 0.0], [0.01, 0.0], 0.03, 10.0)
    twist = np.asarray(model(params, push))
    np.testing.assert_allclose(twist[:2] + twist[2] * np.array([0.0, -0.03]), [0.01, 0.0], atol=1e-8)
    assert twist[1] < 0  # the drift force points -y: the object swings that way


def test_inertia_slides_on_after_the_pusher_stops():
    normal = np.array([1.0, 0.0])
    action = np.array([0.02, 0.0])
    inverse_deceleration = 0.5  # a = 2 m/s^2
    params = {"inertia": {"inverse_deceleration": jnp.asarray(inverse_deceleration)}}
    model = effects.compose(["inertia"])
    speed = 0.4

    def displacement(time_after_stop):
        inputs = effects.PushInputs.create([-0.03, 0.0], normal, action, 0.03, 10.0, push_speed=speed,
                                           time_after_stop=time_after_stop)
        return np.asarray(model(params, inputs))

    np.testing.assert_allclose(displacement(0.0), [0.02, 0.0, 0.0], atol=1e-9)
    # Stops after v / a = 0.2 s, having slid v^2 / (2 a) = 40 mm; after 0.1 s: v t - a t^2 / 2 = 30 mm.
    np.testing.assert_allclose(displacement(0.5), [0.06, 0.0, 0.0], atol=1e-8)
    np.testing.assert_allclose(displacement(0.1), [0.05, 0.0, 0.0], atol=1e-8)
    # Without a stop in the window the decay length does not matter, not even to first order at 0.
    for time_after_stop, expected in ((0.0, 0.0), (0.5, 0.5 * speed ** 2)):
        inputs = effects.PushInputs.create([-0.03, 0.0], normal, action, 0.03, 10.0, push_speed=speed,
                                           time_after_stop=time_after_stop)
        gradient = jax.grad(lambda inverse: model({"inertia": {"inverse_deceleration": inverse}}, inputs)[0])(0.0)
        np.testing.assert_allclose(gradient, expected, rtol=1e-6)


def test_projection_keeps_parameters_physical():
    projected = effects.project_params({"inertia": {"inverse_deceleration": jnp.asarray(-1.0)},
                                        "table_tilt": {"drift_force": jnp.asarray([3.0, 4.0])}})
    assert float(projected["inertia"]["inverse_deceleration"]) == 0.0
    np.testing.assert_allclose(projected["table_tilt"]["drift_force"], [0.57, 0.76], rtol=1e-6)


def test_friction_field_moves_the_centre_of_friction_towards_higher_friction():
    inputs = _random_inputs(7, count=256)
    gradient, curvature = np.array([4.0, -2.0]), np.array([10.0, -5.0, 20.0])
    field = effects.compose(["friction_field"])(
        {"friction_field": {"gradient": jnp.asarray(gradient), "curvature": jnp.asarray(curvature)}}, inputs)
    # The same as a centre-of-friction offset of (9/16) l^2 grad log mu(p), turned into the object's axes.
    position = np.asarray(inputs.object_position)
    local = gradient + np.stack([curvature[0] * position[:, 0] + curvature[1] * position[:, 1],
                                 curvature[1] * position[:, 0] + curvature[2] * position[:, 1]], axis=1)
    shift = 9 / 16 * np.asarray(inputs.l)[:, None] ** 2 * local
    yaw = np.asarray(inputs.object_yaw)
    in_object = np.stack([np.cos(yaw) * shift[:, 0] + np.sin(yaw) * shift[:, 1],
                          -np.sin(yaw) * shift[:, 0] + np.cos(yaw) * shift[:, 1]], axis=1)
    offset = effects.compose(["cof_offset"])({"cof_offset": {"offset": jnp.asarray(in_object, jnp.float32)}}, inputs)
    np.testing.assert_allclose(field, offset, atol=1e-6)


def test_pressure_gradient_moves_the_centre_and_shrinks_l_together():
    inputs = _random_inputs(8, count=256)
    offset = jnp.asarray([0.006, -0.004])
    gradient = effects.compose(["pressure_gradient"])({"pressure_gradient": {"offset": offset}}, inputs)
    share = float(jnp.sum(offset ** 2)) / (9 / 8 * np.asarray(inputs.l) ** 2)
    both = effects.compose(["cof_offset", "friction_ratio"])(
        {"cof_offset": {"offset": offset},
         "friction_ratio": {"log_scale": jnp.asarray(0.5 * np.log(1 - share), jnp.float32)}}, inputs)
    np.testing.assert_allclose(gradient, both, atol=1e-6)


def test_friction_speed_is_inertia_at_zero_gain_and_shortens_fast_slides_when_rate_strengthening():
    normal = np.array([1.0, 0.0])
    inputs = effects.PushInputs.create([-0.03, 0.0], normal, [0.01, 0.0], 0.03, 10.0, push_speed=0.2,
                                       time_after_stop=0.3)
    inertia = effects.compose(["inertia"])({"inertia": {"inverse_deceleration": jnp.asarray(0.4)}}, inputs)

    def speed_model(gain):
        return effects.compose(["friction_speed"])(
            {"friction_speed": {"inverse_deceleration": jnp.asarray(0.4), "gain": jnp.asarray(gain)}}, inputs)

    np.testing.assert_allclose(speed_model(0.0), inertia, rtol=1e-6)
    # 200 mm/s is a decade above the reference: +30 % friction, a slide shorter by 1 / 1.3.
    plain = float(_lynch(inputs)[0])
    np.testing.assert_allclose(float(speed_model(0.3)[0]) - plain, (float(inertia[0]) - plain) / 1.3, rtol=1e-5)
    gradient = jax.grad(lambda gain: speed_model(gain)[0])(0.0)
    assert np.isfinite(gradient) and gradient < 0


def _square_support(half=0.04, cells=10):
    """A uniform square plate of side 2 half as cells [K, 2] with equal weights, and the cells' patch radius."""
    centres = (np.arange(cells) + 0.5) / cells * 2 * half - half
    points = np.stack(np.meshgrid(centres, centres), axis=-1).reshape(-1, 2)
    return points, np.full(len(points), 1.0 / len(points)), 0.3826 * 2 * half / cells


def _pushes_on_a_square(count=200, seed=0):
    """Pushes on the square's bottom side (y = -0.04, normal +y), contact along it, directions within 60 deg of it."""
    rng = np.random.default_rng(seed)
    points, weights, radius = _square_support()
    contact = np.column_stack([rng.uniform(-0.035, 0.035, count), np.full(count, -0.04)])
    angle = np.pi / 2 + rng.uniform(-1, 1, count) * np.radians(60)
    action = 0.005 * np.column_stack([np.cos(angle), np.sin(angle)])
    return effects.PushInputs.create(
        contact, np.tile([0.0, 1.0], (count, 1)), action, np.full(count, effects.MEAN_SQUARE_RADIUS),
        np.full(count, 0.3), object_yaw=rng.uniform(-np.pi, np.pi, count) * 0,
        support_points=np.broadcast_to(points, (count, *points.shape)),
        support_weights=np.broadcast_to(weights, (count, len(weights))), patch_radius=np.full(count, radius))


def test_limit_surface_is_the_exact_surface_of_the_support_and_moves_with_its_pressure():
    inputs = _pushes_on_a_square()
    model = jax.jit(effects.compose(["limit_surface"]))
    zero = effects.init_params(["limit_surface"])
    uniform = np.asarray(model(zero, inputs))
    l = float(np.mean(np.linalg.norm(inputs.support_points[0], axis=1)))  # the uniform square's l
    ellipsoid = np.asarray(lynch.predict(inputs.contact, inputs.normal, inputs.action, l, inputs.mu))
    # The two surfaces agree at the intercepts (a push through the centre translates, both the same), and differ in
    # between: near pure translation the exact surface gives way to a turn more easily than the ellipsoid.
    centred = inputs.replace(contact=jnp.zeros_like(inputs.contact).at[:, 1].set(-0.04),
                             action=jnp.tile(jnp.array([0.0, 0.005]), (len(inputs.mu), 1)))
    np.testing.assert_allclose(model(zero, centred)[:, :2], np.tile([0.0, 0.005], (len(inputs.mu), 1)), atol=1e-6)
    np.testing.assert_allclose(model(zero, centred)[:, 2], 0.0, atol=1e-5)
    assert np.mean(np.abs(uniform - ellipsoid)) > 1e-5
    # Loading the rim makes turning harder; loading the centre easier.
    rim = {"limit_surface": {"rim": jnp.asarray(1.0), "feet": jnp.asarray(0.0)}}
    centre = {"limit_surface": {"rim": jnp.asarray(-1.0), "feet": jnp.asarray(0.0)}}
    turned = np.abs(uniform[:, 2]) > 1e-3
    assert np.all(np.abs(np.asarray(model(rim, inputs))[turned, 2]) < np.abs(uniform[turned, 2]))
    assert np.all(np.abs(np.asarray(model(centre, inputs))[turned, 2]) > np.abs(uniform[turned, 2]))
    # cof_offset moves the support with the centre of pressure: towards +x, a push along +y through the centre of
    # mass passes on its left and turns the plate clockwise.
    shifted = effects.compose(["cof_offset", "limit_surface"])
    params = {"cof_offset": {"offset": jnp.array([0.005, 0.0])}, "limit_surface": {"rim": jnp.asarray(0.0), "feet": jnp.asarray(0.0)}}
    assert np.all(np.asarray(shifted(params, centred))[:, 2] < -1e-4)


def test_limit_surface_feet_rest_a_share_of_the_load_on_the_hull_corners():
    cells = _pushes_on_a_square(count=60, seed=2)
    corners = np.array([[0.04, 0.04], [-0.04, 0.04], [-0.04, -0.04], [0.04, -0.04]])
    count, k = cells.support_weights.shape
    inputs = cells.replace(
        support_points=jnp.concatenate([cells.support_points, jnp.broadcast_to(corners, (count, 4, 2))], axis=1),
        support_weights=jnp.concatenate([cells.support_weights, jnp.zeros((count, 4))], axis=1),
        support_feet=jnp.concatenate([jnp.zeros((count, k)), jnp.full((count, 4), 0.25)], axis=1))
    model = jax.jit(effects.compose(["limit_surface"]))
    zero = effects.init_params(["limit_surface"])
    # No share on the feet: the corners carry nothing, the footprint's exact surface as without them.
    np.testing.assert_allclose(model(zero, inputs), model(zero, cells), rtol=1e-6, atol=1e-9)
    # All of it: the exact surface of the four corners alone.
    on_feet = {"limit_surface": {"rim": jnp.asarray(0.0), "feet": jnp.asarray(1.0)}}
    alone = exact_limit_surface.predict(cells.contact, cells.normal, cells.action, cells.mu,
                                        jnp.broadcast_to(corners, (count, 4, 2)), jnp.full((count, 4), 0.25),
                                        cells.patch_radius)
    np.testing.assert_allclose(model(on_feet, inputs), alone, rtol=1e-5, atol=1e-8)
    # Half of it turns the plate less than the footprint and more than the feet alone; the share is differentiable
    # and kept within [0, 1].
    half = {"limit_surface": {"rim": jnp.asarray(0.0), "feet": jnp.asarray(0.5)}}
    turned = np.abs(np.asarray(model(zero, inputs))[:, 2]) > 1e-3
    rotation = [np.abs(np.asarray(model(params, inputs))[turned, 2]) for params in (zero, half, on_feet)]
    assert np.all(rotation[0] > rotation[1]) and np.all(rotation[1] > rotation[2])
    gradient = jax.grad(lambda p: jnp.sum(model(p, inputs)[:, 2] ** 2))(half)
    assert np.isfinite(gradient["limit_surface"]["feet"]) and gradient["limit_surface"]["feet"] < 0
    projected = effects.EFFECTS["limit_surface"].project({"rim": jnp.asarray(2.0), "feet": jnp.asarray(1.7)})
    assert float(projected["feet"]) == 1.0 and float(projected["rim"]) == 2.0


def test_limit_surface_is_differentiable_and_refuses_what_it_cannot_compose():
    inputs = _pushes_on_a_square(count=50, seed=1)
    names = [name for name in effects.EFFECT_NAMES if effects.compatible([name, "limit_surface"])]
    model = effects.compose(names)
    params = {name: values for name, values in _random_params(3).items() if name in names}
    # (A random frame offset moves these pushes' contacts off the square's side: no motion to differentiate.)
    params["frame_offset"] = {"offset": jnp.zeros(2)}
    params["limit_surface"] = {"rim": jnp.asarray(0.3), "feet": jnp.asarray(0.0)}
    gradient = jax.jit(jax.grad(lambda p: jnp.sum(model(p, inputs) ** 2)))(params)  # one program, not op by op
    assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree.leaves(gradient))
    assert np.asarray(gradient["limit_surface"]["rim"]) != 0 and np.all(np.asarray(gradient["cof_offset"]["offset"]) != 0)
    assert set(effects.EFFECT_NAMES) - set(names) == {"friction_ratio", "pressure_gradient", "anisotropic_friction"}
    with pytest.raises(ValueError, match="cannot compose limit_surface with friction_ratio"):
        effects.compose(["friction_ratio", "limit_surface"])
    bare = inputs.replace(support_points=None, support_weights=None, patch_radius=None)
    with pytest.raises(ValueError, match="limit_surface: needs PushInputs.support_points"):
        effects.compose(["limit_surface"])(effects.init_params(["limit_surface"]), bare)
