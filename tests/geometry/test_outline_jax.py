"""The JAX first contact against the NumPy contact annotation, and its gradients on degenerate pushes."""

import itertools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.geometry import contact as contact_lib
from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, get_object


def _random_pushes(obj, count, seed):
    """Pushes from around the object towards it: touching, missing, starting inside, grazing."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(-np.pi, np.pi, count)
    radius = np.abs(obj.outline).max() * rng.uniform(0.3, 1.6, count)
    start = radius[:, None] * np.stack([np.cos(angle), np.sin(angle)], -1)
    heading = angle + np.pi + rng.uniform(-0.8, 0.8, count)
    motion = rng.uniform(0.0, 0.08, count)[:, None] * np.stack([np.cos(heading), np.sin(heading)], -1)
    return start, motion


_batched = jax.jit(jax.vmap(outline_jax.first_contact, in_axes=(None, 0, 0)))


@pytest.mark.parametrize("name", ["rect1", "tri2", "hex", "butter"])
def test_first_contact_matches_numpy_annotation_on_polygons(name):
    obj = get_object(name)
    start, motion = _random_pushes(obj, 300, seed=len(name))
    expected = contact_lib.annotate(obj, np.zeros(3), start, motion)
    with jax.enable_x64(True):
        shape = outline_jax.outline(obj, jnp.float64)
        got = _batched(shape, start, motion)
        got = jax.tree_util.tree_map(np.asarray, got)
    np.testing.assert_array_equal(got.touches, expected.touches)
    touches = expected.touches
    assert 30 < touches.sum() < 290  # both kinds are covered
    np.testing.assert_allclose(got.fraction, expected.first_contact_fraction, atol=1e-9)
    np.testing.assert_allclose(got.point[touches], expected.contact_world[touches], atol=1e-9)
    np.testing.assert_allclose(got.normal[touches], expected.normal[touches], atol=1e-7)


def test_ellipse_polygon_error_is_the_documented_one():
    obj = get_object("ellip3")
    start, motion = _random_pushes(obj, 300, seed=3)
    expected = contact_lib.annotate(obj, np.zeros(3), start, motion)
    sagitta = outline_jax.ellipse_sagitta(obj.semi_axes, 256)
    assert 5e-6 < sagitta < 6e-6  # the module docstring's 5.9 µm
    with jax.enable_x64(True):
        got = _batched(outline_jax.outline(obj, jnp.float64), start, motion)
    both = np.asarray(got.touches) & expected.touches
    # Touching differs only where the path grazes the outline within the sagitta.
    assert np.mean(np.asarray(got.touches) == expected.touches) > 0.98
    np.testing.assert_allclose(np.asarray(got.point)[both], expected.contact_world[both], atol=5e-4)
    assert np.degrees(np.max(np.arccos(np.clip(np.sum(np.asarray(got.normal)[both] * expected.normal[both], -1),
                                               -1, 1)))) < 1.2  # half a facet's turn, 1.05°, plus the contacts' offset


DEGENERATE = [
    ([0.0, -0.045 - PUSHER_RADIUS], [0.0, 0.0]),            # no motion, touching exactly
    ([0.0, -0.045 - PUSHER_RADIUS], [0.01, 0.0]),           # sliding along the edge, parallel to it
    ([0.0, 0.0], [0.01, 0.002]),                            # centre inside the object
    ([0.0, -0.045], [0.0, 0.01]),                           # centre on the outline
    ([0.2, 0.2], [0.01, 0.0]),                              # far away, never touching
    ([0.045 + PUSHER_RADIUS, 0.045 + 0.01], [0.0, -0.02]),  # onto the corner circle's tangent point
    ([-0.045, -0.06], [0.0, 0.02]),                         # exactly at a vertex's x
    ([0.0, -0.06], [0.0, 0.0]),                             # no motion, not touching
]


def test_gradients_are_finite_on_degenerate_pushes():
    shape = outline_jax.outline("rect1")

    def total(pusher, motion):
        hit = outline_jax.first_contact(shape, pusher, motion)
        return jnp.sum(hit.point) + jnp.sum(hit.normal) + hit.fraction + hit.gap

    pushers, motions = (jnp.asarray(np.array(values, np.float32)) for values in zip(*DEGENERATE))
    grads = jax.jit(jax.vmap(jax.grad(total, argnums=(0, 1))))(pushers, motions)
    for grad in grads:
        assert np.all(np.isfinite(np.asarray(grad)))


def test_vertex_normal_turns_with_the_pusher():
    """At a corner the normal is that of the corner circle: continuous as the pusher passes the corner."""
    shape = outline_jax.outline("rect1")
    offsets = np.linspace(-0.004, 0.002, 13)
    pushers = np.stack([0.045 + PUSHER_RADIUS * 0.5 + offsets, np.full_like(offsets, -0.07)], axis=-1)
    normals = np.asarray(_batched(shape, pushers, np.tile([0.0, 0.05], (len(offsets), 1))).normal)
    turns = [np.degrees(np.arccos(np.clip(a @ b, -1, 1))) for a, b in itertools.pairwise(normals)]
    assert max(turns) < 40.0
    assert np.allclose(normals[0], [0, 1]) and not np.allclose(normals[-1], [0, 1])


def _contact_vector(shape, pusher, offset, motion):
    hit = outline_jax.first_contact(shape, pusher - offset, motion)
    return jnp.concatenate([hit.point, hit.normal, hit.fraction[None], hit.gap[None]])


_second_derivative = jax.jit(jax.grad(
    lambda offset, shape, pusher, motion: jnp.sum(jax.jacfwd(_contact_vector, argnums=2)(shape, pusher, offset,
                                                                                      motion))))
"""d/d offset of the sum of d contact / d offset (one program for every case below, not op by op)."""


@pytest.mark.parametrize("length", [1e-25, 1e-20, 1e-16])
def test_second_derivatives_are_finite_for_a_pusher_standing_still_up_to_float_noise(length):
    """A touching pusher that moves by float noise (as the testbed's pusher after its push): the derivative of the
    contact's Jacobian (what learning a filter's noise differentiates) is finite, as for a pusher exactly still."""
    shape = outline_jax.outline("rect1")
    pusher = jnp.array([float(get_object("rect1").outline[:, 0].min()) - PUSHER_RADIUS, 0.0], jnp.float32)
    for motion in (jnp.array([length, 0.0], jnp.float32), jnp.zeros(2, jnp.float32)):
        second = _second_derivative(jnp.zeros(2, jnp.float32), shape, pusher, motion)
        assert np.all(np.isfinite(np.asarray(second))), (length, second)
