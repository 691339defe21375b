"""The local contact search (the window around a tracked feature, the full search as fallback) against the full
search, on every object; the padded outlines: masked, finite, one compiled program for every object."""

import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax import planar
from pushjax.geometry import OBJECT_NAMES, outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, get_object, limit_surface_ratio
from pushjax.physics import rollout
from tests.geometry.test_outline_jax import DEGENERATE

STEPS = 40
PATHS_PER_KIND = 12


def _approach(obj, rng, gap):
    """(start [2], unit direction [2]): `gap` (m) before a random side point, within ±60° of its normal."""
    point, normal = obj.side_point(int(rng.integers(len(obj.sides))), float(rng.uniform(0.05, 0.95)))
    direction = planar.rotation_matrix(rng.uniform(-1.0, 1.0)) @ normal
    return point - direction * (PUSHER_RADIUS / max(direction @ normal, 0.2) + gap), direction


def _paths(obj, seed):
    """[4 PATHS_PER_KIND, STEPS + 1, 2] pusher paths in the object's frame at yaw 0, four kinds: straight pushes,
    pushes that back off (contact lost) and come back (regained), short pushes followed by one long step (a jump) to
    another side or into the object, and random walks that graze the outline."""
    rng = np.random.default_rng(seed)
    fractions = np.linspace(0.0, 1.0, STEPS + 1)[:, None]
    paths = []
    for _ in range(PATHS_PER_KIND):
        start, direction = _approach(obj, rng, rng.uniform(0.0, 0.005))
        paths.append(start + fractions * rng.uniform(0.02, 0.06) * direction)
    for _ in range(PATHS_PER_KIND):
        start, direction = _approach(obj, rng, rng.uniform(0.0, 0.003))
        along = np.concatenate([np.linspace(0.0, 0.02, 16), np.linspace(0.02, 0.008, 11)[1:],
                                np.linspace(0.008, 0.03, 16)[1:]])
        paths.append(start + along[:, None] * direction)
    for _ in range(PATHS_PER_KIND):
        first, first_direction = _approach(obj, rng, 0.002)
        second, second_direction = _approach(obj, rng, 0.0)  # touching at once
        if rng.uniform() < 0.3:  # jump into the object, near its centre
            second = obj.centroid + rng.uniform(-0.005, 0.005, 2)
        half = fractions[: STEPS // 2 + 1] * 2
        paths.append(np.concatenate([first + half * 0.005 * first_direction,  # a little push, then the jump
                                     second + half[:-1] * 0.02 * second_direction]))
    for _ in range(PATHS_PER_KIND):
        start, direction = _approach(obj, rng, rng.uniform(0.0, 0.01))
        heading = np.arctan2(direction[1], direction[0]) + np.cumsum(rng.normal(0.0, 0.5, STEPS))
        moves = rng.uniform(0.0, 0.003, STEPS)[:, None] * np.stack([np.cos(heading), np.sin(heading)], axis=-1)
        paths.append(np.concatenate([start[None], start + np.cumsum(moves, axis=0)]))
    return np.stack(paths)


@functools.cache
def _rollouts(search):
    def run(shape, pose, path, l, mu):
        return rollout.rollout(shape, pose, path, l, mu, search=search)

    def final(shape, pose, path, l, mu):
        return jnp.sum(run(shape, pose, path, l, mu).poses[-1])

    batched = jax.jit(jax.vmap(run, in_axes=(None, 0, 0, None, 0)))
    gradient = jax.jit(jax.vmap(jax.grad(final, argnums=(2, 4)), in_axes=(None, 0, 0, None, 0)))
    return batched, gradient


def _needs_full(shape, pose, path, l, mu):
    """[T] bool, whether each step of the rollout needed the full search (the rollout replayed step by step)."""
    predict = rollout.effects_lib.compose(())
    r = jnp.asarray(PUSHER_RADIUS, shape.start.dtype)

    def body(carry, inputs):
        pose, feature = carry
        pusher, increment = inputs
        local_pusher = rollout._rotate(pusher - pose[:2], -pose[2])
        motion = rollout._rotate(increment, -pose[2])
        motion = jnp.where(jnp.sum(motion * motion) > 1e-30, motion, 0.0)
        _, needs = outline_jax._local(shape, local_pusher, motion, r, feature)
        new_pose, _, feature = rollout._step(predict, {}, shape, pose, pusher, increment, l, mu, r, 1.0, 0.0, None,
                                             feature, "local")
        return (new_pose, feature), needs

    first = outline_jax.initial_feature(shape, rollout._rotate(path[0] - pose[:2], -pose[2]))
    return jax.lax.scan(body, (pose, first), (path[:-1], jnp.diff(path, axis=0)))[1]


_needs_full_batched = jax.jit(jax.vmap(_needs_full, in_axes=(None, 0, 0, None, 0)))


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_local_search_rolls_out_as_the_full_search(name):
    """Random pusher paths (straight, contact lost and regained, jumps, grazing walks) from random poses: every
    pose, contact and gradient of the local search is the full search's; the window chose most steps."""
    obj = get_object(name)
    rng = np.random.default_rng(len(name))
    with jax.enable_x64(True):
        shape = outline_jax.outline(obj, jnp.float64)
        paths = _paths(obj, seed=len(name))
        poses = np.concatenate([rng.uniform(-0.05, 0.05, (len(paths), 2)), rng.uniform(-np.pi, np.pi, (len(paths), 1))],
                               axis=-1)
        paths = poses[:, None, :2] + planar.rotate(paths, poses[:, None, 2])  # the paths turned with the object
        mus = rng.uniform(0.1, 1.0, len(paths))
        l = limit_surface_ratio(obj)
        local, local_gradient = _rollouts("local")
        full, full_gradient = _rollouts("full")
        got, expected = local(shape, poses, paths, l, mus), full(shape, poses, paths, l, mus)
        for got_leaf, expected_leaf in zip(jax.tree_util.tree_leaves(got), jax.tree_util.tree_leaves(expected),
                                           strict=True):
            np.testing.assert_allclose(np.asarray(got_leaf), np.asarray(expected_leaf), rtol=0, atol=1e-12)
        touches = np.asarray(expected.steps.touches)
        assert touches.mean() > 0.3 and (touches[:, :-1] & ~touches[:, 1:]).any()  # touching, and contact lost
        assert (~touches[:, :-1] & touches[:, 1:]).any()  # and regained
        # One push alone (lax.cond, not the batched rule) is the same too.
        single = rollout.rollout(shape, poses[30], paths[30], l, mus[30])
        np.testing.assert_allclose(np.asarray(single.poses), np.asarray(expected.poses[30]), rtol=0, atol=1e-12)
        for got_leaf, expected_leaf in zip(local_gradient(shape, poses, paths, l, mus),
                                           full_gradient(shape, poses, paths, l, mus), strict=True):
            assert np.all(np.isfinite(np.asarray(got_leaf)))
            np.testing.assert_allclose(np.asarray(got_leaf), np.asarray(expected_leaf), rtol=1e-9, atol=1e-12)
        needs = np.asarray(_needs_full_batched(shape, poses, paths, l, mus))
    if int(shape.count) > outline_jax._SMALL:  # the window, not the small outlines' full search, chose mostly
        assert needs.mean() < 0.2  # (the fallback: test_local_first_contact_is_the_full_one_from_any_feature)


_initial_features = jax.jit(jax.vmap(outline_jax.initial_feature, in_axes=(None, 0)))
_one_contact = jax.jit(outline_jax.first_contact, static_argnames="search")
_windows = jax.jit(jax.vmap(outline_jax._local, in_axes=(None, 0, 0, None, 0)))


@functools.cache
def _contacts(search):
    """The first contacts of a batch of pushes, each searched from its own feature (every object: one program)."""
    contact = functools.partial(outline_jax.first_contact, search=search)
    return jax.jit(jax.vmap(lambda *args: contact(*args), in_axes=(None, 0, 0, None, 0)))


@pytest.mark.parametrize("name", ["ellip1", "ellip3", "butter"])
def test_local_first_contact_is_the_full_one_from_any_feature(name):
    """Pushes from anywhere around the object, starting the search at any edge: the window's choice where it can
    prove it, the full search's elsewhere, the full search's contact always."""
    obj = get_object(name)
    rng = np.random.default_rng(7)
    count = 400
    angle = rng.uniform(-np.pi, np.pi, count)
    start = np.abs(obj.outline).max() * rng.uniform(0.0, 1.5, count)[:, None] * np.stack([np.cos(angle),
                                                                                           np.sin(angle)], -1)
    heading = angle + np.pi + rng.uniform(-1.0, 1.0, count)
    motion = rng.uniform(0.0, 0.02, count)[:, None] * np.stack([np.cos(heading), np.sin(heading)], -1)
    with jax.enable_x64(True):
        shape = outline_jax.outline(obj, jnp.float64)
        exact = int(shape.count)
        near = np.asarray(_initial_features(shape, start))
        features = np.where(rng.uniform(size=count) < 0.5, near, rng.integers(0, exact, count))
        got, expected = (_contacts(search)(shape, start, motion, PUSHER_RADIUS, features)
                         for search in ("local", "full"))
        one = _one_contact(shape, start[3], motion[3], feature=features[3])
        _, needs = _windows(shape, start, motion, PUSHER_RADIUS, features)
    for field in outline_jax.Contact._fields[:-1]:
        np.testing.assert_allclose(np.asarray(getattr(got, field)), np.asarray(getattr(expected, field)), rtol=0,
                                   atol=1e-12, err_msg=field)
        np.testing.assert_allclose(np.asarray(getattr(one, field)), np.asarray(getattr(expected, field))[3], rtol=0,
                                   atol=1e-12, err_msg=field)
    assert 0.05 < np.mean(np.asarray(expected.touches)) < 0.95
    needs = np.asarray(needs)
    assert 0.1 < needs.mean() < 0.9  # random features are often too far off: both branches are exercised
    assert np.all((np.asarray(got.feature) >= 0) & (np.asarray(got.feature) < exact))


def test_every_object_shares_the_padded_shapes_and_one_compiled_rollout():
    shapes = [outline_jax.outline(name) for name in OBJECT_NAMES]
    structures = {jax.tree_util.tree_structure(shape) for shape in shapes}
    signatures = {tuple((leaf.shape, leaf.dtype) for leaf in jax.tree_util.tree_leaves(shape)) for shape in shapes}
    assert len(structures) == 1 and len(signatures) == 1
    assert [int(shape.count) for shape in shapes] == [len(get_object(name).outline) for name in OBJECT_NAMES]
    path = jnp.linspace(jnp.array([-0.09, 0.0]), jnp.array([-0.03, 0.0]), 24)  # 23 steps: a length of its own
    for effects in [(), ("pusher_friction",)]:
        before = rollout.rollout._cache_size()
        poses = [rollout.rollout(shape, jnp.zeros(3), path, 0.04, 0.3, effects=effects).poses for shape in shapes]
        assert rollout.rollout._cache_size() - before == 1, effects  # one program for all 11 objects
        assert all(np.isfinite(np.asarray(pose)).all() for pose in poses)
        assert np.abs(np.asarray(poses[0][-1])).max() > 1e-3  # rect1 was pushed


def test_padding_never_wins_and_changes_nothing():
    """Pushes at and around rect1's first vertex (where the padding's zero-length edges sit) and the degenerate
    pushes: the padded outline's contacts, chosen features and gradients are the unpadded one's, all finite."""
    padded, plain = outline_jax.outline("rect1"), outline_jax.outline("rect1", pad_to=None)
    assert padded.start.shape == (256, 2) and plain.start.shape == (4, 2) and int(padded.count) == 4
    assert outline_jax.outline("ellip2", ellipse_points=300).start.shape == (300, 2)  # more: its own count
    with pytest.raises(ValueError, match="pad_to"):
        outline_jax.outline("rect1", pad_to=0)
    with pytest.raises(ValueError, match="search"):
        outline_jax.first_contact(padded, jnp.zeros(2), jnp.zeros(2), search="nearest")
    corner = np.asarray(padded.start[0], np.float64)
    offsets = np.stack(np.meshgrid(np.linspace(-0.008, 0.008, 9), np.linspace(-0.008, 0.008, 9)), -1).reshape(-1, 2)
    pushers = np.concatenate([corner + offsets, np.array([p for p, _ in DEGENERATE])]).astype(np.float32)
    motions = np.concatenate([np.tile([[0.004, -0.003]], (len(offsets), 1)),
                              np.array([m for _, m in DEGENERATE])]).astype(np.float32)

    def total(shape, pusher, motion, search):
        hit = outline_jax.first_contact(shape, pusher, motion, search=search)
        return jnp.sum(hit.point) + jnp.sum(hit.normal) + hit.fraction + hit.gap, hit

    run = jax.jit(jax.vmap(jax.value_and_grad(total, argnums=(1, 2), has_aux=True), in_axes=(None, 0, 0, None)),
                  static_argnums=3)
    for search in ["local", "full"]:
        (_, got), got_grads = run(padded, pushers, motions, search)
        (_, expected), expected_grads = run(plain, pushers, motions, "full")
        for field in outline_jax.Contact._fields[:-1]:
            np.testing.assert_allclose(np.asarray(getattr(got, field)), np.asarray(getattr(expected, field)),
                                       atol=1e-7, err_msg=field)
        assert np.all(np.asarray(got.feature) < 4)
        for got_grad, expected_grad in zip(got_grads, expected_grads, strict=True):
            assert np.all(np.isfinite(np.asarray(got_grad)))
            np.testing.assert_allclose(np.asarray(got_grad), np.asarray(expected_grad), atol=1e-5)


def test_outlines_of_several_objects_vmap_together():
    """A batch over objects of batches over pushes (the batching rule merges the two axes): each object's result."""
    names = ["rect1", "ellip2", "butter"]
    shapes = jax.tree_util.tree_map(lambda *leaves: jnp.stack(leaves), *[outline_jax.outline(name)
                                                                         for name in names])
    paths = jnp.stack([jnp.asarray(_paths(get_object(name), seed=3)[::8], jnp.float32) for name in names])
    mus = jnp.full(paths.shape[:2], 0.4)
    nested = jax.jit(jax.vmap(jax.vmap(rollout.rollout, in_axes=(None, None, 0, None, 0)),
                              in_axes=(0, None, 0, None, 0)))(shapes, jnp.zeros(3), paths, 0.04, mus).poses
    for k, name in enumerate(names):
        alone = jax.vmap(rollout.rollout, in_axes=(None, None, 0, None, 0))(
            outline_jax.outline(name), jnp.zeros(3), paths[k], 0.04, mus[k]).poses
        np.testing.assert_allclose(np.asarray(nested[k]), np.asarray(alone), atol=1e-6)
        full = jax.vmap(functools.partial(rollout.rollout, search="full"), in_axes=(None, None, 0, None, 0))(
            outline_jax.outline(name), jnp.zeros(3), paths[k], 0.04, mus[k]).poses
        np.testing.assert_allclose(np.asarray(nested[k]), np.asarray(full), atol=1e-6)


@pytest.mark.parametrize("name", ["butter", "ellip3", "rect1", "tri1"])
def test_clearance_grid_is_a_lower_bound_on_the_distance_outside(name):
    """Random points in every cell: where the cell's clearance is positive, the point lies outside the polygon and
    at least that far from its outline."""
    import shapely

    shape = outline_jax.outline(name, jnp.float64 if jax.config.jax_enable_x64 else jnp.float32)
    clearance = np.asarray(shape.clearance, np.float64)
    cells = clearance.shape[0]
    polygon = shapely.Polygon(np.asarray(shape.start, np.float64)[: int(shape.count)])
    rng = np.random.default_rng(0)
    corner = np.asarray(shape.bound_centre, np.float64) - float(shape.bound_radius)
    side = 2 * float(shape.bound_radius) / cells
    cell = rng.integers(0, cells, (4000, 2))
    points = corner + (cell + rng.uniform(0.0, 1.0, (4000, 2))) * side
    bound = clearance[cell[:, 0], cell[:, 1]]
    proven = bound > 0
    distance = shapely.distance(polygon.exterior, shapely.points(points))
    outside = ~shapely.contains(polygon, shapely.points(points))
    assert proven.mean() > 0.3  # the grid proves something about most of the square around the object
    assert np.all(outside[proven]) and np.all(distance[proven] >= bound[proven] - 1e-7)
    lookup = jax.vmap(outline_jax._clearance, in_axes=(None, 0))(shape, jnp.asarray(points, shape.start.dtype))
    np.testing.assert_allclose(np.asarray(lookup), bound, rtol=1e-6, atol=1e-9)
    assert float(outline_jax._clearance(shape, jnp.asarray(corner - side, shape.start.dtype))) == -np.inf


def test_a_pusher_in_butters_bay_needs_no_full_search():
    """butter's notch on its -x side holds a pusher 2 cm from every edge, inside the bounding circle and behind no
    supporting line: the clearance grid proves that a short push touches nothing (before the grid, every step of
    the controller's plans there ran the full search), and the contact is the full search's."""
    shape = outline_jax.outline("butter")
    pushers = jnp.array([[-0.048, 0.0], [-0.046, 0.004], [-0.047, -0.004]])
    motions = jnp.array([[0.003, 0.0], [0.002, 0.001], [0.002, -0.002]])
    features = jax.vmap(outline_jax.initial_feature, in_axes=(None, 0))(shape, pushers)
    _, needs = _windows(shape, pushers, motions, PUSHER_RADIUS, features)
    assert not np.any(np.asarray(needs))
    got, expected = (_contacts(search)(shape, pushers, motions, PUSHER_RADIUS, features) for search in ("local", "full"))
    for field in outline_jax.Contact._fields[:-1]:
        np.testing.assert_array_equal(np.asarray(getattr(got, field)), np.asarray(getattr(expected, field)), field)
    assert not np.any(np.asarray(expected.reachable) & np.asarray(expected.touches))
