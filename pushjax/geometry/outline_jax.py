"""First contact of a moving disc pusher with an object's outline, as pure JAX (for rollouts and filters).

The same geometry as :mod:`pushjax.geometry.contact` (which stays the NumPy annotation of datasets), written
for ``jax.jit``, ``jax.vmap`` and ``jax.grad``: the pusher is a disc of radius ``r`` whose centre moves along
``p + t u``, ``t`` in [0, 1], and the first contact fraction is

    t* = min { t in [0, 1] : dist(p + t u, footprint) <= r }.

* Touching (or penetrating) at ``t = 0``: ``t* = 0``, the contact is the closest outline point, the normal
  points from the pusher centre to it (away from the centre when the centre lies inside the footprint).
* Otherwise ``t*`` is the smallest hit time of the path with the outline grown by ``r``: the edges offset
  outward by ``r`` (normal ``-outward``) and the circles of radius ``r`` about the vertices (normal from
  the pusher centre at the hit to the vertex). No convexity is assumed (butter is non-convex).

Every outline is a polygon (:class:`Outline`, built once per object by :func:`outline`). Ellipses are
sampled densely (:data:`pushjax.geometry.objects.ELLIPSE_OUTLINE_POINTS` = 256 vertices by default, or
``ellipse_points``): the chords lie inside the true ellipse by at most :func:`ellipse_sagitta` (4.0 µm for
ellip1 to 5.9 µm for ellip3 at 256 points, 0.25 to 0.37 µm at 1024) and the normal is piecewise constant,
off the true normal by up to half a facet's turn (0.7° for ellip1 to 1.05° for ellip3 at 256 points); the
first shrinks with the square, the second with the inverse of the vertex count. The contact normal still
turns continuously as the pusher passes a vertex, whose circle feature turns the normal with the pusher.

Everything is per push (one pusher, one motion): ``jax.vmap`` for batches. The features (the nearest edge, the
first one hit) are chosen over all of them without derivatives (``argmin``, a branch choice); the chosen
features' quantities are then computed again from their own vertices, so derivatives cost O(1), not O(V), per
contact. Every quantity is finite (double ``where``), so the gradients are finite everywhere, including pushes
parallel to an edge, a zero motion and a pusher centre exactly on the outline. Derivatives are those of the
chosen feature: exact wherever the contact feature (and whether it is touching at the start) does not change
under a small perturbation.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import shapely

from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object

__all__ = ["NO_HIT", "Contact", "Outline", "ellipse_sagitta", "first_contact", "outline"]

NO_HIT = 2.0
"""Hit time of a feature that the path never reaches (any value > 1 works; finite, unlike inf, so that
unselected features do not make NaN gradients)."""
_DISTANCE_TOLERANCE = 1e-12
"""m; as in :mod:`pushjax.geometry.contact`: a start this much farther than r from the outline still touches."""
_TIME_TOLERANCE = 1e-12
"""Hit times this far below 0 count as 0."""
_MIN_SQUARED_LENGTH = 1e-30
"""Squared length (m^2) at or below which a vector has no direction: a pusher motion shorter than 1 fm is no motion
(float32's squares of such lengths are subnormal or zero, where the hit times' second derivatives overflow), a
normal that short falls back to the edge's."""


class Outline(NamedTuple):
    """A closed counter-clockwise polygon in the object's tracked frame (a JAX pytree), m.

    Attributes:
      start: [V, 2] edge start vertices.
      edge: [V, 2] edge vectors (start[k + 1] - start[k]), none of zero length.
      outward: [V, 2] unit outward normals of the edges.
      centroid: [2] centre of mass in the tracked frame.
    """

    start: jax.Array
    edge: jax.Array
    outward: jax.Array
    centroid: jax.Array


class Contact(NamedTuple):
    """First contact of one push (object frame unless said otherwise).

    Attributes:
      touches: [] bool, whether the pusher touches the object during the motion.
      fraction: [] fraction t* of the motion before the first touch; 0 when touching at the start, 1 when
        never touching.
      point: [2] touched outline point, m; when the pusher does not touch within the motion but would if it
        went on along ``u`` (``reachable``, within ``t < NO_HIT``), the point it would touch; else zeros.
      normal: [2] unit inward normal at that point; zeros when not ``reachable``.
      gap: [] distance the pusher travels along the normal before it touches, m: ``t* (u . normal)`` for a
        hit (beyond the motion when not touching), ``distance - r`` when touching at the start (negative:
        penetrating), 0 when not ``reachable``.
      touching_at_start: [] bool.
      reachable: [] bool, whether the pusher touches now or would touch going on along ``u`` (``t* < NO_HIT``).
    """

    touches: jax.Array
    fraction: jax.Array
    point: jax.Array
    normal: jax.Array
    gap: jax.Array
    touching_at_start: jax.Array
    reachable: jax.Array


def outline(obj: PushObject | str, dtype=jnp.float32, ellipse_points: int | None = None) -> Outline:
    """The polygon of `obj` (or its name) for :func:`first_contact`.

    Args:
      obj: the object or its name.
      dtype: float dtype of the arrays (``jnp.float64`` needs ``jax.enable_x64``).
      ellipse_points: vertices of an ellipse's polygon; default the object's own outline (256).

    Returns:
      The :class:`Outline`: counter-clockwise, repeated vertices dropped.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    vertices = np.asarray(obj.outline, dtype=np.float64)
    if obj.is_ellipse and ellipse_points is not None:
        if ellipse_points < 8:
            raise ValueError(f"ellipse_points: expected at least 8, got {ellipse_points}")
        angles = np.linspace(0.0, 2 * np.pi, ellipse_points, endpoint=False)
        vertices = np.stack([obj.semi_axes[0] * np.cos(angles), obj.semi_axes[1] * np.sin(angles)], axis=-1)
    edge = np.roll(vertices, -1, axis=0) - vertices
    vertices = vertices[np.linalg.norm(edge, axis=-1) > 0]
    if not shapely.LinearRing(vertices).is_ccw:
        vertices = vertices[::-1]
    edge = np.roll(vertices, -1, axis=0) - vertices
    outward = np.stack([edge[:, 1], -edge[:, 0]], axis=-1) / np.linalg.norm(edge, axis=-1)[:, None]
    return Outline(*(jnp.asarray(value, dtype) for value in (vertices, edge, outward, obj.centroid)))


def ellipse_sagitta(semi_axes: tuple[float, float], points: int) -> float:
    """Largest distance (m) between an ellipse and its inscribed polygon of `points` equally spaced (in the
    parameter angle) vertices, measured on a fine grid of the parameter."""
    a, b = semi_axes
    step = 2 * math.pi / points
    fine = np.linspace(0.0, step, 201)
    worst = 0.0
    for begin in np.linspace(0.0, 2 * math.pi, points, endpoint=False)[: points // 4 + 1]:
        p0 = np.array([a * math.cos(begin), b * math.sin(begin)])
        p1 = np.array([a * math.cos(begin + step), b * math.sin(begin + step)])
        chord = p1 - p0
        normal = np.array([chord[1], -chord[0]]) / np.linalg.norm(chord)
        arc = np.stack([a * np.cos(begin + fine), b * np.sin(begin + fine)], axis=-1)
        worst = max(worst, float(np.max((arc - p0) @ normal)))
    return worst


def _cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def _safe_sqrt(value):
    positive = value > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, value, 1.0)), 0.0)


def _unit_or(vector, fallback):
    """`vector` normalised, or `fallback` where its length is (near) zero; finite gradients."""
    squared = _dot(vector, vector)
    usable = squared > _MIN_SQUARED_LENGTH
    length = jnp.sqrt(jnp.where(usable, squared, 1.0))
    return jnp.where(usable[..., None], vector / length[..., None], fallback)


def _inside(shape: Outline, point):
    """[] bool, whether `point` [2] lies inside the polygon (crossing number; no gradient needed)."""
    a = shape.start
    b = a + shape.edge
    straddles = (a[:, 1] > point[1]) != (b[:, 1] > point[1])
    dy = jnp.where(straddles, b[:, 1] - a[:, 1], 1.0)
    x_cross = a[:, 0] + (point[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
    return (jnp.sum(straddles & (point[0] < x_cross)) % 2) == 1


def first_contact(shape: Outline, pusher, motion, radius=PUSHER_RADIUS) -> Contact:
    """First contact of a disc pusher with the outline (see the module docstring).

    Args:
      shape: the :class:`Outline`.
      pusher: [2] pusher centre at the start, object frame, m.
      motion: [2] pusher displacement, object frame, m.
      radius: [] pusher radius, m (>= 0).

    Returns:
      The :class:`Contact` (object frame).
    """
    pusher, motion = jnp.asarray(pusher), jnp.asarray(motion)
    if pusher.shape != (2,) or motion.shape != (2,):
        raise ValueError(f"pusher, motion: expected shape [2] each (vmap for batches), got {pusher.shape}, "
                         f"{motion.shape}")
    r = jnp.asarray(radius, shape.start.dtype)
    motion = jnp.where(_dot(motion, motion) > _MIN_SQUARED_LENGTH, motion, 0.0)
    # Which features: decided over all of them without derivatives (a branch choice), then the chosen features'
    # quantities are computed again from their vertices alone, so derivatives cost O(1) instead of O(V).
    fixed = jax.lax.stop_gradient((shape, pusher, motion, r))
    nearest_index, inside, touching_at_start, feature, is_edge, t_hit = _select(*fixed)
    a, e, out = shape.start, shape.edge, shape.outward

    closest, offset = _closest_on_edges(a[nearest_index], e[nearest_index], pusher)
    distance = _safe_sqrt(_dot(offset, offset))
    start_normal = _unit_or(jnp.where(inside, pusher - closest, closest - pusher), -out[nearest_index])
    start_gap = jnp.where(inside, -distance - r, distance - r)

    t_edge, s_edge = _edge_times(a[feature], e[feature], out[feature], pusher, motion, r)
    t_corner = _corner_times(a[feature], pusher, motion, r)
    t_value = jnp.where(t_hit < NO_HIT, jnp.where(is_edge, t_edge, t_corner), NO_HIT)
    hit_point = jnp.where(is_edge, a[feature] + jnp.clip(s_edge, 0.0, 1.0) * e[feature], a[feature])
    centre_at_hit = pusher + jnp.minimum(t_value, 1.0) * motion
    hit_normal = jnp.where(is_edge, -out[feature], _unit_or(a[feature] - centre_at_hit, -out[feature]))

    touches = touching_at_start | (t_hit <= 1.0)
    reachable = touching_at_start | (t_hit < NO_HIT)
    fraction = jnp.where(touching_at_start, 0.0, jnp.where(touches, t_value, 1.0))
    point = jnp.where(touching_at_start, closest, hit_point)
    normal = jnp.where(touching_at_start, start_normal, hit_normal)
    gap = jnp.where(touching_at_start, start_gap, t_value * _dot(motion, hit_normal))
    return Contact(
        touches=touches,
        fraction=fraction,
        point=jnp.where(reachable, point, 0.0),
        normal=jnp.where(reachable, normal, 0.0),
        gap=jnp.where(reachable, gap, 0.0),
        touching_at_start=touching_at_start,
        reachable=reachable,
    )


def _closest_on_edges(a, e, pusher):
    """Closest points [..., 2] of edges (start `a`, vector `e`) to `pusher`, and pusher minus them."""
    along = jnp.clip(_dot(pusher - a, e) / _dot(e, e), 0.0, 1.0)
    closest = a + along[..., None] * e
    return closest, pusher - closest


def _edge_times(a, e, out, pusher, motion, r):
    """Hit time of the path with each edge offset outward by r (p + t u = a + r out + s e), NO_HIT where it
    misses, and s."""
    offset_start = a + r * out - pusher
    denominator = _cross(motion, e)
    parallel = denominator == 0
    safe_denominator = jnp.where(parallel, 1.0, denominator)
    t_edge = _cross(offset_start, e) / safe_denominator
    s_edge = _cross(offset_start, motion) / safe_denominator
    edge_hit = ~parallel & (s_edge >= 0) & (s_edge <= 1) & (t_edge >= -_TIME_TOLERANCE)
    return jnp.where(edge_hit, jnp.maximum(t_edge, 0.0), NO_HIT), s_edge


def _corner_times(a, pusher, motion, r):
    """Hit time of the path with the circles of radius r about vertices `a`, NO_HIT where it misses: the first root
    of |p - a + t u|^2 = r^2, written as c / (-b + sqrt(b^2 - a c)) to avoid cancellation."""
    relative = pusher - a
    half_b = _dot(motion, relative)
    c = _dot(relative, relative) - r * r
    discriminant = half_b * half_b - _dot(motion, motion) * c
    corner_hit = (half_b < 0) & (discriminant >= 0)
    root_denominator = -half_b + _safe_sqrt(discriminant)
    t_corner = c / jnp.where(corner_hit, root_denominator, 1.0)
    corner_hit = corner_hit & (t_corner >= -_TIME_TOLERANCE)
    return jnp.where(corner_hit, jnp.maximum(t_corner, 0.0), NO_HIT)


def _select(shape: Outline, pusher, motion, r):
    """The features (no derivatives): nearest edge to the start, whether the start is inside and touching, the
    first-hit feature's index, whether it is an edge (else the circle about its start vertex) and its hit time."""
    a, e, out = shape.start, shape.edge, shape.outward
    _, offsets = _closest_on_edges(a, e, pusher)
    squared = _dot(offsets, offsets)
    nearest_index = jnp.argmin(squared)
    inside = _inside(shape, pusher)
    touching_at_start = inside | (_safe_sqrt(squared[nearest_index]) <= r + _DISTANCE_TOLERANCE)
    t_edge, _ = _edge_times(a, e, out, pusher, motion, r)
    times = jnp.concatenate([t_edge, _corner_times(a, pusher, motion, r)])
    index = jnp.argmin(times)
    count = a.shape[0]
    return nearest_index, inside, touching_at_start, index % count, index < count, times[index]
