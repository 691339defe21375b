"""An object's outline as a polygon padded to one vertex count, for the pure JAX first contact of
:mod:`pushjax.geometry.outline_jax` (which re-exports these names).

:func:`outline` builds the :class:`Outline` once per object: the polygon counter-clockwise in the object's tracked
frame (an ellipse sampled densely, its chords inside the true ellipse by at most :func:`ellipse_sagitta`), the local
search's table of every edge's window and the bounds on the features outside it (:attr:`Outline.ring`), and the table
of bearings behind :func:`initial_feature`, the guess of the edge nearest to a pusher on a path's first step. Every
polygon is padded to :data:`PADDED_VERTICES` with zero-length edges, so every object's outline has the same shapes and
one compiled program serves all 11.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import shapely

from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object

PADDED_VERTICES = 256
"""Vertices every :func:`outline` is padded to by default (the ellipses' 256; a polygon with more keeps its own)."""
WINDOW = 6
"""Edges on either side of the tracked edge that the local search looks at (13 edges, 14 vertices)."""
SECTORS = 256
"""Bearings about the outline's bounding circle's centre in :func:`initial_feature`'s table."""
CLEARANCE_CELLS = 32
"""Cells per side of :attr:`Outline.clearance`'s grid over the square about the bounding circle (2.5 mm cells for
butter)."""
_DISTANCE_TOLERANCE = 1e-12
"""m; as in :mod:`pushjax.geometry.contact`: a start this much farther than r from the outline still touches."""


class Outline(NamedTuple):
    """A closed counter-clockwise polygon in the object's tracked frame (a JAX pytree), m, padded to a fixed size.

    Attributes:
      start: [N, 2] edge start vertices (the first ``count`` real; the padding repeats the first vertex).
      edge: [N, 2] edge vectors (start[k + 1] - start[k]), none of zero length but the padding's.
      outward: [N, 2] unit outward normals of the edges (the padding repeats the first).
      centroid: [2] centre of mass in the tracked frame.
      count: [] int32, the number of real vertices (``V <= N``).
      ring: [N + 2 WINDOW + 2, 13] the local search's table, row i for edge ``(i - WINDOW) mod count`` (so that
        rows k to k + 2 WINDOW + 1 are the window around edge k, wrapped around): its start vertex (2), edge (2),
        outward normal (2), the start vertex's pseudo-normal (the sum of its two edges' outward normals, 2), the
        pusher's centre touching the edge's middle (2), that centre's distance to the edges more than ``WINDOW``
        edges away (1; inf when there are none), whether the edge's line supports the outline (1: every vertex
        on its inner side; all edges of a convex outline) and how far behind the edge's line those edges lie (1;
        inf when there are none, negative when some lie in front); the padding's rows repeat the first.
      bound_centre: [2] centre of the vertices' bounding box.
      bound_radius: [] largest distance of a vertex from ``bound_centre``.
      sectors: [SECTORS] int32, the edge nearest to a pusher on the outline's outermost point at each bearing
        about ``bound_centre`` (:func:`initial_feature`).
      clearance: [CLEARANCE_CELLS, CLEARANCE_CELLS] a lower bound on the distance from every point of each cell of
        the square ``bound_centre ± bound_radius`` (first index along x) to the outline, where that point lies
        outside the polygon; zero or negative where the cell may reach the outline or lie inside (no bound).
    """

    start: jax.Array
    edge: jax.Array
    outward: jax.Array
    centroid: jax.Array
    count: jax.Array
    ring: jax.Array
    bound_centre: jax.Array
    bound_radius: jax.Array
    sectors: jax.Array
    clearance: jax.Array


def outline(obj: PushObject | str, dtype=jnp.float32, ellipse_points: int | None = None,
            pad_to: int | None = PADDED_VERTICES) -> Outline:
    """The polygon of `obj` (or its name) for :func:`~pushjax.geometry.outline_jax.first_contact`.

    Args:
      obj: the object or its name.
      dtype: float dtype of the arrays (``jnp.float64`` needs ``jax.enable_x64``).
      ellipse_points: vertices of an ellipse's polygon; default the object's own outline (256).
      pad_to: vertices to pad to (a polygon with more keeps its own count); None: no padding, ``N = V`` (a
        program compiled for each vertex count).

    Returns:
      The :class:`Outline`: counter-clockwise, repeated vertices dropped, padded.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    vertices = np.asarray(obj.outline, dtype=np.float64)
    if obj.is_ellipse and ellipse_points is not None:
        if ellipse_points < 8:
            raise ValueError(f"ellipse_points: expected at least 8, got {ellipse_points}")
        angles = np.linspace(0.0, 2 * np.pi, ellipse_points, endpoint=False)
        vertices = np.stack([obj.semi_axes[0] * np.cos(angles), obj.semi_axes[1] * np.sin(angles)], axis=-1)
    if pad_to is not None and pad_to < 1:
        raise ValueError(f"pad_to: expected a positive count or None, got {pad_to}")
    edge = np.roll(vertices, -1, axis=0) - vertices
    vertices = vertices[np.linalg.norm(edge, axis=-1) > 0]
    if not shapely.LinearRing(vertices).is_ccw:
        vertices = vertices[::-1]
    edge = np.roll(vertices, -1, axis=0) - vertices
    outward = np.stack([edge[:, 1], -edge[:, 0]], axis=-1) / np.linalg.norm(edge, axis=-1)[:, None]
    guard_centre, guard_radius, guard_depth = _guards(vertices, edge, outward)
    bound_centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    bound_radius = np.max(np.linalg.norm(vertices - bound_centre, axis=-1))
    sectors = _sector_table(vertices, edge, bound_centre)
    clearance = _clearance_grid(vertices, bound_centre, bound_radius)
    count = len(vertices)
    padding = 0 if pad_to is None else max(pad_to - count, 0)

    def padded(values, fill):
        return np.concatenate([values, np.repeat(fill[None], padding, axis=0)])

    floats = (padded(vertices, vertices[0]), padded(edge, np.zeros(2)), padded(outward, outward[0]), obj.centroid)
    supporting = np.array([np.max((vertices - vertex) @ normal) <= _DISTANCE_TOLERANCE
                           for vertex, normal in zip(vertices, outward, strict=True)])
    rows = np.concatenate([vertices, edge, outward, np.roll(outward, 1, axis=0) + outward, guard_centre,
                           guard_radius[:, None], supporting[:, None], guard_depth[:, None]], axis=-1)
    ring = rows[(np.arange(count + 2 * WINDOW + 2) - WINDOW) % count]
    ring = np.concatenate([ring, np.repeat(ring[:1], len(floats[0]) - count, axis=0)])
    return Outline(*(jnp.asarray(value, dtype) for value in floats), jnp.asarray(count, jnp.int32),
                   jnp.asarray(ring, dtype), jnp.asarray(bound_centre, dtype), jnp.asarray(bound_radius, dtype),
                   jnp.asarray(sectors, jnp.int32), jnp.asarray(clearance, dtype))


def _guards(vertices, edge, outward, window: int = WINDOW, radius: float = PUSHER_RADIUS, chunk: int = 256):
    """The local search's bounds on the features outside the window around each edge k, which all lie on the edges
    more than `window` edges away: ([V, 2] the pusher's centre touching edge k's middle, [V] its distance to those
    edges, [V] how far behind edge k's line they all lie (negative: some in front)); inf when there are none.
    float64."""
    count = len(vertices)
    centre = vertices + 0.5 * edge + radius * outward
    if 2 * window + 1 >= count:
        return centre, np.full(count, np.inf), np.full(count, np.inf)
    index = np.arange(count)
    squared_length = np.sum(edge * edge, axis=-1)
    radii, depths = np.empty(count), np.empty(count)
    for begin in range(0, count, chunk):
        rows = slice(begin, begin + chunk)
        relative = centre[rows, None, :] - vertices[None, :, :]
        along = np.clip(np.sum(relative * edge[None], axis=-1) / squared_length[None], 0.0, 1.0)
        distance = np.linalg.norm(relative - along[..., None] * edge[None], axis=-1)
        apart = np.abs(index[None, :] - index[rows, None])
        radii[rows] = np.min(np.where(np.minimum(apart, count - apart) > window, distance, np.inf), axis=1)
        # The far edges' vertices: window + 1 to count - window places after edge k's start.
        after = (index[None, :] - index[rows, None]) % count
        height = np.sum((vertices[None, :, :] - vertices[rows, None, :]) * outward[rows, None, :], axis=-1)
        depths[rows] = np.min(np.where((after > window) & (after <= count - window), -height, np.inf), axis=1)
    return centre, radii, depths


def _clearance_grid(vertices, centre, radius, cells: int = CLEARANCE_CELLS):
    """[cells, cells] :attr:`Outline.clearance`: each cell's centre's distance to the outline, less the cell's half
    diagonal, where that centre lies outside the polygon (every point of the cell then lies outside, at least that
    far); minus the distance less the half diagonal where it lies inside. float64."""
    side = 2 * radius / cells
    coordinates = centre[:, None] - radius + side * (np.arange(cells) + 0.5)[None]
    x, y = np.meshgrid(coordinates[0], coordinates[1], indexing="ij")
    points = shapely.points(x.ravel(), y.ravel())
    polygon = shapely.Polygon(vertices)
    distance = shapely.distance(polygon.exterior, points)
    signed = np.where(shapely.contains(polygon, points), -distance, distance)
    return (signed - side / math.sqrt(2)).reshape(cells, cells)


def _sector_table(vertices, edge, centre, sectors: int = SECTORS, radius: float = PUSHER_RADIUS):
    """[sectors] the edge nearest to a pusher touching the outline's outermost crossing with the ray from `centre`
    at each sector's middle bearing (from -pi)."""
    angles = -np.pi + 2 * np.pi * (np.arange(sectors) + 0.5) / sectors
    direction = np.stack([np.cos(angles), np.sin(angles)], axis=-1)[:, None, :]
    relative = (vertices - centre)[None]
    denominator = _cross(direction, edge[None])
    usable = np.abs(denominator) > 0
    safe = np.where(usable, denominator, 1.0)
    along_ray, along_edge = _cross(relative, edge[None]) / safe, _cross(relative, direction) / safe
    crossing = usable & (along_ray >= 0) & (along_edge >= 0) & (along_edge <= 1)
    reach = np.max(np.where(crossing, along_ray, 0.0), axis=1)
    points = centre + (reach + radius)[:, None] * direction[:, 0]
    relative = points[:, None, :] - vertices[None]
    along = np.clip(np.sum(relative * edge[None], axis=-1) / np.sum(edge * edge, axis=-1)[None], 0.0, 1.0)
    return np.argmin(np.linalg.norm(relative - along[..., None] * edge[None], axis=-1), axis=1)


def initial_feature(shape: Outline, pusher) -> jax.Array:
    """[] int32, a guess of the edge nearest to a pusher at `pusher` [2] (object frame) from its bearing, for
    :func:`~pushjax.geometry.outline_jax.first_contact`'s ``feature`` on a path's first step (the local search
    checks it)."""
    shape, pusher = jax.lax.stop_gradient((shape, jnp.asarray(pusher)))
    relative = pusher - shape.bound_centre
    count = shape.sectors.shape[0]
    bearing = (jnp.arctan2(relative[1], relative[0]) + jnp.pi) / (2 * jnp.pi)
    return shape.sectors[jnp.clip(jnp.floor(bearing * count).astype(jnp.int32), 0, count - 1)]


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
