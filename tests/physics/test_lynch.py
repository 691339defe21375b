"""Tests of the differentiable Lynch pushing model against an independent NumPy reference."""

import hypothesis
import hypothesis.strategies as st
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.physics import lynch

from . import numpy_lynch

PROPERTY_SETTINGS = hypothesis.settings(max_examples=40, deadline=None, derandomize=True)


def _unit(angle):
    return np.array([np.cos(angle), np.sin(angle)])


def _random_pushes(rng, count):
    """Pushes covering sticking, both slipping sides, pulling, and contacts far from the COM."""
    l = rng.uniform(0.02, 0.06, count)
    contact = _unit(rng.uniform(-np.pi, np.pi, count)).T * (l * rng.uniform(0, 3, count))[:, None]
    normal_angle = rng.uniform(-np.pi, np.pi, count)
    normal = _unit(normal_angle).T * rng.uniform(0.2, 3, count)[:, None]
    action_angle = normal_angle + rng.uniform(-1.1, 1.1, count) * np.pi / 2
    action = _unit(action_angle).T * rng.uniform(1e-4, 0.02, count)[:, None]
    mu = rng.uniform(0, 2, count)
    s = rng.uniform(0, 1, count)
    return contact, normal, action, l, mu, s


@st.composite
def regular_pushes(draw):
    """One push with |c| <= l and mu <= 1: then v_pb . n >= 0.79 l^2 |n|^2 on both boundaries, so
    the slipping ratio is well conditioned enough for tight tolerances."""
    angle = st.floats(-np.pi, np.pi)
    l = draw(st.floats(0.02, 0.08))
    contact = _unit(draw(angle)) * draw(st.floats(0, 1)) * l
    normal = _unit(draw(angle)) * draw(st.floats(0.5, 2))
    action = _unit(draw(angle)) * draw(st.floats(1e-3, 0.05))
    mu = draw(st.floats(0, 1))
    s = draw(st.floats(0, 1))
    return contact, normal, action, l, mu, s


def _scale(action, l):
    """Magnitude of the outputs, for absolute tolerances."""
    return np.linalg.norm(action) * (1 + 1 / l)


def _all_gradients(function, dtype, *args):
    with jax.enable_x64(dtype == np.float64):
        args = [jnp.asarray(np.asarray(arg), dtype) for arg in args]
        return jax.grad(lambda *a: jnp.sum(function(*a)), argnums=range(len(args)))(*args)


def test_matches_numpy_reference_on_random_pushes():
    contact, normal, action, l, mu, s = _random_pushes(np.random.default_rng(0), 10_000)
    mode = numpy_lynch.contact_mode(contact, normal, action, l, mu)
    for expected_mode in (
        numpy_lynch.NOT_PUSHING,
        numpy_lynch.STICKING,
        numpy_lynch.SLIPPING_LEFT,
        numpy_lynch.SLIPPING_RIGHT,
    ):
        assert np.mean(mode == expected_mode) > 0.05
    # Large mu with far contacts: one motion-cone boundary points out of the object ...
    v_left, v_right = numpy_lynch.motion_cone(contact, normal, l, mu)
    n = numpy_lynch.unit_normal(normal)
    left_out, right_out = np.sum(v_left * n, -1) <= 0, np.sum(v_right * n, -1) <= 0
    assert left_out.sum() > 100 and right_out.sum() > 100
    # ... but the cone then covers that whole side, so slipping never uses that boundary.
    assert not np.any((mode == numpy_lynch.SLIPPING_LEFT) & left_out)
    assert not np.any((mode == numpy_lynch.SLIPPING_RIGHT) & right_out)

    expected_v_p, expected_sticking = numpy_lynch.effective_push_velocity(
        contact, normal, action, l, mu
    )
    expected_twist = numpy_lynch.predict(contact, normal, action, l, mu, s)
    with jax.enable_x64(True):
        v_p, sticking = lynch.effective_push_velocity(contact, normal, action, l, mu)
        twist = lynch.predict(contact, normal, action, l, mu, s)
        assert twist.dtype == jnp.float64
    np.testing.assert_allclose(v_p, expected_v_p, rtol=1e-5, atol=1e-12)
    np.testing.assert_allclose(twist, expected_twist, rtol=1e-5, atol=1e-12)
    np.testing.assert_array_equal(sticking, expected_sticking)


def test_jacobian_matches_finite_differences_of_numpy_reference():
    pushes = list(_random_pushes(np.random.default_rng(5), 500))
    with jax.enable_x64(True):
        jacobians = jax.vmap(jax.jacrev(lynch.predict, argnums=range(6)))(*pushes)
    mode = numpy_lynch.contact_mode(*pushes[:5])
    for argument, jacobian in enumerate(jacobians):
        jacobian = np.asarray(jacobian).reshape(len(mode), 3, -1)
        for component in range(jacobian.shape[-1]):
            step = 1e-7 * np.maximum(np.abs(pushes[argument]).reshape(len(mode), -1).max(-1), 1e-3)
            shifted = []
            for sign in (1, -1):
                perturbed = [x.copy() for x in pushes]
                perturbed[argument].reshape(len(mode), -1)[:, component] += sign * step
                shifted.append(perturbed)
            # Compare only where the perturbation stays in the same stick/slip mode.
            same_mode = np.all(
                [numpy_lynch.contact_mode(*p[:5]) == mode for p in shifted], axis=0
            )
            assert same_mode.mean() > 0.95
            difference = (numpy_lynch.predict(*shifted[0]) - numpy_lynch.predict(*shifted[1])) / (
                2 * step[:, None]
            )
            np.testing.assert_allclose(
                jacobian[same_mode, :, component],
                difference[same_mode],
                rtol=1e-4,
                atol=1e-5 * np.abs(difference).max(),
                err_msg=f"argument {argument}, component {component}",
            )


def test_predict_is_object_velocity_of_scaled_push_velocity():
    contact, normal, action, l, mu, s = _random_pushes(np.random.default_rng(1), 1000)
    with jax.enable_x64(True):
        v_p, _ = lynch.effective_push_velocity(contact, normal, action, l, mu)
        np.testing.assert_allclose(
            lynch.predict(contact, normal, action, l, mu, s),
            lynch.object_velocity(contact, s[:, None] * v_p, l),
            rtol=1e-9,
            atol=1e-14,
        )


@PROPERTY_SETTINGS
@hypothesis.given(regular_pushes(), st.floats(-np.pi, np.pi))
def test_rotation_equivariance(push, angle):
    contact, normal, action, l, mu, s = push
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    with jax.enable_x64(True):
        twist = np.asarray(lynch.predict(contact, normal, action, l, mu, s))
        rotated = np.asarray(
            lynch.predict(rotation @ contact, rotation @ normal, rotation @ action, l, mu, s)
        )
    atol = 1e-12 * _scale(action, l)
    np.testing.assert_allclose(rotated[:2], rotation @ twist[:2], rtol=1e-9, atol=atol)
    np.testing.assert_allclose(rotated[2], twist[2], rtol=1e-9, atol=atol)


@PROPERTY_SETTINGS
@hypothesis.given(regular_pushes())
def test_mirror_symmetry(push):
    contact, normal, action, l, mu, s = push
    flip = np.array([1.0, -1.0])
    with jax.enable_x64(True):
        twist = np.asarray(lynch.predict(contact, normal, action, l, mu, s))
        mirrored = np.asarray(lynch.predict(flip * contact, flip * normal, flip * action, l, mu, s))
    np.testing.assert_allclose(
        mirrored, twist * np.array([1, -1, -1]), rtol=1e-9, atol=1e-12 * _scale(action, l)
    )


@PROPERTY_SETTINGS
@hypothesis.given(regular_pushes(), st.floats(1e-3, 1e3))
def test_positive_homogeneity_in_action(push, factor):
    contact, normal, action, l, mu, s = push
    with jax.enable_x64(True):
        twist = np.asarray(lynch.predict(contact, normal, action, l, mu, s))
        scaled = np.asarray(lynch.predict(contact, normal, factor * action, l, mu, s))
    np.testing.assert_allclose(
        scaled, factor * twist, rtol=1e-9, atol=1e-12 * factor * _scale(action, l)
    )


@PROPERTY_SETTINGS
@hypothesis.given(regular_pushes())
def test_zero_contact_indicator_gives_no_motion(push):
    contact, normal, action, l, mu, _ = push
    np.testing.assert_array_equal(lynch.predict(contact, normal, action, l, mu, 0.0), 0.0)


@PROPERTY_SETTINGS
@hypothesis.given(
    st.floats(-np.pi, np.pi),
    st.floats(0.1, 10),
    st.floats(0, 3),
    st.floats(1e-3, 0.05),
    st.floats(0.02, 0.08),
    st.floats(0, 2),
)
def test_central_push_along_normal_translates_with_the_pusher(
    angle, normal_length, distance, speed, l, mu
):
    direction = _unit(angle)
    contact = -distance * l * direction  # on the line through the COM along the normal
    with jax.enable_x64(True):
        twist = lynch.predict(contact, normal_length * direction, speed * direction, l, mu)
    np.testing.assert_allclose(twist, [*(speed * direction), 0.0], rtol=1e-9, atol=1e-12)


def _on_boundary_action(contact, normal, l, mu, side):
    v_left, v_right = numpy_lynch.motion_cone(contact, normal, l, mu)
    return 0.01 * (v_left if side == "left" else v_right) / np.linalg.norm(v_left)


_REGULAR = dict(
    contact=[0.01, -0.03], normal=[0.0, 1.0], action=[0.004, 0.01], l=0.04, mu=0.5, s=1.0
)
_DEGENERATE_PUSHES = {
    "no_normal": dict(_REGULAR, normal=[0.0, 0.0]),
    "no_action": dict(_REGULAR, action=[0.0, 0.0]),
    "contact_at_com": dict(_REGULAR, contact=[0.0, 0.0]),
    "no_contact_indicator": dict(_REGULAR, s=0.0),
    "frictionless": dict(_REGULAR, mu=0.0),
    "pulling": dict(_REGULAR, action=[0.004, -0.01]),
    "tangential": dict(_REGULAR, action=[0.01, 0.0]),
    "on_left_boundary": dict(
        _REGULAR, action=_on_boundary_action([0.01, -0.03], [0.0, 1.0], 0.04, 0.5, "left")
    ),
    "on_right_boundary": dict(
        _REGULAR, action=_on_boundary_action([0.01, -0.03], [0.0, 1.0], 0.04, 0.5, "right")
    ),
    # c x n = 0.01, c . n = -0.05, mu = 1: v_pl . n = 0.01^2 + (0.01 - 0.05) * 0.01 < 0.
    "left_boundary_points_outward": dict(
        _REGULAR, contact=[0.01, -0.05], l=0.01, mu=1.0, action=_unit(np.radians(5)) * 0.01
    ),
    "everything_zero": dict(
        contact=[0.0, 0.0], normal=[0.0, 0.0], action=[0.0, 0.0], l=0.04, mu=0.0, s=0.0
    ),
}


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("name", sorted(_DEGENERATE_PUSHES))
def test_gradients_are_finite_on_degenerate_pushes(name, dtype):
    push = _DEGENERATE_PUSHES[name]
    args = [push[key] for key in ("contact", "normal", "action", "l", "mu", "s")]
    for gradient in _all_gradients(lynch.predict, dtype, *args):
        assert gradient.dtype == dtype
        assert np.all(np.isfinite(gradient)), name
    for gradient in _all_gradients(
        lambda *a: lynch.effective_push_velocity(*a)[0], dtype, *args[:5]
    ):
        assert np.all(np.isfinite(gradient)), name
    with jax.enable_x64(dtype == np.float64):
        jacobians = jax.jacfwd(lynch.predict, argnums=range(6))(
            *[jnp.asarray(np.asarray(arg), dtype) for arg in args]
        )
    assert all(np.all(np.isfinite(jacobian)) for jacobian in jacobians), name


def test_degenerate_pushes_have_the_documented_motion():
    def run(name):
        push = _DEGENERATE_PUSHES[name]
        args = [push[key] for key in ("contact", "normal", "action", "l", "mu")]
        with jax.enable_x64(True):
            v_p, sticking = lynch.effective_push_velocity(*args)
        return np.asarray(v_p), bool(sticking), np.asarray(push["action"])

    for name in ("no_normal", "no_action", "pulling", "tangential"):
        v_p, sticking, _ = run(name)
        np.testing.assert_array_equal(v_p, 0.0, err_msg=name)
        assert not sticking, name
    for name in ("on_left_boundary", "on_right_boundary"):
        v_p, _, action = run(name)
        np.testing.assert_allclose(v_p, action, rtol=1e-9, err_msg=name)
    push = _DEGENERATE_PUSHES["left_boundary_points_outward"]
    _, v_right = numpy_lynch.motion_cone(push["contact"], push["normal"], push["l"], push["mu"])
    v_p, sticking, action = run("left_boundary_points_outward")
    assert not sticking
    np.testing.assert_allclose(v_p, action[1] / v_right[1] * v_right, rtol=1e-9)
    at_com = {key: np.asarray(value) for key, value in _DEGENERATE_PUSHES["contact_at_com"].items()}
    np.testing.assert_allclose(lynch.predict(**at_com), [0.004, 0.01, 0.0], rtol=1e-6)


def test_length_of_normal_does_not_matter():
    contact, normal, action, l, mu, s = (
        x.astype(np.float32) for x in _random_pushes(np.random.default_rng(6), 1000)
    )
    unit = numpy_lynch.unit_normal(normal)
    twist = lynch.predict(contact, unit, action, l, mu, s)
    for length in (1e-6, 1e6):
        np.testing.assert_allclose(
            lynch.predict(contact, length * unit, action, l, mu, s), twist, rtol=1e-4, atol=1e-6
        )


def test_float32_and_float64():
    contact, normal, action, l, mu, s = _random_pushes(np.random.default_rng(2), 1000)
    args32 = [x.astype(np.float32) for x in (contact, normal, action, l, mu, s)]
    twist32 = lynch.predict(*args32)
    v_p32, _ = lynch.effective_push_velocity(*args32[:5])
    assert twist32.dtype == jnp.float32 and v_p32.dtype == jnp.float32
    assert lynch.object_velocity(args32[0], v_p32, args32[3]).dtype == jnp.float32
    with jax.enable_x64(True):
        twist64 = lynch.predict(contact, normal, action, l, mu, s)
        assert twist64.dtype == jnp.float64
        # float32 inputs stay float32 even with x64 enabled.
        assert lynch.predict(*args32).dtype == jnp.float32
    # Pushes close to v_pb . n = 0 amplify float32 rounding; compare the well-conditioned rest.
    v_left, v_right = numpy_lynch.motion_cone(contact, normal, l, mu)
    n = numpy_lynch.unit_normal(normal)
    conditioning = np.minimum(np.abs(np.sum(v_left * n, -1)), np.abs(np.sum(v_right * n, -1)))
    well_conditioned = conditioning > 0.1 * l**2
    np.testing.assert_allclose(
        np.asarray(twist32)[well_conditioned],
        np.asarray(twist64)[well_conditioned],
        rtol=1e-3,
        atol=1e-5,
    )


def test_jacfwd_matches_jacrev_and_vmap_matches_batching():
    contact, normal, action, l, mu, s = _random_pushes(np.random.default_rng(3), 8)
    with jax.enable_x64(True):
        single = [x[0] for x in (contact, normal, action, l, mu, s)]
        forward = jax.jacfwd(lynch.predict, argnums=range(6))(*single)
        reverse = jax.jacrev(lynch.predict, argnums=range(6))(*single)
        for jac_forward, jac_reverse in zip(forward, reverse):
            np.testing.assert_allclose(jac_forward, jac_reverse, rtol=1e-9, atol=1e-12)
        batched = lynch.predict(contact, normal, action, l, mu, s)
        np.testing.assert_allclose(
            jax.vmap(lynch.predict)(contact, normal, action, l, mu, s), batched, rtol=1e-12
        )
        shared_l = jax.vmap(lynch.predict, in_axes=(0, 0, 0, None, 0, 0))(
            contact, normal, action, 0.04, mu, s
        )
        np.testing.assert_allclose(
            shared_l, lynch.predict(contact, normal, action, 0.04, mu, s), rtol=1e-12
        )
        per_push_gradient = jax.vmap(jax.grad(lambda *a: lynch.predict(*a).sum(), argnums=3))(
            contact, normal, action, l, mu, s
        )
        batch_gradient = jax.grad(lambda *a: lynch.predict(*a).sum(), argnums=3)(
            contact, normal, action, l, mu, s
        )
        np.testing.assert_allclose(per_push_gradient, batch_gradient, rtol=1e-12)


def test_batch_shapes_broadcast():
    contact = np.zeros((4, 1, 2)) + [0.01, -0.03]
    twist = lynch.predict(contact, [0.0, 1.0], np.full((3, 2), 0.01), 0.04, np.full(3, 0.5))
    assert twist.shape == (4, 3, 3)
    v_p, sticking = lynch.effective_push_velocity(contact, [0.0, 1.0], [0.0, 0.01], 0.04, 0.5)
    assert v_p.shape == (4, 1, 2) and sticking.shape == (4, 1)


def test_check_inputs_accepts_valid_input():
    contact, normal, action, l, mu, s = _random_pushes(np.random.default_rng(4), 10)
    lynch.check_inputs(contact, normal / np.linalg.norm(normal, axis=-1, keepdims=True), action, l, mu, s)
    lynch.check_inputs([0.0, 0.0], [0.0, 1.0], [0.0, 0.0], 0.04, 0.0)
    lynch.check_inputs([0.0, 0.0], [0.0, 1.0009], [0.0, 0.0], 0.04, 0.0)  # within the tolerance
    lynch.check_inputs([0.0, 0.0], np.array([0.6, 0.8], np.float32), [0.0, 0.0], 0.04, 0.0)  # float32 rounding


@pytest.mark.parametrize(
    "name, value, message",
    [
        ("contact", np.zeros((5, 3)), r"contact: expected shape \[\.\.\., 2\]"),
        ("normal", np.zeros(()), r"normal: expected shape \[\.\.\., 2\]"),
        ("action", np.zeros((5, 1)), r"action: expected shape \[\.\.\., 2\]"),
        ("l", 0.0, "l: expected limit-surface ratio > 0"),
        ("l", -np.ones(5), "l: expected limit-surface ratio > 0"),
        ("mu", -0.1, "mu: expected friction coefficient >= 0"),
        ("s", 1.5, r"s: expected contact indicator in \[0, 1\]"),
        ("s", -0.5, r"s: expected contact indicator in \[0, 1\]"),
        ("contact", np.full((5, 2), np.nan), "contact: expected finite values"),
        ("mu", np.inf, "mu: expected finite values"),
        ("l", np.ones(4), "batch shapes do not broadcast"),
        ("s", "a", "s: expected a real numeric array"),
        ("normal", [0.0, 0.0], r"normal: expected unit vectors \(length 1 within 0.001\), got length 0 \(a zero "
                               r"normal predicts no motion\)"),
        ("normal", np.ones((5, 2)), "normal: expected unit vectors .*, got length 1.41421"),
        ("normal", np.array([[0.0, 1.0]] * 4 + [[0.0, 1.002]]), "normal: expected unit vectors .*, got length 1.002"),
        ("normal", [0.0, 0.5], "normal: expected unit vectors .*, got length 0.5"),
    ],
)
def test_check_inputs_rejects_bad_input(name, value, message):
    args = dict(
        contact=np.zeros((5, 2)), normal=np.tile([0.0, 1.0], (5, 1)), action=np.ones((5, 2)),
        l=np.full(5, 0.04), mu=np.full(5, 0.5), s=np.ones(5),
    )
    args[name] = value
    with pytest.raises(ValueError, match=message):
        lynch.check_inputs(**args)


def _valid_pushes():
    """Four valid pushes."""
    return dict(contact=np.full((4, 2), [0.01, -0.02]), normal=np.array([0.0, 1.0]), action=np.array([0.0, 0.01]),
                l=np.full(4, 0.04), mu=0.5, s=1.0)


@pytest.mark.parametrize(
    "name, value, message",
    [
        ("contact", np.zeros(3), r"contact: expected shape \[\.\.\., 2\], got \(3,\)"),
        ("normal", np.zeros(()), r"normal: expected shape \[\.\.\., 2\], got \(\)"),
        ("action", np.zeros((4, 3)), r"action: expected shape \[\.\.\., 2\], got \(4, 3\)"),
        ("contact", np.array([0.01, 0.02], np.complex64),
         "contact: expected a real numeric array, got dtype complex64"),
        ("l", np.complex64(0.04), "l: expected a real numeric array, got dtype complex64"),
        ("s", True, "s: expected a real numeric array, got dtype bool"),
        ("mu", np.ones(3, bool), "mu: expected a real numeric array, got dtype bool"),
        ("l", np.full(5, 0.04), r"batch shapes do not broadcast: contact \(4,\), .* l \(5,\)"),
    ],
)
@pytest.mark.parametrize("transform", ["jit", "vmap", "grad"])
def test_predict_checks_shapes_and_dtypes_when_traced(name, value, message, transform):
    arguments = {**_valid_pushes(), name: value}
    if transform == "jit":
        call = jax.jit(lambda args: lynch.predict(**args))
    elif transform == "vmap":  # a batch of one: the check sees the shapes without the mapped axis
        arguments = jax.tree.map(lambda array: np.asarray(array)[None], arguments)
        call = jax.vmap(lambda args: lynch.predict(**args))
    else:  # the gradient with respect to another (valid, float) argument
        wrt = "action" if name != "action" else "normal"
        point = arguments.pop(wrt)
        call = lambda args: jax.grad(lambda x: lynch.predict(**args, **{wrt: x}).sum())(point)  # noqa: E731
    with pytest.raises(ValueError, match=message):
        call(arguments)


@pytest.mark.parametrize(
    "function, arguments, message",
    [
        (lynch.effective_push_velocity, dict(contact=np.zeros(3), normal=np.ones(2), action=np.ones(2), l=0.04, mu=0.5),
         r"contact: expected shape \[\.\.\., 2\]"),
        (lynch.effective_push_velocity, dict(contact=np.zeros(2), normal=np.ones(2), action=np.ones(2, complex),
                                             l=0.04, mu=0.5), "action: expected a real numeric array"),
        (lynch.object_velocity, dict(contact=np.zeros(2), v_p=np.ones(3), l=0.04),
         r"v_p: expected shape \[\.\.\., 2\]"),
        (lynch.object_velocity, dict(contact=np.zeros(2), v_p=np.ones(2), l=True), "l: expected a real numeric array"),
    ],
)
def test_stages_check_shapes_and_dtypes(function, arguments, message):
    with pytest.raises(ValueError, match=message):
        function(**arguments)



def _gated_predict(contact, normal, action, l, mu, s=1.0):
    """`lynch.predict` with the straight-through push gate, as the hybrid heads train it."""
    motion = lynch.predict(contact, normal, action, l, mu, s)
    return lynch.with_push_gate_gradient(motion, contact, normal, action, l, mu, s)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_push_gate_gradient_keeps_the_motion_bit_for_bit(dtype):
    pushes = [x.astype(dtype) for x in _random_pushes(np.random.default_rng(7), 1000)]
    with jax.enable_x64(dtype == np.float64):
        motion = np.asarray(lynch.predict(*pushes))
        gated = np.asarray(_gated_predict(*pushes))
    assert gated.dtype == dtype
    np.testing.assert_array_equal(gated.view(np.uint8), motion.view(np.uint8))


def _facing_away_push(normal_angle):
    """A push along +y at a contact below the centre of mass, its predicted normal at `normal_angle` [rad] and
    the motion the true normal (+y) gives, which the loss asks for."""
    contact, action, l, mu = np.array([0.01, -0.03]), np.array([0.0, 0.01]), 0.04, 0.3
    target = np.asarray(lynch.predict(contact, [0.0, 1.0], action, l, mu))
    return contact, _unit(normal_angle), action, l, mu, target


def _motion_loss(physics, contact, action, l, mu, target):
    """Squared motion error [cm^2 + rad^2] as a function of the normal."""
    weights = jnp.asarray([1e4, 1e4, 1.0])
    return lambda normal: jnp.sum(weights * (physics(contact, normal, action, l, mu) - target) ** 2)


def _angle_deg(a, b):
    return np.degrees(np.arccos(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b)))


@pytest.mark.parametrize("degrees_from_push", [95, 120, 150, 175, -95, -120, -150, -175])
def test_normal_facing_away_from_the_push_is_turned_towards_it(degrees_from_push):
    contact, normal, action, l, mu, target = _facing_away_push(np.radians(90 + degrees_from_push))
    assert np.dot(normal, action) < 0
    exact = jax.jit(jax.grad(_motion_loss(lynch.predict, contact, action, l, mu, target)))
    gated_loss = jax.jit(_motion_loss(_gated_predict, contact, action, l, mu, target))
    gated = jax.jit(jax.grad(gated_loss))
    np.testing.assert_array_equal(exact(normal), 0.0)  # what training got before
    gradient = np.asarray(gated(normal))
    assert np.linalg.norm(gradient) > 0
    assert abs(np.dot(gradient, normal)) < 1e-5 * np.linalg.norm(gradient)  # turns the normal, keeps its length
    initial_loss = gated_loss(normal)
    angles = [_angle_deg(normal, action)]
    for _ in range(300):
        normal = normal - 50 * np.asarray(gated(normal))
        angles.append(_angle_deg(normal, action))
    # Each step turns it towards the push until it pushes; then the exact gradient fits the motion.
    pushing = int(np.argmax(np.asarray(angles) < 90))
    assert pushing > 0 and np.all(np.diff(angles[: pushing + 1]) < 0)
    assert gated_loss(normal) < 1e-6 * initial_loss


def test_push_gate_gradient_is_the_exact_derivative_where_the_pusher_pushes():
    pushes = _random_pushes(np.random.default_rng(8), 200)
    pushing = np.sum(pushes[1] * pushes[2], -1) > 0
    assert 10 < (~pushing).sum() < 100
    with jax.enable_x64(True):
        exact = jax.vmap(jax.jacrev(lynch.predict, argnums=range(6)))(*pushes)
        gated = jax.vmap(jax.jacrev(_gated_predict, argnums=range(6)))(*pushes)
    for argument, (jacobian, gated_jacobian) in enumerate(zip(exact, gated)):
        np.testing.assert_array_equal(gated_jacobian[pushing], jacobian[pushing], err_msg=f"argument {argument}")
        if argument not in (1, 2):  # only the normal and the action open the gate
            np.testing.assert_array_equal(gated_jacobian[~pushing], jacobian[~pushing], err_msg=f"argument {argument}")


def test_push_gate_gradient_is_continuous_at_the_gate():
    contact, action, l, mu = np.array([0.01, -0.03]), np.array([0.004, 0.01]), 0.04, 0.5
    gate = np.arctan2(action[1], action[0]) - np.pi / 2  # the normal perpendicular to the push
    with jax.enable_x64(True):
        pushing, facing_away = (
            np.asarray(jax.jacfwd(_gated_predict, argnums=(1, 2))(contact, _unit(gate + side * 1e-7), action, l, mu))
            for side in (1, -1)
        )
    assert np.abs(pushing).max() > 0
    np.testing.assert_allclose(facing_away, pushing, rtol=1e-5, atol=1e-6 * np.abs(pushing).max())


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("name", sorted(_DEGENERATE_PUSHES))
def test_push_gate_gradients_are_finite_on_degenerate_pushes(name, dtype):
    push = _DEGENERATE_PUSHES[name]
    args = [push[key] for key in ("contact", "normal", "action", "l", "mu", "s")]
    for gradient in _all_gradients(_gated_predict, dtype, *args):
        assert gradient.dtype == dtype
        assert np.all(np.isfinite(gradient)), name
    for normal in ([0.0, -1.0], [0.0, -1e-6]):  # facing away, of any length
        for gradient in _all_gradients(_gated_predict, dtype, *args[:1], normal, *args[2:]):
            assert np.all(np.isfinite(gradient)), name


def test_push_gate_gradient_checks_the_motion_shape():
    with pytest.raises(ValueError, match=r"motion: expected shape \[\.\.\., 3\]"):
        lynch.with_push_gate_gradient(np.zeros(2), [0.01, -0.03], [0.0, 1.0], [0.0, 0.01], 0.04, 0.5)
