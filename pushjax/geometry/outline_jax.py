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

Every outline is a polygon (:class:`Outline`, built once per object by :func:`outline`, both in
:mod:`pushjax.geometry.outline_polygon`). Ellipses are sampled densely
(:data:`pushjax.geometry.objects.ELLIPSE_OUTLINE_POINTS` = 256 vertices by default, or ``ellipse_points``): the
chords lie inside the true ellipse by at most :func:`ellipse_sagitta` (4.0 µm for ellip1 to 5.9 µm for ellip3 at
256 points, 0.25 to 0.37 µm at 1024) and the normal is piecewise constant, off the true normal by up to half a
facet's turn (0.7° for ellip1 to 1.05° for ellip3 at 256 points); the first shrinks with the square, the second
with the inverse of the vertex count. The contact normal still turns continuously as the pusher passes a vertex,
whose circle feature turns the normal with the pusher.

Everything is per push (one pusher, one motion): ``jax.vmap`` for batches. The features (the nearest edge, the
first one hit) are chosen without derivatives (``argmin``, a branch choice); the chosen features' quantities are
then computed again from their own vertices, so derivatives cost O(1), not O(V), per contact. Every quantity is
finite (double ``where``), so the gradients are finite everywhere, including pushes parallel to an edge, a zero
motion and a pusher centre exactly on the outline. Derivatives are those of the chosen feature: exact wherever the
contact feature (and whether it is touching at the start) does not change under a small perturbation.

Choosing the features in O(1) (``search="local"``, the default): a rollout's contact stays on or next to the
previous step's, so :func:`first_contact` searches only the ``2 WINDOW + 1`` edges around the edge ``feature`` it
is given (the previous step's :attr:`Contact.feature`, or :func:`initial_feature`'s guess from the pusher's
bearing) and their vertices, and keeps the window's choice only where it is provably the full search's:

* every feature outside the window is at least ``rho_k - |p - c_k|`` from the pusher centre ``p`` (a disc of
  radius ``rho_k`` about the pusher's place ``c_k`` touching edge ``k``, empty of the outline outside the window)
  and at least ``(p - a_k) . n_k + delta_k`` (all of them lie ``delta_k`` or more behind edge k's line; both
  computed once by :func:`outline`, in :attr:`Outline.ring`). This bound must exceed the window's nearest distance (then the nearest edge
  is the window's, and inside or outside follows from the side of its nearest point, away from the outline and
  from spikes) and, for a pusher not touching at the start, the radius plus the way the pusher travels before the
  window's first hit (or ``NO_HIT``): no feature outside is reached first;
* or the path (to ``NO_HIT``) stays farther than the radius from the outline's bounding circle, from the outer
  side of a window edge's line that has the whole outline on its inner side (every edge of a convex outline), or
  from the outline by the clearance grid's bound for the pusher's cell (:attr:`Outline.clearance`: a bay of a
  non-convex outline such as butter's): no contact (the next search starts around the window's nearest edge, or beyond the circle from the bearing).

Elsewhere (contact lost or far, a pusher that jumped, the first step when the guess is off) the full search over
every feature runs, under ``lax.cond``: one push runs it only when it needs it; under ``jax.vmap`` the batch runs
the window for all, then the full search for the pushes that need it alone when they are few (an eighth of the
batch or fewer), for the whole batch when more, and not at all when none (a custom batching rule,
``jax.custom_batching.custom_vmap``, also under nested ``vmap``). The window computes each feature with the full
search's arithmetic and breaks ties towards the lower index as ``argmin`` does, so the choices, hence values and
gradients, are the full search's (``search="full"``: every feature every time, the former behaviour).

Padding: :func:`outline` pads every polygon to :data:`PADDED_VERTICES` (256, the ellipses' count) with
zero-length edges at the first vertex, past its ``count`` real ones; both searches mask them (they never win and
never make a NaN), so every object's outline has the same shapes and one compiled program serves all 11.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp

from pushjax.geometry.objects import PUSHER_RADIUS
from pushjax.geometry.outline_polygon import (
    _DISTANCE_TOLERANCE,
    PADDED_VERTICES,
    SECTORS,
    WINDOW,
    Outline,
    _cross,
    ellipse_sagitta,
    initial_feature,
    outline,
)

__all__ = ["NO_HIT", "PADDED_VERTICES", "SECTORS", "WINDOW", "Contact", "Outline", "ellipse_sagitta",
           "first_contact", "initial_feature", "outline"]

NO_HIT = 2.0
"""Hit time of a feature that the path never reaches (any value > 1 works; finite, unlike inf, so that
unselected features do not make NaN gradients)."""
_TIME_TOLERANCE = 1e-12
"""Hit times this far below 0 count as 0."""
_MIN_SQUARED_LENGTH = 1e-30
"""Squared length (m^2) at or below which a vector has no direction: a pusher motion shorter than 1 fm is no motion
(float32's squares of such lengths are subnormal or zero, where the hit times' second derivatives overflow), a
normal that short falls back to the edge's."""
_GUARD_MARGIN = 1e-4
"""Safety margin of the local search's bounds, relative to the bounding circle's radius (7 µm for rect1): far above
the rounding of float32 coordinates, far below the millimetres the bounds leave."""
_SIDE_COSINE = 0.1
"""The nearest point's side (inside or outside) is trusted where the pusher's offset from it lies within
arccos(0.1) = 84° of the outward (pseudo-)normal there; closer to tangent (a spike's tip) the full search decides."""


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
      feature: [] int32, the edge to search around next (``feature`` of the next call along a path): the nearest
        edge when touching at the start, the edge (or the vertex's edge) hit when reachable, else the nearest edge
        (the window's, or the bearing's guess, when the pusher is far from the outline).
    """

    touches: jax.Array
    fraction: jax.Array
    point: jax.Array
    normal: jax.Array
    gap: jax.Array
    touching_at_start: jax.Array
    reachable: jax.Array
    feature: jax.Array


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


def _norm(vector):
    return _safe_sqrt(_dot(vector, vector))


def _crossings(a, e, point, mask):
    """[] bool, whether `point` [2] lies inside the polygon of edges (start `a`, vector `e`) where `mask` (crossing
    number; no gradient needed)."""
    b = a + e
    straddles = mask & ((a[:, 1] > point[1]) != (b[:, 1] > point[1]))
    dy = jnp.where(straddles, b[:, 1] - a[:, 1], 1.0)
    x_cross = a[:, 0] + (point[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / dy
    return (jnp.sum(straddles & (point[0] < x_cross)) % 2) == 1


def first_contact(shape: Outline, pusher, motion, radius=PUSHER_RADIUS, feature=None, search: str = "local") -> Contact:
    """First contact of a disc pusher with the outline (see the module docstring).

    Args:
      shape: the :class:`Outline`.
      pusher: [2] pusher centre at the start, object frame, m.
      motion: [2] pusher displacement, object frame, m.
      radius: [] pusher radius, m (>= 0).
      feature: [] int, the edge to search around (the previous step's :attr:`Contact.feature` along a path); None:
        :func:`initial_feature`'s guess. It changes no result, only how soon the search finds it.
      search: "local" (the window around `feature`, the full search where the window cannot prove its choice) or
        "full" (every feature; the former search, kept for comparison).

    Returns:
      The :class:`Contact` (object frame).
    """
    pusher, motion = jnp.asarray(pusher), jnp.asarray(motion)
    if pusher.shape != (2,) or motion.shape != (2,):
        raise ValueError(f"pusher, motion: expected shape [2] each (vmap for batches), got {pusher.shape}, "
                         f"{motion.shape}")
    if search not in _SEARCHES:
        raise ValueError(f"search: expected one of {', '.join(_SEARCHES)}, got {search!r}")
    r = jnp.asarray(radius, shape.start.dtype)
    motion = jnp.where(_dot(motion, motion) > _MIN_SQUARED_LENGTH, motion, 0.0)
    # Which features: decided without derivatives (a branch choice), then the chosen features' quantities are
    # computed again from their vertices alone, so derivatives cost O(1) instead of O(V).
    fixed = jax.lax.stop_gradient((shape, pusher, motion, r))
    start = initial_feature(shape, fixed[1]) if feature is None else jnp.asarray(feature, jnp.int32) % shape.count
    choice = _search(*fixed, jax.lax.stop_gradient(start), search)
    nearest_index, inside, _, feature, is_edge, _ = choice[:6]
    a, e, out = shape.start, shape.edge, shape.outward

    closest, offset = _closest_on_edges(a[nearest_index], e[nearest_index], pusher)
    distance = _safe_sqrt(_dot(offset, offset))
    start_normal = _unit_or(jnp.where(inside, pusher - closest, closest - pusher), -out[nearest_index])
    start_gap = jnp.where(inside, -distance - r, distance - r)

    t_edge, s_edge = _edge_times(a[feature], e[feature], out[feature], pusher, motion, r)
    t_corner = _corner_times(a[feature], pusher, motion, r)
    # Whether it touches (at the start, within the motion, within NO_HIT) is decided again from the chosen
    # features' own quantities, so that both searches decide alike to the last bit wherever they choose alike
    # (their vectorised distances and times can round differently).
    touching_at_start = inside | (jax.lax.stop_gradient(distance) <= r + _DISTANCE_TOLERANCE)
    t_chosen = jnp.where(is_edge, t_edge, t_corner)
    t_hit = jax.lax.stop_gradient(t_chosen)
    t_value = jnp.where(t_hit < NO_HIT, t_chosen, NO_HIT)
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
        feature=choice.track,
    )


def _closest_on_edges(a, e, pusher):
    """Closest points [..., 2] of edges (start `a`, vector `e`; a zero-length one: its start) to `pusher`, and
    pusher minus them."""
    squared_length = _dot(e, e)
    along = jnp.clip(_dot(pusher - a, e) / jnp.where(squared_length > 0, squared_length, 1.0), 0.0, 1.0)
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


_SEARCHES = ("local", "full")


class _Choice(NamedTuple):
    """The features a search chose (no derivatives): the nearest edge to the start, whether the start is inside and
    touching, the first-hit feature's index, whether it is an edge (else the circle about its start vertex), its hit
    time, and the edge to search around next."""

    nearest: jax.Array
    inside: jax.Array
    touching: jax.Array
    feature: jax.Array
    is_edge: jax.Array
    t_hit: jax.Array
    track: jax.Array


def _track(nearest, touching, feature, t_hit):
    return jnp.where(touching | (t_hit >= NO_HIT), nearest, feature).astype(jnp.int32)


_SMALL = 8
"""Outlines of at most this many vertices (the rectangles, triangles and hex) are searched in full over their first
rows, as cheap as a window (under ``vmap`` when every push's outline is that small)."""


def _search(shape: Outline, pusher, motion, r, start, search: str) -> _Choice:
    if search == "full" or shape.start.shape[0] <= 2 * WINDOW + 1:  # (static) a window would hold every edge
        return _full(shape, pusher, motion, r)
    return _tracked(shape, pusher, motion, r, start)


def _full(shape: Outline, pusher, motion, r, rows: int | None = None) -> _Choice:
    """The full search: every real feature (the padding masked), among the first `rows` (None: all)."""
    a, e, out = (x[:rows] for x in (shape.start, shape.edge, shape.outward))
    size = a.shape[0]
    real = jnp.arange(size) < shape.count
    _, offsets = _closest_on_edges(a, e, pusher)
    squared = jnp.where(real, _dot(offsets, offsets), jnp.inf)
    nearest = jnp.argmin(squared).astype(jnp.int32)
    inside = _crossings(a, e, pusher, real)
    touching = inside | (_safe_sqrt(squared[nearest]) <= r + _DISTANCE_TOLERANCE)
    t_edge, _ = _edge_times(a, e, out, pusher, motion, r)
    times = jnp.where(jnp.concatenate([real, real]),
                      jnp.concatenate([t_edge, _corner_times(a, pusher, motion, r)]), jnp.inf)
    index = jnp.argmin(times)
    feature, t_hit = (index % size).astype(jnp.int32), times[index]
    return _Choice(nearest, inside, touching, feature, index < size, t_hit, _track(nearest, touching, feature, t_hit))


def _local(shape: Outline, pusher, motion, r, start) -> tuple[_Choice, jax.Array]:
    """The window's choice around edge `start` and whether it needs the full search (see the module docstring)."""
    count, size = shape.count, shape.start.shape[0]
    length = shape.ring.shape[0] - size  # 2 WINDOW + 2 vertices, 2 WINDOW + 1 edges
    half = (length - 2) // 2
    rows = jax.lax.dynamic_slice_in_dim(shape.ring, start, length, axis=0)
    vertices, vertex_normal = rows[:, 0:2], rows[:, 6:8]
    a, e, out = vertices[:-1], rows[:-1, 2:4], rows[:-1, 4:6]
    slots = jnp.arange(length, dtype=jnp.int32)
    index = (start - half + slots) % count  # the features' own indices; repeated when count < length
    edges = index[:-1]
    covers = count < length  # the window holds every edge (some more than once): exact as it is

    along = _dot(pusher - a, e) / _dot(e, e)
    offsets = pusher - (a + jnp.clip(along, 0.0, 1.0)[:, None] * e)
    squared = _dot(offsets, offsets)
    least = jnp.min(squared)
    nearest = jnp.min(jnp.where(squared == least, edges, size))
    at_nearest = slots[:-1] == jnp.argmax(edges == nearest)
    distance = _safe_sqrt(least)
    # Inside: the crossing number when the window holds each edge once; else the side of the nearest point, from
    # the edge's normal or, at a vertex, the sum of its two edges' normals (the pseudo-normal).
    crossed = _crossings(a, e, pusher, slots[:-1] < count)
    pseudo_normal = jnp.where((along <= 0)[:, None], vertex_normal[:-1],
                              jnp.where((along >= 1)[:, None], vertex_normal[1:], out))
    side = jnp.sum(jnp.where(at_nearest, _dot(offsets, pseudo_normal), 0.0))
    pseudo_length = jnp.sum(jnp.where(at_nearest, _norm(pseudo_normal), 0.0))
    margin = _GUARD_MARGIN * shape.bound_radius
    sure_side = (distance > margin) & (jnp.abs(side) > _SIDE_COSINE * distance * pseudo_length)
    inside = jnp.where(covers, crossed, side < 0)
    touching = inside | (distance <= r + _DISTANCE_TOLERANCE)

    t_edge, _ = _edge_times(a, e, out, pusher, motion, r)
    t_corner = _corner_times(vertices, pusher, motion, r)
    t_first = jnp.minimum(jnp.min(t_edge), jnp.min(t_corner))
    first_edge = jnp.min(jnp.where(t_edge == t_first, edges, size))
    first_corner = jnp.min(jnp.where(t_corner == t_first, index, size))
    is_edge = first_edge < size
    feature = jnp.where(is_edge, first_edge, first_corner)
    t_hit = jnp.minimum(t_first, NO_HIT)
    choice = _Choice(nearest, inside, touching, feature, is_edge, t_hit, _track(nearest, touching, feature, t_hit))

    # Everything outside the window is at least `guard` from the pusher (the guard disc about the place touching
    # edge `start`), and at least `behind` (those features all lie `depth` behind that edge's line).
    guard = rows[half, 10] - _norm(pusher - rows[half, 8:10])
    behind = _dot(pusher - rows[half, 0:2], rows[half, 4:6]) + rows[half, 12]
    sees_nearest = jnp.maximum(guard, behind) > distance + margin
    sees_hit = ((guard - t_hit * _norm(motion) > r + margin)
                | (behind + t_hit * jnp.minimum(_dot(motion, rows[half, 4:6]), 0.0) > r + margin))
    # Touching or not is decided again from the nearest edge (first_contact): near the radius, the hit must be
    # the global one too.
    surely_touching = inside | (distance < r - margin)
    proven = covers | (sees_nearest & sure_side & (surely_touching | sees_hit))
    # No contact to choose where the whole path to NO_HIT stays farther than r from the bounding circle, or from
    # the outer side of a window edge's supporting line (the outline lies on its inner side).
    beyond_circle = _norm(pusher - shape.bound_centre) - shape.bound_radius - NO_HIT * _norm(motion) > r + margin
    height = _dot(pusher - a, out) - NO_HIT * jnp.maximum(-_dot(motion, out), 0.0)
    beyond_line = jnp.any((rows[:-1, 11] > 0) & (height > r + margin))
    far = beyond_circle | beyond_line | (_clearance(shape, pusher) - NO_HIT * _norm(motion) > r + margin)
    # The next search starts from the bearing's guess beyond the circle, from the window's nearest edge nearer.
    track = jnp.where(beyond_circle, initial_feature(shape, pusher), nearest)
    none = _Choice(nearest, jnp.array(False), jnp.array(False), nearest, jnp.array(True),
                   jnp.asarray(NO_HIT, t_hit.dtype), track)
    choice = jax.tree_util.tree_map(lambda far_value, value: jnp.where(far, far_value, value), none, choice)
    return choice, ~(far | proven)


def _clearance(shape: Outline, pusher) -> jax.Array:
    """[] the clearance grid's lower bound on the pusher centre's distance to the outline (outside it); -inf off the
    grid."""
    cells = shape.clearance.shape[0]
    corner = shape.bound_centre - shape.bound_radius
    cell = jnp.floor((pusher - corner) / (2 * shape.bound_radius) * cells).astype(jnp.int32)
    on_grid = jnp.all((cell >= 0) & (cell < cells))
    cell = jnp.clip(cell, 0, cells - 1)
    return jnp.where(on_grid, shape.clearance[cell[0], cell[1]], -jnp.inf)


def _one(shape, pusher, motion, r, start) -> _Choice:
    def tracked():
        choice, needs_full = _local(shape, pusher, motion, r, start)
        return jax.lax.cond(needs_full, lambda: _full(shape, pusher, motion, r), lambda: choice)

    return jax.lax.cond(shape.count <= _SMALL, lambda: _full(shape, pusher, motion, r, _SMALL), tracked)


@jax.custom_batching.custom_vmap
def _tracked(shape, pusher, motion, r, start) -> _Choice:
    """The local search with its fallback for one push; under ``vmap``, :func:`_batched`."""
    return _one(shape, pusher, motion, r, start)


@_tracked.def_vmap
def _tracked_vmap(axis_size, in_batched, shape, pusher, motion, r, start):
    shape_batched = any(jax.tree_util.tree_leaves(in_batched[0]))
    if shape_batched:
        shape = jax.tree_util.tree_map(lambda x, b: x if b else jnp.broadcast_to(x, (axis_size, *x.shape)), shape,
                                       in_batched[0])
    pusher, motion, r, start = (x if b else jnp.broadcast_to(x, (axis_size, *jnp.shape(x)))
                                for x, b in zip((pusher, motion, r, start), in_batched[1:], strict=True))
    choice = _batched(shape_batched)(shape, pusher, motion, r, start)
    return choice, jax.tree_util.tree_map(lambda _: True, choice)


@functools.cache
def _batched(shape_batched: bool):
    """The search over a batch (leading axis of everything but an unbatched shape), itself batched again under an
    outer ``vmap`` by merging the two batch axes."""

    @jax.custom_batching.custom_vmap
    def batched(shape, pusher, motion, r, start):
        return _over_batch(shape, shape_batched, pusher, motion, r, start)

    @batched.def_vmap
    def batched_vmap(axis_size, in_batched, shape, pusher, motion, r, start):
        inner = pusher.shape[1] if in_batched[1] else pusher.shape[0]
        merged_shape_batched = shape_batched or any(jax.tree_util.tree_leaves(in_batched[0]))

        def merge(x, outer, batched_inside):
            if outer and batched_inside:
                return x.reshape(axis_size * inner, *x.shape[2:])
            if outer:
                return jnp.repeat(x, inner, axis=0)
            if batched_inside:
                return jnp.broadcast_to(x[None], (axis_size, *x.shape)).reshape(axis_size * inner, *x.shape[1:])
            return jnp.broadcast_to(x, (axis_size * inner, *x.shape)) if merged_shape_batched else x

        shape = jax.tree_util.tree_map(lambda x, b: merge(x, b, shape_batched), shape, in_batched[0])
        pusher, motion, r, start = (merge(x, b, True) for x, b in zip((pusher, motion, r, start), in_batched[1:],
                                                                          strict=True))
        choice = _batched(merged_shape_batched)(shape, pusher, motion, r, start)
        choice = jax.tree_util.tree_map(lambda x: x.reshape(axis_size, inner, *x.shape[1:]), choice)
        return choice, jax.tree_util.tree_map(lambda _: True, choice)

    return batched


def _over_batch(shape, shape_batched: bool, pusher, motion, r, start) -> _Choice:
    """The window for the whole batch; the full search for the pushes that need it when they are few, for all when
    more, not at all when none."""
    shape_axis = 0 if shape_batched else None
    full = jax.vmap(_full, in_axes=(shape_axis, 0, 0, 0))

    def tracked():
        choice, needs_full = jax.vmap(_local, in_axes=(shape_axis, 0, 0, 0, 0))(shape, pusher, motion, r, start)
        size = needs_full.shape[0]
        few = size // 8
        needed = jnp.sum(needs_full)

        def everyone():
            return jax.tree_util.tree_map(
                lambda f, c: jnp.where(needs_full.reshape(size, *(1,) * (f.ndim - 1)), f, c),
                full(shape, pusher, motion, r), choice)

        def some():
            picked = jnp.nonzero(needs_full, size=few, fill_value=size)[0]

            def pick(x):
                return jnp.take(x, picked, axis=0, mode="clip")

            result = full(jax.tree_util.tree_map(pick, shape) if shape_batched else shape, pick(pusher),
                          pick(motion), pick(r))
            return jax.tree_util.tree_map(lambda c, f: c.at[picked].set(f, mode="drop"), choice, result)

        if few == 0:
            return jax.lax.cond(needed > 0, everyone, lambda: choice)
        return jax.lax.cond(needed > 0, lambda: jax.lax.cond(needed <= few, some, everyone), lambda: choice)

    def small():
        return jax.vmap(functools.partial(_full, rows=_SMALL), in_axes=(shape_axis, 0, 0, 0))(shape, pusher, motion, r)

    return jax.lax.cond(jnp.all(shape.count <= _SMALL), small, tracked)
