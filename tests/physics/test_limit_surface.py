"""Tests of the exact limit-surface pushing model against an independent NumPy/SciPy reference."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.physics import limit_surface, lynch

from . import numpy_limit_surface

RADIUS = 0.05


def _sunflower(count, radius=RADIUS):
    """``count`` nearly uniformly spread points in a disc (a uniform support), [count, 2]."""
    index = np.arange(count) + 0.5
    r = radius * np.sqrt(index / count)
    angle = index * np.pi * (3 - np.sqrt(5))
    return np.stack([r * np.cos(angle), r * np.sin(angle)], -1)


def _rotate(vectors, angle):
    cos, sin = np.cos(angle), np.sin(angle)
    return np.stack([cos * vectors[..., 0] - sin * vectors[..., 1], sin * vectors[..., 0] + cos * vectors[..., 1]], -1)


def _random_pushes(rng, count):
    """Pushes around a disc of radius RADIUS: sticking, slipping both ways, pulling, no contact."""
    contact_angle = rng.uniform(-np.pi, np.pi, count)
    contact = np.stack([np.cos(contact_angle), np.sin(contact_angle)], -1) * RADIUS * rng.uniform(0.3, 1.4, (count, 1))
    normal_angle = contact_angle + np.pi + rng.uniform(-1.0, 1.0, count)
    normal = np.stack([np.cos(normal_angle), np.sin(normal_angle)], -1) * rng.uniform(0.5, 2, (count, 1))
    normal[:5] = 0  # no contact
    action_angle = normal_angle + rng.uniform(-1.9, 1.9, count)  # about 1/6 pull
    action = np.stack([np.cos(action_angle), np.sin(action_angle)], -1) * rng.uniform(1e-3, 0.02, (count, 1))
    mu = rng.uniform(0, 1.2, count)
    s = rng.uniform(0.2, 1, count)
    return contact, normal, action, mu, s


def _supports(rng, name):
    """(points [K, 2], weights [K], patch radius): a weighted uniform disc, or few points with padding."""
    if name == "disc":
        points = _sunflower(24)
        return points, rng.uniform(0.3, 1, 24), float(0.5 * RADIUS / np.sqrt(24))
    # 24 like the disc (one compilation for both): 4 weighted points, 20 zero-weight padding points.
    points = rng.uniform(-RADIUS, RADIUS, (24, 2))
    return points, np.concatenate([[0.5, 1.0, 0.7, 0.3], np.zeros(20)]), 0.012


@pytest.mark.parametrize("name", ["disc", "padded"])
def test_matches_independent_scipy_reference(name):
    rng = np.random.default_rng(0 if name == "disc" else 1)
    points, weights, rho = _supports(rng, name)
    count = 128
    contact, normal, action, mu, s = _random_pushes(rng, count)
    drift = np.where(np.arange(count)[:, None] % 2 == 0, 0.0, rng.uniform(-0.25, 0.25, (count, 2)))
    with jax.enable_x64(True):
        solution = limit_surface.solve(contact, normal, action, mu, points, weights, rho, s, drift)
    modes, sides = [], []
    for i in range(count):
        twist, force, mode = numpy_limit_surface.solve(contact[i], normal[i], action[i], mu[i], points, weights,
                                                       rho, s[i], drift[i])
        modes.append(mode)
        sides.append(np.sign(normal[i, 0] * force[1] - normal[i, 1] * force[0]) if mode == "slip" else 0)
        scale = np.linalg.norm(action[i]) * (1 + 1 / RADIUS)
        np.testing.assert_allclose(solution.twist[i], twist, rtol=1e-6, atol=1e-6 * scale, err_msg=f"push {i}")
        if mode != "none":
            np.testing.assert_allclose(solution.force[i], force, rtol=1e-6, atol=1e-8, err_msg=f"push {i}")
    modes = np.array(modes)
    assert np.max(np.asarray(solution.residual)) < 1e-13  # converged within the default iterations
    np.testing.assert_array_equal(np.asarray(solution.sticking), modes == "stick")
    np.testing.assert_array_equal(np.asarray(solution.slipping), modes == "slip")
    pulling = np.sum(action * normal, -1) <= 0
    sides = np.array(sides)
    # Every case is represented: sticking, slipping on both sides, pulling and no contact, with and without drift.
    for selection in (modes == "stick", sides > 0, sides < 0, pulling):
        assert np.sum(selection[::2]) >= 5 and np.sum(selection[1::2]) >= 5
    assert np.all(modes[:5] == "none")


def test_central_push_on_a_symmetric_support_translates():
    # Point symmetric about the origin, padded to 64 supports (as the next tests, which then share a compilation).
    points = np.concatenate([_sunflower(24), -_sunflower(24), np.full((16, 2), 0.02)])
    weights = np.concatenate([np.ones(48), np.zeros(16)])
    with jax.enable_x64(True):
        for angle in (0.0, 0.7, 2.0):
            direction = np.array([np.cos(angle), np.sin(angle)])
            solution = limit_surface.solve(-RADIUS * direction, direction, 0.01 * direction, 0.3, points,
                                           weights, 0.004)
            np.testing.assert_allclose(solution.twist, [*(0.01 * direction), 0.0], atol=1e-14)
            # A translating support pushes back with the full friction force, along the motion.
            np.testing.assert_allclose(solution.force, direction, atol=1e-12)
            assert solution.sticking


def test_single_support_point_rotates_about_the_line_to_the_pusher():
    # One point carries all the weight (the others are zero-weight padding): the object turns so that the
    # support point moves along the line from the contact (no friction torque about it but rho's), and the
    # support resists with the full friction force along that motion.
    rng = np.random.default_rng(2)
    support = np.array([0.01, -0.02])
    points = np.stack([support, [0.04, 0.0], [-0.03, 0.03]])
    contact, normal, action, _, _ = _random_pushes(rng, 40)
    rho = 1e-5
    with jax.enable_x64(True):
        solution = limit_surface.solve(contact, normal, action, 5.0, points, [2.0, 0.0, 0.0], rho,
                                       stick_iterations=40, slip_iterations=40)
    twist = np.asarray(solution.twist)
    velocity = twist[:, :2] + twist[:, 2:] * np.stack([-support[1] * np.ones(40), support[0] * np.ones(40)], -1)
    line = (support - contact) / np.linalg.norm(support - contact, axis=-1, keepdims=True)
    speed = np.linalg.norm(velocity, axis=-1)
    # Sticking wherever the force along that line points into the friction cone (mu = 5).
    sticking = np.asarray(solution.sticking)
    assert sticking.sum() >= 15
    cross = (velocity[:, 0] * line[:, 1] - velocity[:, 1] * line[:, 0])[sticking]
    # The patch (rho) adds a friction torque of relative size (rho / |r - c|)^2 ~ 1e-6.
    np.testing.assert_allclose(cross / speed[sticking], 0, atol=2e-5)
    # Its speed is the pusher's component along that line.
    np.testing.assert_allclose(speed[sticking], np.abs(np.sum(action * line, -1))[sticking], rtol=2e-5)
    np.testing.assert_allclose(np.asarray(solution.force)[sticking], velocity[sticking] / speed[sticking, None], atol=2e-5)


def test_pure_rotation_intercept_is_mean_support_distance():
    # A frictionless push whose force line passes far (h) from the centre turns the object about the point
    # of zero friction force, the supports' weighted geometric median (the centre of a point-symmetric
    # support): the wrench approaches the limit surface's torque intercept
    # m_max = sum_k p_k sqrt(|r_k|^2 + rho^2) (-> sum_k p_k |r_k| as rho -> 0), which is where Lynch's
    # ellipsoid with l = m_max agrees.
    rng = np.random.default_rng(3)
    half = _sunflower(32)
    half_weights = rng.uniform(0.5, 1, 32)
    points, weights = np.concatenate([half, -half]), np.concatenate([half_weights, half_weights])
    p = weights / weights.sum()
    rho = 1e-4
    h = 1e3 * RADIUS
    with jax.enable_x64(True):
        contact, normal, action = np.array([-RADIUS, h]), np.array([1.0, 0.0]), np.array([0.01, 0.0])
        solution = limit_surface.solve(contact, normal, action, 0.0, points, weights, rho)
        force = np.asarray(solution.force)
        torque = -h * force[0]  # c x f with f along x
        intercept = p @ np.sqrt(np.sum(points**2, -1) + rho**2)
        np.testing.assert_allclose(-torque, intercept, rtol=1e-6)
        np.testing.assert_allclose(intercept, p @ np.linalg.norm(points, axis=-1), rtol=1e-5)
        # Both models turn the object about (nearly) its centre there.
        twist = np.asarray(solution.twist)
        lynch_twist = np.asarray(lynch.predict(contact, normal, action, intercept, 0.0))
        for motion in (twist, lynch_twist):
            assert np.hypot(*motion[:2]) / abs(motion[2]) < 1e-3 * RADIUS


def test_small_rotations_differ_from_lynch_by_the_second_moment():
    # Near pure translation the exact surface is the ellipsoid with l_eff^2 = Var(x along the motion) + rho^2,
    # not l = m_max: a push along x at a small offset delta from the centre turns a uniform disc by
    # omega = -delta / (l_eff^2 + c_x^2) where Lynch (l = m_max) says -delta / (l^2 + c_x^2).
    points = _sunflower(64)
    points -= points.mean(0)
    rho = 0.5 * RADIUS / 8
    weights = np.ones(64)
    m_max = np.mean(np.sqrt(np.sum(points**2, -1) + rho**2))
    l_eff2 = np.mean(points[:, 0] ** 2) + rho**2
    delta = 1e-4 * RADIUS
    contact = np.array([-RADIUS, delta])
    with jax.enable_x64(True):
        along_x = np.array([1.0, 0.0])
        solution = limit_surface.solve(contact, along_x, along_x, 1.0, points, weights, rho)
        lynch_twist = lynch.predict(contact, along_x, along_x, m_max, 1.0)
    assert solution.sticking
    np.testing.assert_allclose(solution.twist[2], -delta / (l_eff2 + RADIUS**2), rtol=1e-4)
    ratio = float(solution.twist[2] / lynch_twist[2])
    np.testing.assert_allclose(ratio, (m_max**2 + RADIUS**2) / (l_eff2 + RADIUS**2), rtol=1e-4)
    # For a uniform disc (m_max = 2R/3, Var x = R^2/4) the exact model turns about 16 % more than Lynch's here.
    assert 1.12 < ratio < 1.18


@pytest.fixture(scope="module")
def disc_pushes():
    rng = np.random.default_rng(4)
    points, weights, rho = _supports(rng, "disc")
    contact, normal, action, mu, s = _random_pushes(rng, 128)  # 128 pushes on 24 supports as above: one compilation
    drift = rng.uniform(-0.2, 0.2, (128, 2))
    return contact, normal, action, mu, points, weights, rho, s, drift


def test_invariances(disc_pushes):
    contact, normal, action, mu, points, weights, rho, s, drift = disc_pushes
    with jax.enable_x64(True):
        base = limit_surface.solve(*disc_pushes)
        scale = np.linalg.norm(action, axis=-1, keepdims=True) * (1 + 1 / RADIUS)
        # Rotating everything rotates the translation and the force, and keeps the rotation.
        angle = 0.9
        turned = limit_surface.solve(*(_rotate(x, angle) for x in (contact, normal, action)), mu,
                                     _rotate(points, angle), weights, rho, s, _rotate(drift, angle))
        _assert_close(turned.twist[:, :2], _rotate(np.asarray(base.twist[:, :2]), angle), 1e-12, scale)
        _assert_close(turned.twist[:, 2], base.twist[:, 2], 1e-12, scale[:, 0])
        np.testing.assert_allclose(turned.force, _rotate(np.asarray(base.force), angle), atol=1e-12)
        # Twice the action, twice the motion; the same force. Weights at any common scale; normal of any length.
        doubled = limit_surface.solve(contact, 3 * normal, 2 * action, mu, points, 7 * weights, rho, s, drift)
        _assert_close(doubled.twist, 2 * np.asarray(base.twist), 1e-12, scale)
        np.testing.assert_allclose(doubled.force, base.force, atol=1e-12)
        # Zero-weight padding anywhere (one on the first contact) changes nothing.
        padding = np.array([contact[0], [0.3, -0.2], [0.0, 0.0]])
        padded = limit_surface.solve(contact, normal, action, mu, np.concatenate([points, padding]),
                                     np.concatenate([weights, np.zeros(3)]), rho, s, drift)
        _assert_close(padded.twist, base.twist, 1e-13, scale)
        np.testing.assert_allclose(padded.force, base.force, atol=1e-13)
        # s scales the twist only.
        still = limit_surface.solve(contact, normal, action, mu, points, weights, rho, np.zeros(128), drift)
        assert np.all(np.asarray(still.twist) == 0)
        np.testing.assert_array_equal(still.force, base.force)
        assert np.all(np.asarray(base.twist)[np.sum(action * normal, -1) <= 0] == 0)


def test_force_balances_the_friction_wrench(disc_pushes):
    # Quasi-static equilibrium: the support's friction wrench grad D(V) at the predicted twist equals the pusher's
    # wrench (force, c x force) plus the drift force, sticking or slipping.
    contact, normal, _, mu, points, weights, rho, _, drift = disc_pushes
    with jax.enable_x64(True):
        solution = limit_surface.solve(*disc_pushes)
        moving = np.asarray(solution.sticking | solution.slipping)
        _, wrench = limit_surface.dissipation(solution.twist[moving], points, weights, rho)
    force = np.asarray(solution.force)[moving]
    np.testing.assert_allclose(wrench[:, :2], force + drift[moving], atol=1e-12)
    torque = contact[moving, 0] * force[:, 1] - contact[moving, 1] * force[:, 0]
    np.testing.assert_allclose(wrench[:, 2], torque, atol=1e-12)
    # Slipping forces lie on the friction-cone edge.
    slipping = np.asarray(solution.slipping)
    unit = normal[slipping] / np.linalg.norm(normal[slipping], axis=-1, keepdims=True)
    slip_force = np.asarray(solution.force)[slipping]
    along, across = np.sum(unit * slip_force, -1), unit[:, 0] * slip_force[:, 1] - unit[:, 1] * slip_force[:, 0]
    np.testing.assert_allclose(np.abs(across), mu[slipping] * along, rtol=1e-10)


def test_vmap_and_batched_support_arrays(disc_pushes):
    contact, normal, action, mu, points, weights, rho, s, drift = disc_pushes
    with jax.enable_x64(True):
        batched = limit_surface.solve(*disc_pushes).twist
        mapped = jax.vmap(limit_surface.predict, in_axes=(0, 0, 0, 0, None, None, None, 0, 0))(*disc_pushes)
        np.testing.assert_allclose(mapped, batched, rtol=1e-12, atol=1e-15)
        # Per-push supports (here all the same) broadcast like the other arguments.
        per_push = limit_surface.predict(contact, normal, action, mu, np.broadcast_to(points, (128, *points.shape)),
                                         np.broadcast_to(weights, (128, len(weights))), np.full(128, rho), s, drift)
        np.testing.assert_allclose(per_push, batched, rtol=1e-12, atol=1e-15)
    with pytest.raises(ValueError, match="support_weights"):
        limit_surface.predict(contact, normal, action, mu, points, weights[:5], rho)
    with pytest.raises(ValueError, match="contact"):
        limit_surface.predict(contact[:, :1], normal, action, mu, points, weights, rho)


def test_float32_agrees_with_float64(disc_pushes):
    action = disc_pushes[2]
    single = limit_surface.solve(*(np.asarray(x, np.float32) for x in disc_pushes))
    assert single.twist.dtype == jnp.float32
    with jax.enable_x64(True):
        double = limit_surface.solve(*disc_pushes)
    scale = np.linalg.norm(action, axis=-1, keepdims=True) * (1 + 1 / RADIUS)
    _assert_close(single.twist, double.twist, 1e-4, scale)
    assert np.max(np.asarray(single.residual)) < 1e-5
    np.testing.assert_allclose(single.force, double.force, rtol=1e-4, atol=1e-4)


def _assert_close(actual, desired, tolerance, scale=1.0):
    """|actual - desired| <= tolerance * scale elementwise (scale broadcasts, e.g. per push)."""
    error = np.abs(np.asarray(actual) - np.asarray(desired)) / scale
    assert np.all(error <= tolerance), f"largest error {np.max(error):.3g} (scaled) > {tolerance}"


def _loss(weights_out, *args):
    """A random linear functional of the twist and the force, summed over the batch."""
    solution = limit_surface.solve(*args)
    return jnp.sum(solution.twist * weights_out[0]) + jnp.sum(solution.force * weights_out[1])


_loss_value = jax.jit(_loss)
_loss_gradient = jax.jit(jax.grad(_loss, argnums=tuple(range(1, 10))))


SMALL_SUPPORT = (np.array([[0.0, 0.0], [0.02, 0.01], [-0.01, 0.02], [0.03, -0.02], [0.01, 0.01]]),
                 np.array([1.0, 2.0, 1.0, 0.5, 0.0]), 0.005)
"""Four support points and a zero-weight padding point, shared by the gradient tests (one compilation)."""


def _regular_pushes():
    """8 pushes on SMALL_SUPPORT away from the stick/slip switch: 3 sticking, 3 slipping left, 2 right."""
    rng = np.random.default_rng(6)
    contact, normal, action, mu, s = _random_pushes(rng, 400)
    contact, normal = (contact * 0.8)[5:], normal[5:] / np.linalg.norm(normal[5:], axis=-1, keepdims=True)
    action, mu, s = action[5:], mu[5:], s[5:]
    drift = np.where(np.arange(395)[:, None] % 2 == 0, 0.0, rng.uniform(-0.2, 0.2, (395, 2)))
    points, weights, rho = SMALL_SUPPORT
    with jax.enable_x64(True):
        solution = limit_surface.solve(contact, normal, action, mu, points, weights, rho, s, drift)
        # The sticking force (all stick with mu = 1e9), whose angle to the cone edge is the distance to the switch.
        force = np.asarray(limit_surface.solve(contact, normal, action, np.full(395, 1e9), points, weights, rho, s, drift).force)
    angle = np.arctan2(normal[:, 0] * force[:, 1] - normal[:, 1] * force[:, 0], np.sum(normal * force, -1))
    unit_action = action / np.linalg.norm(action, axis=-1, keepdims=True)
    clear = (np.abs(np.abs(angle) - np.arctan(mu)) > 0.05) & (np.sum(unit_action * normal, -1) > 0.1)
    chosen = np.concatenate([np.flatnonzero(clear & solution.sticking)[:3],
                             np.flatnonzero(clear & solution.slipping & (angle > 0))[:3],
                             np.flatnonzero(clear & solution.slipping & (angle < 0))[:2]])
    assert len(chosen) == 8
    return [np.asarray(x, float) for x in (contact[chosen], normal[chosen], action[chosen], mu[chosen], points,
                                           weights, rho, s[chosen], drift[chosen])]


def test_gradients_match_central_differences():
    rng = np.random.default_rng(5)
    args = _regular_pushes()
    weights_out = (rng.normal(size=(8, 3)) * [1, 1, RADIUS], rng.normal(size=(8, 2)) * 1e-2)
    with jax.enable_x64(True):
        gradients = _loss_gradient(weights_out, *args)
        for position, (arg, gradient) in enumerate(zip(args, gradients)):
            step = 1e-6 * max(np.max(np.abs(arg)), 1e-2)
            numeric = np.zeros(arg.size)
            for j in range(arg.size):
                delta = np.zeros(arg.size)
                delta[j] = step
                plus = [*args[:position], arg + delta.reshape(arg.shape), *args[position + 1:]]
                minus = [*args[:position], arg - delta.reshape(arg.shape), *args[position + 1:]]
                numeric[j] = (_loss_value(weights_out, *plus) - _loss_value(weights_out, *minus)) / (2 * step)
            np.testing.assert_allclose(np.ravel(gradient), numeric, rtol=1e-5,
                                       atol=1e-7 * np.max(np.abs(numeric)) + 1e-10, err_msg=f"argument {position}")


DEGENERATE = {
    "no contact": {"normal": [0.0, 0.0]},
    "no action": {"action": [0.0, 0.0]},
    "pulling": {"action": [-0.01, 0.0]},
    "s = 0": {"s": 0.0},
    "contact on a support point": {"contact": [0.0, 0.0]},
    "contact on the padding point": {"contact": [0.01, 0.01]},
    "frictionless": {"mu": 0.0},
    "drift": {"drift": [0.2, 0.1]},
}


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_gradients_are_finite_on_degenerate_pushes(dtype):
    base = {"contact": [-0.03, 0.01], "normal": [1.0, 0.0], "action": [0.01, 0.003], "mu": 0.3, "s": 1.0, "drift": [0.0, 0.0]}
    cases = [{**base, **change} for change in DEGENERATE.values()]
    points, weights, rho = SMALL_SUPPORT
    batch = [np.asarray([case[name] for case in cases], float) for name in ("contact", "normal", "action", "mu")]
    batch += [points, weights, np.asarray(rho, float)]
    batch += [np.asarray([case[name] for case in cases], float) for name in ("s", "drift")]
    weights_out = (np.ones((8, 3)), np.ones((8, 2)))
    with jax.enable_x64(dtype == np.float64):
        gradients = _loss_gradient(jax.tree.map(lambda x: jnp.asarray(x, dtype), weights_out),
                                   *(jnp.asarray(x, dtype) for x in batch))
    for name, gradient in zip(("contact", "normal", "action", "mu", "points", "weights", "rho", "s", "drift"),
                              gradients):
        assert gradient.dtype == dtype
        assert np.all(np.isfinite(gradient)), name
    with jax.enable_x64(True):
        # Each push's twist (dx, dy, dtheta) through the loss compiled for test_gradients_match_central_differences.
        twist = np.zeros((8, 3))
        for i, j in np.ndindex(8, 3):
            selection = np.zeros((8, 3))
            selection[i, j] = 1.0
            twist[i, j] = _loss_value((selection, np.zeros((8, 2))), *batch)
    assert np.all(twist[:4] == 0)  # no contact, no action, pulling, s = 0
    assert np.all(twist[4:, 0] > 0)
