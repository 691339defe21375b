"""The JAX rollout: agreement with an independent NumPy rollout, gradients against finite differences, contact
lost and regained, effects, vmap."""

import itertools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax import planar
from pushjax.geometry import contact as contact_lib
from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, get_object, limit_surface_ratio, support
from pushjax.physics import effects, rollout
from tests.physics import numpy_limit_surface, numpy_lynch

STEPS = 30


def _numpy_rollout(obj, pose, pusher_path, l, mu):
    """The former NumPy rollout, written with the NumPy contact annotation and the NumPy Lynch reference."""
    pose = np.asarray(pose, np.float64).copy()
    poses = [pose.copy()]
    for start, end in itertools.pairwise(pusher_path):
        state = contact_lib.annotate(obj, pose, start, end - start)
        motion = numpy_lynch.predict(state.contact_rel_com, state.normal, state.action_from_contact, l, mu)
        com_offset = planar.rotate(obj.centroid, pose[2])
        com = pose[:2] + com_offset + motion[:2]
        pose = np.array([*(com - planar.rotate(com_offset, motion[2])), pose[2] + motion[2]])
        poses.append(pose.copy())
    return np.stack(poses)


def _push(obj, side, point, angle_deg, distance=0.04, steps=STEPS, clearance=1e-3):
    """[steps + 1, 2] straight pusher path starting `clearance` before `side` at `point`, `angle_deg` off its normal."""
    surface_point, normal = obj.side_point(side, point)
    direction = planar.rotation_matrix(np.deg2rad(angle_deg)) @ normal
    start = surface_point - direction * (PUSHER_RADIUS / max(direction @ normal, 1e-6) + clearance)
    return start + np.linspace(0.0, 1.0, steps + 1)[:, None] * distance * direction


PUSHES = [("rect1", 0, 0.3, 20.0, 0.25), ("tri2", 1, 0.5, -30.0, 0.8), ("butter", 2, 0.4, 10.0, 0.1),
          ("hex", 3, 0.7, 45.0, 0.5)]


@pytest.mark.parametrize("name, side, point, angle, mu", PUSHES)
def test_matches_the_numpy_rollout(name, side, point, angle, mu):
    obj = get_object(name)
    path = _push(obj, side, point, angle)
    pose = np.array([0.01, -0.02, 0.3])
    # The path is given in the object's frame at yaw 0: turn it with the object.
    path = pose[:2] + planar.rotate(path, pose[2])
    l = limit_surface_ratio(obj)
    expected = _numpy_rollout(obj, pose, path, l, mu)
    with jax.enable_x64(True):
        got = rollout.rollout(outline_jax.outline(obj, jnp.float64), pose, path, l, mu).poses
    assert np.abs(expected[-1] - expected[0]).max() > 5e-3  # the object moved
    np.testing.assert_allclose(np.asarray(got), expected, atol=1e-9)


def test_matches_the_numpy_rollout_on_an_ellipse_within_the_polygon_error():
    obj = get_object("ellip2")
    path = _push(obj, 0, 0.3, 20.0)
    expected = _numpy_rollout(obj, np.zeros(3), path, limit_surface_ratio(obj), 0.25)
    with jax.enable_x64(True):
        got = np.asarray(rollout.rollout(outline_jax.outline(obj, jnp.float64, ellipse_points=1024), jnp.zeros(3),
                                         path, limit_surface_ratio(obj), 0.25).poses)
    np.testing.assert_allclose(got[:, :2], expected[:, :2], atol=5e-5)
    np.testing.assert_allclose(got[:, 2], expected[:, 2], atol=np.radians(0.2))


def test_straight_push_is_the_former_entry_point():
    obj = get_object("rect1")
    path = _push(obj, 0, 0.3, 20.0, distance=0.05, steps=20, clearance=0.0)
    with jax.enable_x64(True):
        poses = rollout.straight_push(obj, np.zeros(3), path[0], path[-1] - path[0], 0.25, steps=20)
    np.testing.assert_allclose(poses, _numpy_rollout(obj, np.zeros(3), path, limit_surface_ratio(obj), 0.25),
                               atol=1e-9)
    with pytest.raises(ValueError, match="steps"):
        rollout.straight_push(obj, np.zeros(3), path[0], path[-1] - path[0], 0.25, steps=0)


EFFECTS = ("frame_offset", "cof_offset", "friction_ratio", "pusher_friction", "friction_field")


def _effect_params(scale=1.0):
    return {"frame_offset": {"offset": scale * jnp.array([0.001, -0.0005])},
            "cof_offset": {"offset": scale * jnp.array([0.002, -0.001])},
            "friction_ratio": {"log_scale": scale * jnp.array(-0.1)},
            "pusher_friction": {"log_scale": scale * jnp.array(0.2)},
            "friction_field": {"gradient": scale * jnp.array([1.0, -2.0]),
                               "curvature": scale * jnp.array([5.0, 1.0, -3.0])}}


@pytest.mark.parametrize("name, angle, mu", [("butter", 25.0, 0.2)])  # non-convex, slips: mu matters
def test_gradients_match_central_finite_differences(name, angle, mu):
    """Final pose w.r.t. the pusher path, l, mu and the effects' parameters, on pushes that keep their side."""
    obj = get_object(name)
    with jax.enable_x64(True):
        shape = outline_jax.outline(obj, jnp.float64)
        path = jnp.asarray(_push(obj, 0, 0.3, angle))
        l = jnp.asarray(limit_surface_ratio(obj))
        params = jax.tree_util.tree_map(lambda x: x.astype(jnp.float64), _effect_params())

        def final(path, l, mu, params):
            return rollout.rollout(shape, jnp.zeros(3), path, l, mu, params, effects=EFFECTS).poses[-1]

        steps = rollout.rollout(shape, jnp.zeros(3), path, l, mu, params, effects=EFFECTS).steps
        assert bool(jnp.all(steps.touches[1:]))
        jacobian = jax.jit(jax.jacfwd(final, argnums=(0, 1, 2, 3)))(path, l, jnp.asarray(mu), params)
        h = 1e-7

        def central(shift):
            plus, minus = shift(h), shift(-h)
            return (final(*plus) - final(*minus)) / (2 * h)

        np.testing.assert_allclose(jacobian[1], central(lambda d: (path, l + d, mu, params)), rtol=1e-5, atol=1e-7)
        np.testing.assert_allclose(jacobian[2], central(lambda d: (path, l, mu + d, params)), rtol=1e-5, atol=1e-7)
        for index in [(3, 0), (12, 1), (STEPS, 0)]:
            np.testing.assert_allclose(jacobian[0][(slice(None), *index)],
                                       central(lambda d, index=index: (path.at[index].add(d), l, mu, params)),
                                       rtol=1e-5, atol=1e-7)
        for effect, name_ in [("cof_offset", "offset"), ("pusher_friction", "log_scale"),
                              ("friction_field", "gradient"), ("frame_offset", "offset")]:
            value = params[effect][name_]
            unit = jnp.zeros_like(value).reshape(-1).at[0].set(1.0).reshape(value.shape)

            def shifted(d, effect=effect, name_=name_, unit=unit, value=value):
                return path, l, mu, {**params, effect: {**params[effect], name_: value + d * unit}}

            np.testing.assert_allclose(jnp.tensordot(jacobian[3][effect][name_], unit, unit.ndim),
                                       central(shifted), rtol=1e-5, atol=1e-7)
        assert np.abs(jacobian[2]).max() > 0  # the push slips: mu matters


def _lost_and_regained_path():
    """Towards rect1's bottom edge along its normal through the centre: 2 mm to the touch, 10 mm of pushing in
    1 mm steps, 10 mm back, then 20 mm forward in 2 mm steps (the touch comes after 12 mm, 8 mm of pushing)."""
    y0 = -0.045 - PUSHER_RADIUS - 0.002
    ys = np.concatenate([np.linspace(y0, y0 + 0.012, 13), np.linspace(y0 + 0.012, y0 + 0.002, 11)[1:],
                         np.linspace(y0 + 0.002, y0 + 0.022, 11)[1:]])
    return np.stack([np.zeros_like(ys), ys], axis=-1)


def test_contact_is_lost_and_regained():
    obj = get_object("rect1")
    path = _lost_and_regained_path()
    l = limit_surface_ratio(obj)
    with jax.enable_x64(True):
        result = rollout.rollout(outline_jax.outline(obj, jnp.float64), jnp.zeros(3), path, l, 0.3)
    touches = np.asarray(result.steps.touches)
    moved = np.abs(np.asarray(result.steps.twist)).sum(-1) > 0
    assert not touches[0] and touches[2:12].all() and moved[2:12].all()
    assert not moved[12:26].any() and not touches[14:25].any()  # backing off and coming back: no contact
    assert moved[27:].all() and touches[26:].all()
    pose = np.asarray(result.poses)
    np.testing.assert_allclose(pose[12], [0.0, 0.010, 0.0], atol=1e-12)
    np.testing.assert_allclose(pose[-1], [0.0, 0.020, 0.0], atol=1e-12)
    np.testing.assert_allclose(pose, _numpy_rollout(obj, np.zeros(3), path, l, 0.3), atol=1e-12)


def test_gradients_are_finite_everywhere():
    """Contact lost and regained, a pusher standing still, far away, inside the object, sliding along an edge."""
    count = len(_lost_and_regained_path())
    paths = np.stack([
        _lost_and_regained_path(),
        np.tile([[0.0, -0.045 - PUSHER_RADIUS]], (count, 1)),
        np.linspace([0.3, 0.3], [0.3, 0.4], count),
        np.linspace([0.0, 0.0], [0.01, 0.0], count),
        np.linspace([-0.03, -0.045 - PUSHER_RADIUS], [0.03, -0.045 - PUSHER_RADIUS], count),
    ])
    shape = outline_jax.outline("rect1")

    def final(path, l, mu, params):
        return jnp.sum(rollout.rollout(shape, jnp.zeros(3), path, l, mu, params, effects=EFFECTS).poses[-1])

    gradient = jax.jit(jax.vmap(jax.grad(final, argnums=(0, 1, 2, 3)), in_axes=(0, None, None, None)))
    grads = gradient(jnp.asarray(paths, jnp.float32), jnp.float32(0.034), jnp.float32(0.3), _effect_params(0.0))
    for leaf in jax.tree_util.tree_leaves(grads):
        assert np.all(np.isfinite(np.asarray(leaf)))


def test_no_effects_is_plain_lynch_and_effects_change_the_rollout():
    """``pusher_friction`` with log scale log 2 is the plain model with twice mu, with 0 the plain model."""
    obj = get_object("butter")
    path = jnp.asarray(_push(obj, 2, 0.4, 25.0), jnp.float32)
    shape = outline_jax.outline(obj)
    l = limit_surface_ratio(obj)
    plain = rollout.rollout(shape, jnp.zeros(3), path, l, 0.4).poses
    scaled = rollout.rollout(shape, jnp.zeros(3), path, l, 0.2, {"pusher_friction": {"log_scale": jnp.log(2.0)}},
                             effects=("pusher_friction",)).poses
    np.testing.assert_allclose(scaled, plain, atol=1e-6)
    neutral = rollout.rollout(shape, jnp.zeros(3), path, l, 0.4, {"pusher_friction": {"log_scale": jnp.float32(0.0)}},
                              effects=("pusher_friction",)).poses
    np.testing.assert_allclose(neutral, plain, atol=1e-6)
    assert np.abs(np.asarray(rollout.rollout(shape, jnp.zeros(3), path, l, 0.2).poses - plain)).max() > 1e-3


def test_slide_after_the_stop_acts_in_the_last_step_only():
    obj = get_object("rect1")
    path = jnp.asarray(_push(obj, 0, 0.5, 0.0, distance=0.02, steps=10), jnp.float32)
    shape = outline_jax.outline(obj)
    params = {"inertia": {"inverse_deceleration": jnp.float32(2.0)}}

    def run(stop):
        return np.asarray(rollout.rollout(shape, jnp.zeros(3), path, 0.034, 0.3, params, effects=("inertia",),
                                          step_time=0.1, time_after_stop=stop).poses)

    still, sliding = run(0.0), run(0.5)
    np.testing.assert_allclose(still[:-1], sliding[:-1])
    # Pushed along -x at v = 2 mm / 0.1 s = 20 mm/s, a = 0.5 m/s^2: it stops after v^2 / (2 a) = 0.4 mm.
    np.testing.assert_allclose(sliding[-1] - still[-1], [-0.0004, 0.0, 0.0], rtol=1e-3, atol=1e-9)


def test_vmap_over_pushes_matches_one_by_one_and_jit():
    obj = get_object("tri2")
    shape = outline_jax.outline(obj)
    paths = jnp.asarray(np.stack([_push(obj, 1, point, angle) for point, angle in [(0.2, 0.0), (0.5, 30.0),
                                                                                   (0.8, -20.0)]]), jnp.float32)
    poses0 = jnp.asarray([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    ls, mus = jnp.asarray([0.03, 0.04, 0.05]), jnp.asarray([0.1, 0.5, 1.0])
    batched = jax.vmap(rollout.rollout, in_axes=(None, 0, 0, 0, 0))(shape, poses0, paths, ls, mus).poses
    assert batched.shape == (3, STEPS + 1, 3)
    for k in range(3):
        np.testing.assert_allclose(batched[k], rollout.rollout(shape, poses0[k], paths[k], ls[k], mus[k]).poses,
                                   atol=1e-6)


def test_bad_shapes_are_named():
    shape = outline_jax.outline("rect1")
    with pytest.raises(ValueError, match="pusher_path"):
        rollout.rollout(shape, jnp.zeros(3), jnp.zeros((1, 2)), 0.03, 0.3)
    with pytest.raises(ValueError, match="object_pose"):
        rollout.rollout(shape, jnp.zeros((2, 3)), jnp.zeros((4, 2)), 0.03, 0.3)
    with pytest.raises(ValueError, match="unknown"):
        rollout.rollout(shape, jnp.zeros(3), jnp.zeros((4, 2)), 0.03, 0.3, effects=("nope",))


def test_every_effect_composes_in_a_rollout_and_no_effect_values_change_nothing():
    shape = outline_jax.outline("hex")
    path = jnp.asarray(_push(get_object("hex"), 0, 0.4, 15.0, steps=8), jnp.float32)
    final = rollout.rollout(shape, jnp.zeros(3), path, 0.04, 0.3, effects=effects.ELLIPSOID_EFFECTS).poses[-1]
    plain = rollout.rollout(shape, jnp.zeros(3), path, 0.04, 0.3).poses[-1]
    assert np.abs(np.asarray(plain)).max() > 1e-3
    np.testing.assert_allclose(final, plain, atol=1e-6)


def _numpy_exact_rollout(obj, pose, pusher_path, mu):
    """The rollout with the exact limit surface of the object's uniform support, written with the NumPy contact
    annotation and the NumPy maximal-dissipation reference."""
    points, weights, _, patch_radius = support(obj)
    pose = np.asarray(pose, np.float64).copy()
    poses = [pose.copy()]
    for start, end in itertools.pairwise(pusher_path):
        state = contact_lib.annotate(obj, pose, start, end - start)
        world = points @ planar.rotation_matrix(pose[2]).T
        motion, _, _ = numpy_limit_surface.solve(state.contact_rel_com, state.normal, state.action_from_contact, mu,
                                                 world, weights, patch_radius)
        com_offset = planar.rotate(obj.centroid, pose[2])
        com = pose[:2] + com_offset + motion[:2]
        pose = np.array([*(com - planar.rotate(com_offset, motion[2])), pose[2] + motion[2]])
        poses.append(pose.copy())
    return np.stack(poses)


def test_the_exact_limit_surface_rolls_out_as_a_numpy_maximal_dissipation_rollout():
    name, side, point, angle, mu = PUSHES[1]
    obj = get_object(name)
    path = _push(obj, side, point, angle, steps=10)
    expected = _numpy_exact_rollout(obj, np.zeros(3), path, mu)
    result = rollout.rollout(outline_jax.outline(obj), jnp.zeros(3), jnp.asarray(path, jnp.float32),
                             limit_surface_ratio(obj), mu, effects=("limit_surface",),
                             support=rollout.object_support(obj)).poses
    assert np.abs(expected[-1] - expected[0]).max() > 1e-3
    np.testing.assert_allclose(result, expected, atol=2e-5)
    plain = rollout.rollout(outline_jax.outline(obj), jnp.zeros(3), jnp.asarray(path, jnp.float32),
                            limit_surface_ratio(obj), mu).poses
    assert np.abs(np.asarray(plain - result)[-1, 2]) > 1e-3  # the exact surface turns the object differently


def test_the_exact_limit_surface_needs_the_support_and_its_gradients_match_finite_differences():
    obj = get_object("tri2")
    shape, path = outline_jax.outline(obj), jnp.asarray(_push(obj, 1, 0.3, -25.0, steps=10), jnp.float32)
    with pytest.raises(ValueError, match="support"):
        rollout.rollout(shape, jnp.zeros(3), path, 0.04, 0.3, effects=("limit_surface",))
    support_ = rollout.object_support(obj)

    def final_yaw(mu, rim):
        params = {"limit_surface": {"rim": rim, "feet": jnp.float32(0.2)}}
        return rollout.rollout(shape, jnp.zeros(3), path, 0.04, mu, params, effects=("limit_surface",),
                               support=support_).poses[-1, 2]

    gradient = jax.jit(jax.grad(final_yaw, argnums=(0, 1)))(jnp.float32(0.15), jnp.float32(0.5))
    for k, delta in enumerate(np.eye(2) * 2e-3):
        args = np.array([0.15, 0.5])
        difference = (final_yaw(*map(jnp.float32, args + delta)) - final_yaw(*map(jnp.float32, args - delta))) / 4e-3
        np.testing.assert_allclose(gradient[k], difference, rtol=0.03, atol=2e-3)
    assert abs(float(gradient[0])) > 1e-3 and abs(float(gradient[1])) > 1e-3
