"""First contact between a moving disc pusher and a push object (data annotation).

Following Kloss, Schaal & Bohg (Sec. IV-B), every push is annotated with the point where the pusher
first touches the object, the surface normal there and the part of the pusher motion that happens
after the touch. The pusher is a disc of radius ``r`` whose centre moves along ``p + t u``,
``t`` in [0, 1]; the object's footprint is a closed region (its outline plus interior). The first
contact fraction is

    t* = min { t in [0, 1] : dist(p + t u, footprint) <= r },

and the contact point is the footprint point closest to the pusher centre at ``t*``.

Method (NumPy, float64, vectorised over the batch; no convexity assumption anywhere):

* Polygons, exactly: if the pusher does not touch the footprint at ``t = 0``, it first touches it
  where its centre enters the footprint grown by ``r``. That region's boundary is made of the edges
  offset outward by ``r`` and circles of radius ``r`` about the vertices, and every such feature
  lies inside the region, so ``t*`` is the minimum of the path's ray-segment and ray-circle hit
  times over all features. An axis-aligned bounding-box test of the path against each edge (grown
  by ``r``) first selects the candidate features, which keeps the non-convex 637-vertex butter
  cheap.
* Ellipses, exactly: the grown ellipse is convex and its boundary is the offset curve
  ``q(theta) + r n(theta)``. On the arc of the offset curve that faces the motion the cross
  product of ``u`` with the curve point is monotone in ``theta``, so the entry point is found by
  bisection on ``theta`` to machine precision. The distance at ``t = 0`` uses the closest point on
  the ellipse (Eberly's bisection on the Lagrange multiplier).
* Already touching or penetrating at ``t = 0``: ``t* = 0``, the contact is the closest boundary
  point and the normal points from the pusher centre to it (away from the pusher centre if the
  centre lies inside the footprint).

Everything is computed in the object's tracked frame and rotated back into world axes. The speed
goal (>= 1e5 annotations in <= 10 s on 2 CPU cores) is met by NumPy; see ``benchmarks/contact.py``.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import shapely

from pushjax import planar
from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object

__all__ = ["NO_CONTACT_FRACTION", "ContactAnnotation", "annotate"]

NO_CONTACT_FRACTION = 1.0
"""``first_contact_fraction`` of a push that never touches the object."""

_CHUNK = 8192
"""Queries processed at once; bounds the [chunk, edges] candidate masks to a few MB."""
_BISECTION_STEPS = 80
"""Halvings of a bracket: enough to shrink any bracket used here below float64 resolution."""
_TIME_TOLERANCE = 1e-12
"""Hit times this far below 0 count as 0 (rounding when the start is exactly r from the object)."""
_DISTANCE_TOLERANCE = 1e-12
"""m; a start this much farther than r from the object still touches it, so that a pusher placed
at exactly r (e.g. from ``side_point``) touches regardless of rounding."""


@dataclasses.dataclass(frozen=True)
class ContactAnnotation:
    """Contact annotation of a batch of pushes, batch shape ``[...]`` (NumPy arrays, world axes).

    Attributes:
      touches: [...] bool, whether the pusher touches the object during the push.
      first_contact_fraction: [...] fraction ``t*`` in [0, 1] of the push made before the first
        touch; 0 when touching at the start, :data:`NO_CONTACT_FRACTION` (1) when never touching.
      contact_world: [..., 2] touched point on the object's boundary in world coordinates, m;
        zeros when never touching.
      contact_rel_com: [..., 2] that point minus the object's centre of mass, in world axes, m
        (the ``contact`` of :func:`pushjax.physics.lynch.predict` with a world-frame action);
        zeros when never touching.
      normal: [..., 2] unit surface normal at the contact pointing into the object, world axes;
        at a corner the direction from the pusher centre to the corner; zeros when never touching.
      action_from_contact: [..., 2] pusher displacement after the first touch, ``(1 - t*) u``, m;
        zeros when never touching.
    """

    touches: np.ndarray
    first_contact_fraction: np.ndarray
    contact_world: np.ndarray
    contact_rel_com: np.ndarray
    normal: np.ndarray
    action_from_contact: np.ndarray


def annotate(
    obj: PushObject | str,
    object_pose,
    pusher_xy,
    action,
    radius: float = PUSHER_RADIUS,
) -> ContactAnnotation:
    """Annotates pushes of a disc pusher against one object.

    Args:
      obj: the object, or its name (see :data:`pushjax.geometry.OBJECT_NAMES`).
      object_pose: [..., 3] pose (x m, y m, yaw rad) of the object's tracked frame in the world.
      pusher_xy: [..., 2] pusher centre at the start of the push, world, m.
      action: [..., 2] pusher displacement over the push, world, m.
      radius: pusher radius in m (>= 0).

    The leading axes of the three arrays broadcast against each other to the batch shape.

    Returns:
      The :class:`ContactAnnotation` with that batch shape.

    Raises:
      ValueError: naming the argument, for a wrong last axis, batch shapes that do not broadcast,
        non-finite values or a negative radius.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    pose = _as_float_array(object_pose, "object_pose", 3)
    pusher = _as_float_array(pusher_xy, "pusher_xy", 2)
    motion = _as_float_array(action, "action", 2)
    try:
        batch_shape = np.broadcast_shapes(pose.shape[:-1], pusher.shape[:-1], motion.shape[:-1])
    except ValueError:
        raise ValueError(
            "object_pose, pusher_xy, action: batch shapes do not broadcast: "
            f"{pose.shape[:-1]}, {pusher.shape[:-1]}, {motion.shape[:-1]}") from None
    radius = float(radius)
    if not (np.isfinite(radius) and radius >= 0):
        raise ValueError(f"radius: expected a finite value >= 0 in m, got {radius}")

    pose = np.broadcast_to(pose, batch_shape + (3,)).reshape(-1, 3)
    pusher = np.broadcast_to(pusher, batch_shape + (2,)).reshape(-1, 2)
    motion = np.broadcast_to(motion, batch_shape + (2,)).reshape(-1, 2)

    yaw = pose[:, 2]

    def to_local(v):
        return planar.rotate(v, -yaw)

    def to_world_axes(v):
        return planar.rotate(v, yaw)

    start_local = to_local(pusher - pose[:, :2])
    motion_local = to_local(motion)
    first_contact = _first_contact_ellipse if obj.is_ellipse else _first_contact_polygon
    touches = np.empty(len(pose), bool)
    fraction = np.empty(len(pose))
    contact_local = np.empty((len(pose), 2))
    normal_local = np.empty((len(pose), 2))
    for begin in range(0, len(pose), _CHUNK):
        chunk = slice(begin, begin + _CHUNK)
        touches[chunk], fraction[chunk], contact_local[chunk], normal_local[chunk] = first_contact(
            obj, start_local[chunk], motion_local[chunk], radius)

    mask = touches[:, None]
    fields = dict(
        touches=touches,
        first_contact_fraction=fraction,
        contact_world=np.where(mask, pose[:, :2] + to_world_axes(contact_local), 0.0),
        contact_rel_com=np.where(mask, to_world_axes(contact_local - obj.centroid), 0.0),
        normal=np.where(mask, to_world_axes(normal_local), 0.0),
        action_from_contact=np.where(mask, (1.0 - fraction[:, None]) * motion, 0.0),
    )
    return ContactAnnotation(**{
        name: value.reshape(batch_shape + value.shape[1:]) for name, value in fields.items()})


def _as_float_array(value, name: str, last: int) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}: expected a float array of shape [..., {last}] ({error})") from None
    if array.ndim == 0 or array.shape[-1] != last:
        raise ValueError(f"{name}: expected shape [..., {last}], got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name}: expected finite values, got NaN or inf")
    return array


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def _unit_or(vectors: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """Normalises [N, 2] vectors; rows of (near) zero length take ``fallback`` instead."""
    length = np.linalg.norm(vectors, axis=-1, keepdims=True)
    usable = length > 1e-15
    return np.where(usable, vectors / np.where(usable, length, 1.0), fallback)


# --------------------------------------------------------------------------------------------------
# Polygons


@functools.cache
def _polygon_features(obj: PushObject):
    """Edges of the outline: start vertices, edge vectors, unit outward normals, prepared polygon."""
    start = np.asarray(obj.outline, dtype=np.float64)
    edge = np.roll(start, -1, axis=0) - start
    keep = np.linalg.norm(edge, axis=-1) > 0  # a repeated vertex adds nothing but a NaN normal
    start = start[keep]
    if not shapely.LinearRing(start).is_ccw:  # the outward normals below need CCW order
        start = start[::-1]
    edge = np.roll(start, -1, axis=0) - start
    outward = np.stack([edge[:, 1], -edge[:, 0]], axis=-1) / np.linalg.norm(edge, axis=-1)[:, None]
    polygon = shapely.Polygon(start)
    shapely.prepare(polygon)
    return start, edge, outward, polygon


def _first_contact_polygon(obj: PushObject, p: np.ndarray, u: np.ndarray, r: float):
    """First contact for [N, 2] starts ``p`` and motions ``u`` in the object frame; see module doc."""
    start, edge, outward, polygon = _polygon_features(obj)
    n = len(p)
    reach = r + _DISTANCE_TOLERANCE
    edge_lo = np.minimum(start, start + edge) - reach
    edge_hi = np.maximum(start, start + edge) + reach
    path_lo, path_hi = np.minimum(p, p + u), np.maximum(p, p + u)
    # Each edge owns its offset segment and the circle about its start vertex; both lie in the edge's
    # box grown by r, so a path that misses that box can neither hit them nor start within r of it.
    candidate = ((path_lo[:, None, 0] <= edge_hi[None, :, 0]) & (path_hi[:, None, 0] >= edge_lo[None, :, 0])
                 & (path_lo[:, None, 1] <= edge_hi[None, :, 1]) & (path_hi[:, None, 1] >= edge_lo[None, :, 1]))
    query, feature = np.nonzero(candidate)
    pq, uq = p[query], u[query]
    a, e, out = start[feature], edge[feature], outward[feature]

    with np.errstate(divide="ignore", invalid="ignore"):
        # Closest point of each candidate edge to the start.
        along = np.clip(_dot(pq - a, e) / _dot(e, e), 0.0, 1.0)
        closest = a + along[:, None] * e
        start_distance = np.linalg.norm(pq - closest, axis=-1)
        # Path vs the edge offset outward by r: p + t u = a + r out + s e.
        offset_start = a + r * out - pq
        denominator = _cross(uq, e)
        t_edge = _cross(offset_start, e) / denominator
        s_edge = _cross(offset_start, uq) / denominator
        edge_hit = (denominator != 0) & (s_edge >= 0) & (s_edge <= 1)
        t_edge = np.where(edge_hit & (t_edge >= -_TIME_TOLERANCE), np.maximum(t_edge, 0.0), np.inf)
        # Path vs the circle of radius r about vertex a: first root of |p - a + t u|^2 = r^2, written
        # as c / (-b + sqrt(b^2 - a c)) to avoid cancellation.
        relative = pq - a
        half_b = _dot(uq, relative)
        c = _dot(relative, relative) - r * r
        discriminant = half_b * half_b - _dot(uq, uq) * c
        t_corner = c / (-half_b + np.sqrt(discriminant))
        corner_hit = (half_b < 0) & (discriminant >= 0)
        t_corner = np.where(corner_hit & (t_corner >= -_TIME_TOLERANCE), np.maximum(t_corner, 0.0), np.inf)

    hit_edge_side = t_edge <= t_corner
    t_feature = np.minimum(t_edge, t_corner)
    feature_contact = np.where(hit_edge_side[:, None], a + np.clip(s_edge, 0, 1)[:, None] * e, a)
    # Inward normal at first contact: along the pusher-to-contact direction, exactly -out on an edge.
    centre_at_hit = pq + np.where(np.isfinite(t_feature), t_feature, 0.0)[:, None] * uq
    feature_normal = np.where(hit_edge_side[:, None], -out,
                              _unit_or(feature_contact - centre_at_hit, -out))

    inside = shapely.contains_xy(polygon, p[:, 0], p[:, 1])
    nearest_distance, nearest = _select_min(n, query, start_distance, closest, out)
    nearest_point, nearest_edge_normal = nearest
    # An edge within reach of the start is always a candidate; starts inside the footprint with no
    # edge that close still need the closest boundary point: search all edges.
    deep = inside & (nearest_distance > reach)
    if np.any(deep):
        nearest_distance[deep], nearest_point[deep], nearest_edge_normal[deep] = _closest_on_outline(
            start, edge, outward, p[deep])
    touching_at_start = inside | (nearest_distance <= reach)
    towards = np.where(inside[:, None], p - nearest_point, nearest_point - p)
    start_normal = _unit_or(towards, -nearest_edge_normal)

    first_t, (first_contact, first_normal) = _select_min(n, query, t_feature, feature_contact, feature_normal)
    touches = touching_at_start | (first_t <= 1.0)
    fraction = np.where(touching_at_start, 0.0, np.where(touches, first_t, NO_CONTACT_FRACTION))
    contact = np.where(touching_at_start[:, None], nearest_point, first_contact)
    normal = np.where(touching_at_start[:, None], start_normal, first_normal)
    return touches, fraction, np.where(touches[:, None], contact, 0.0), np.where(touches[:, None], normal, 0.0)


def _select_min(n: int, query: np.ndarray, key: np.ndarray, *values: np.ndarray):
    """Per query, the smallest ``key`` over its rows and the ``values`` rows attaining it.

    ``query`` is sorted (row-major ``np.nonzero``). Queries without rows get ``inf`` and zeros.
    """
    best = np.full(n, np.inf)
    chosen = [np.zeros((n,) + v.shape[1:]) for v in values]
    if len(query) == 0:
        return best, chosen
    starts = np.flatnonzero(np.r_[True, query[1:] != query[:-1]])
    owners = query[starts]
    best[owners] = np.minimum.reduceat(key, starts)
    winners = np.flatnonzero(key == best[query])
    # Among ties keep the first row of each query.
    winners = winners[np.r_[True, query[winners][1:] != query[winners][:-1]]]
    for target, v in zip(chosen, values):
        target[query[winners]] = v[winners]
    return best, chosen


def _closest_on_outline(start, edge, outward, points):
    """Distance [M], closest outline point [M, 2] and that edge's outward normal [M, 2]."""
    along = np.clip(_dot(points[:, None] - start, edge) / _dot(edge, edge), 0.0, 1.0)
    closest = start + along[..., None] * edge
    distance = np.linalg.norm(points[:, None] - closest, axis=-1)
    index = np.argmin(distance, axis=1)
    rows = np.arange(len(points))
    return distance[rows, index], closest[rows, index], outward[index]


# --------------------------------------------------------------------------------------------------
# Ellipses


def _first_contact_ellipse(obj: PushObject, p: np.ndarray, u: np.ndarray, r: float):
    """First contact for [N, 2] starts ``p`` and motions ``u`` in the object frame; see module doc."""
    a, b = obj.semi_axes
    inside = (p[:, 0] / a) ** 2 + (p[:, 1] / b) ** 2 <= 1.0
    nearest_point = _closest_on_ellipse(p, a, b)
    gradient = nearest_point / np.array([a * a, b * b])
    # Inward normal at the closest point; the pusher-to-point direction agrees with it unless the
    # centre sits on the boundary.
    towards = np.where(inside[:, None], p - nearest_point, nearest_point - p)
    start_normal = _unit_or(towards, -_unit_or(gradient, np.array([1.0, 0.0])))
    touching_at_start = inside | (np.linalg.norm(p - nearest_point, axis=-1) <= r + _DISTANCE_TOLERANCE)

    def offset_curve(theta):
        cos, sin = np.cos(theta), np.sin(theta)
        boundary = np.stack([a * cos, b * sin], axis=-1)
        outward = np.stack([b * cos, a * sin], axis=-1)
        outward /= np.linalg.norm(outward, axis=-1, keepdims=True)
        return boundary, outward, boundary + r * outward

    # The outward normal (b cos, a sin) is perpendicular to u at phi +- pi/2; between them, on the
    # arc facing the motion, cross(u, offset point - p) is monotone in theta.
    phi = np.arctan2(a * u[:, 1], b * u[:, 0])
    low, high = phi + 0.5 * np.pi, phi + 1.5 * np.pi
    sign_low = np.sign(_cross(u, offset_curve(low)[2] - p))
    sign_high = np.sign(_cross(u, offset_curve(high)[2] - p))
    moving = _dot(u, u) > 0
    crosses = moving & (sign_low * sign_high <= 0)
    for _ in range(_BISECTION_STEPS):
        middle = 0.5 * (low + high)
        same_as_low = np.sign(_cross(u, offset_curve(middle)[2] - p)) == sign_low
        low = np.where(same_as_low, middle, low)
        high = np.where(same_as_low, high, middle)
    theta = 0.5 * (low + high)
    boundary, outward, centre = offset_curve(theta)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_entry = _dot(u, centre - p) / _dot(u, u)
    hits = crosses & (t_entry >= -_TIME_TOLERANCE) & (t_entry <= 1.0)

    touches = touching_at_start | hits
    fraction = np.where(touching_at_start, 0.0, np.where(hits, np.clip(t_entry, 0.0, 1.0), NO_CONTACT_FRACTION))
    contact = np.where(touching_at_start[:, None], nearest_point, boundary)
    normal = np.where(touching_at_start[:, None], start_normal, -outward)
    return touches, fraction, np.where(touches[:, None], contact, 0.0), np.where(touches[:, None], normal, 0.0)


def _closest_on_ellipse(points: np.ndarray, a: float, b: float) -> np.ndarray:
    """[N, 2] closest points on the ellipse x^2/a^2 + y^2/b^2 = 1 to [N, 2] points (inside or out).

    Eberly, "Distance from a point to an ellipse, an ellipsoid, or a hyperellipsoid" (2013): in the
    first quadrant with the major axis e0 along x, the closest point is
    (r x0 / (sigma - 1 + r), y0 / sigma) with r = (e0 / e1)^2 and sigma > 0 the root of
    (r x0 / e0 / (sigma - 1 + r))^2 + (y0 / e1 / sigma)^2 = 1, which decreases in sigma. Bisecting
    at geometric means fixes sigma to full relative precision, which keeps y accurate for points
    just off the major axis, where sigma is tiny.
    """
    swap = b > a
    e0, e1 = (b, a) if swap else (a, b)
    local = points[:, ::-1] if swap else points
    x0, y0 = np.abs(local[:, 0]), np.abs(local[:, 1])
    ratio = (e0 / e1) ** 2
    scaled_z0, z1 = ratio * x0 / e0, y0 / e1
    on_axis = y0 == 0.0
    outside = (x0 / e0) ** 2 + z1 * z1 > 1.0
    low = np.where(on_axis, 1.0, z1)  # the on-axis placeholders are replaced below
    high = np.where(outside, np.hypot(scaled_z0, z1), 1.0)
    for _ in range(_BISECTION_STEPS):
        sigma = np.sqrt(low) * np.sqrt(high)
        positive = (scaled_z0 / (sigma + (ratio - 1.0))) ** 2 + (z1 / sigma) ** 2 > 1.0
        low = np.where(positive, sigma, low)
        high = np.where(positive, high, sigma)
    sigma = np.sqrt(low) * np.sqrt(high)
    x = ratio * x0 / (sigma + (ratio - 1.0))
    y = y0 / sigma
    # On the major axis the root is sigma = 0 for points inside the evolute's cusp; solve directly.
    cusp = e0 - e1 * e1 / e0
    x_axis = np.where(x0 < cusp, e0 * np.minimum(x0, cusp) / np.where(cusp > 0, cusp, 1.0), e0)
    y_axis = e1 * np.sqrt(np.maximum(0.0, 1.0 - (x_axis / e0) ** 2))
    x = np.where(on_axis, x_axis, x)
    y = np.where(on_axis, y_axis, y)
    closest = np.stack([np.copysign(x, local[:, 0]), np.copysign(y, local[:, 1])], axis=-1)
    return closest[:, ::-1] if swap else closest
