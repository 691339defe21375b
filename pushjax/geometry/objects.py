"""The 11 objects of the MIT Push Dataset (Yu et al., IROS 2016), defined from their dimensions.

Every object is a 12.7 mm thick stainless-steel plate. Coordinates are in metres in the object's
*tracked frame*: the origin of the dataset's mesh, i.e. the frame whose pose the motion-capture
system records. For rect*, ellip*, hex and butter that frame sits at the centroid; for the right
triangles tri1-3 it does not (the right-angle corner is at (+45, +45) mm and the centroid is a few
millimetres off the origin), so a model that takes the tracked frame for the centre of mass is
wrong for triangles.

The dimensions come from the dataset's annotation scripts and meshes. Butter's non-convex outline is
package data (``data/butter_outline.csv``): the mid-height section of the dataset's ``butter.obj``
(its four 2 mm marker holes left out). The outline published beside the dataset
(``butter_outline.csv`` in the reference data) deviates from that mesh by up to 1 mm (it is not
mirror-symmetric; footprint IoU 0.985); the mesh is what the tracked object looks like, so pushjax
follows the mesh: area 116.7 cm^2 and uniform-pressure l = 46.3 mm, within 0.8 % of the published
outline's figures.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.resources
from typing import Callable

import numpy as np
import scipy.optimize
import shapely
import trimesh

THICKNESS = 0.0127
"""Plate thickness in m."""
STAINLESS_STEEL_DENSITY = 7930.0
"""kg/m^3 (AISI 304)."""
PUSHER_RADIUS = 0.00476
"""Radius of the MIT pusher tip in m."""
ELLIPSE_OUTLINE_POINTS = 256

OBJECT_NAMES = (
    "rect1", "rect2", "rect3", "ellip1", "ellip2", "ellip3",
    "tri1", "tri2", "tri3", "hex", "butter",
)


@dataclasses.dataclass(frozen=True, eq=False)
class PushObject:
    """One push object: a flat plate with a 2-D outline in its tracked frame.

    Attributes:
      name: dataset name, e.g. ``"rect1"``.
      outline: [V, 2] counter-clockwise outline in m (tracked frame); ellipses are sampled.
      sides: tuple of [P_i, 2] polylines in m that partition the boundary into the dataset's push
        sides (polygon edges; quarter arcs for the ellipses and butter), each running
        counter-clockwise, so side index ``i`` and point ``s`` in [0, 1] name a boundary point.
      semi_axes: (a, b) in m for ellipses (axes along x and y), else None.
      thickness: plate thickness in m.
      density: kg/m^3.
    """

    name: str
    outline: np.ndarray
    sides: tuple[np.ndarray, ...]
    semi_axes: tuple[float, float] | None = None
    thickness: float = THICKNESS
    density: float = STAINLESS_STEEL_DENSITY

    @property
    def is_ellipse(self) -> bool:
        return self.semi_axes is not None

    @functools.cached_property
    def polygon(self) -> shapely.Polygon:
        return shapely.Polygon(self.outline)

    @property
    def area(self) -> float:
        """Footprint area in m^2 (exact for ellipses)."""
        if self.is_ellipse:
            return float(np.pi * self.semi_axes[0] * self.semi_axes[1])
        return float(self.polygon.area)

    @property
    def centroid(self) -> np.ndarray:
        """[2] centre of mass (uniform density) in the tracked frame, m."""
        if self.is_ellipse:
            return np.zeros(2)
        c = self.polygon.centroid
        return np.array([c.x, c.y])

    @property
    def mass(self) -> float:
        """kg."""
        return self.area * self.thickness * self.density

    @functools.cached_property
    def inertia(self) -> np.ndarray:
        """[3] principal-axis-aligned diagonal of the inertia tensor about the centroid, kg m^2.

        The plate's x/y axes are not principal for the triangles; MuJoCo needs the full tensor
        there, so use :attr:`inertia_tensor` when building models.
        """
        return np.diag(self.inertia_tensor)

    @functools.cached_property
    def inertia_tensor(self) -> np.ndarray:
        """[3, 3] inertia tensor about the centroid in the tracked frame's axes, kg m^2."""
        mesh = self.mesh.copy()
        mesh.density = self.density
        return np.asarray(mesh.moment_inertia)

    @functools.cached_property
    def mesh(self) -> trimesh.Trimesh:
        """Watertight plate mesh in the tracked frame, z from -thickness/2 to +thickness/2 (m)."""
        mesh = trimesh.creation.extrude_polygon(self.polygon, self.thickness)
        mesh.apply_translation([0.0, 0.0, -self.thickness / 2])
        return mesh

    def side_point(self, side: int, point: float) -> tuple[np.ndarray, np.ndarray]:
        """Boundary point and inward unit normal of push side ``side`` at fraction ``point``.

        Args:
          side: index into :attr:`sides`.
          point: position along the side in [0, 1] (by arc length, counter-clockwise).

        Returns:
          ([2] point in m, [2] unit normal pointing into the object), tracked frame.
        """
        if not 0 <= side < len(self.sides):
            raise ValueError(f"side: {self.name} has sides 0..{len(self.sides) - 1}, got {side}")
        if not 0.0 <= point <= 1.0:
            raise ValueError(f"point: expected a fraction in [0, 1], got {point}")
        polyline = self.sides[side]
        segments = np.diff(polyline, axis=0)
        lengths = np.linalg.norm(segments, axis=1)
        cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
        target = point * cumulative[-1]
        k = int(np.clip(np.searchsorted(cumulative, target, side="right") - 1, 0, len(segments) - 1))
        fraction = (target - cumulative[k]) / lengths[k]
        position = polyline[k] + fraction * segments[k]
        tangent = segments[k] / lengths[k]
        inward = np.array([-tangent[1], tangent[0]])  # left of a counter-clockwise boundary
        return position, inward


def limit_surface_ratio(
    obj: PushObject,
    pressure: Callable[[np.ndarray], np.ndarray] | None = None,
    support_points: np.ndarray | None = None,
    support_weights: np.ndarray | None = None,
    resolution: int = 400,
) -> float:
    """Ratio l = m_max / f_max of the ellipsoidal limit surface, in m.

    With a support pressure p(r) and the centre of pressure r_p, f_max = mu_s * sum(p) and
    m_max = mu_s * sum(p |r - r_p|), so l = sum(p |r - r_p|) / sum(p), independent of mu_s.

    Args:
      obj: the object.
      pressure: optional function mapping [N, 2] footprint points (m, tracked frame) to [N]
        non-negative pressure weights; uniform when omitted.
      support_points: optional [K, 2] discrete support points (m) instead of a distributed
        pressure, e.g. a plate resting on a few bumps. Mutually exclusive with ``pressure``.
      support_weights: optional [K] non-negative weights of the support points (default equal).
      resolution: grid cells along the longer footprint side for the distributed case.

    Returns:
      l in m.
    """
    if pressure is not None and support_points is not None:
        raise ValueError("pressure and support_points: give at most one of them")
    if support_points is not None:
        points = np.asarray(support_points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
            raise ValueError(f"support_points: expected shape [K, 2] with K >= 1, got {points.shape}")
        weights = (np.ones(len(points)) if support_weights is None
                   else np.asarray(support_weights, dtype=np.float64))
        if weights.shape != (len(points),):
            raise ValueError(f"support_weights: expected shape [{len(points)}], got {weights.shape}")
    else:
        if support_weights is not None:
            raise ValueError("support_weights: only meaningful together with support_points")
        points = footprint_grid(obj, resolution)
        weights = np.ones(len(points)) if pressure is None else np.asarray(pressure(points), np.float64)
        if weights.shape != (len(points),):
            raise ValueError(f"pressure: expected it to return shape [{len(points)}], got {weights.shape}")
    if not np.all(np.isfinite(weights)) or np.any(weights < 0) or weights.sum() <= 0:
        raise ValueError("pressure weights: expected finite, non-negative values with a positive sum")
    centre = weights @ points / weights.sum()
    return float(weights @ np.linalg.norm(points - centre, axis=1) / weights.sum())


def footprint_grid(obj: PushObject, resolution: int) -> np.ndarray:
    """[N, 2] centres of a regular grid's cells that lie inside the footprint, m."""
    if resolution < 2:
        raise ValueError(f"resolution: expected >= 2, got {resolution}")
    lo, hi = obj.outline.min(axis=0), obj.outline.max(axis=0)
    cell = (hi - lo).max() / resolution
    xs = np.arange(lo[0] + cell / 2, hi[0], cell)
    ys = np.arange(lo[1] + cell / 2, hi[1], cell)
    grid = np.stack(np.meshgrid(xs, ys, indexing="xy"), axis=-1).reshape(-1, 2)
    if obj.is_ellipse:
        a, b = obj.semi_axes
        inside = (grid[:, 0] / a) ** 2 + (grid[:, 1] / b) ** 2 <= 1.0
    else:
        inside = shapely.contains_xy(obj.polygon, grid[:, 0], grid[:, 1])
    return grid[inside]


SUPPORT_RESOLUTION = 6
"""Cells along the longer footprint side in :func:`support_cells` (20 to 36 cells for the MIT objects: the exact limit
surface's cost grows with the cells, and with their patches the torque intercept is within 2.5 % of ``l``)."""
PATCH_RADIUS_OVER_CELL = 0.3826
"""Mean distance of a square cell's points from its centre over the cell's side: a support point with a patch of
this radius (times the side) dissipates what the cell does when the object turns about the point."""


def support_cells(obj: PushObject, resolution: int = SUPPORT_RESOLUTION,
                  subsamples: int = 8) -> tuple[np.ndarray, np.ndarray, float]:
    """The footprint as support cells for the exact limit surface (:mod:`pushjax.physics.limit_surface`).

    Args:
      obj: the object.
      resolution: cells along the longer side of the footprint's bounding box.
      subsamples: points per cell side with which the part of a cell inside the footprint is measured.

    Returns:
      (points [K, 2] centroids of the cells' parts inside the footprint, relative to their area centroid (the
      uniform plate's centre of mass), object axes, m; weights [K] those parts' areas over the footprint's (summing to about 1); the patch
      radius, m, :data:`PATCH_RADIUS_OVER_CELL` times the cell side).
    """
    if resolution < 2 or subsamples < 1:
        raise ValueError(f"resolution, subsamples: expected >= 2 and >= 1, got {resolution}, {subsamples}")
    fine = footprint_grid(obj, resolution * subsamples)
    lo = obj.outline.min(axis=0)
    cell = (obj.outline.max(axis=0) - lo).max() / resolution
    index = np.floor((fine - lo) / cell).astype(int)
    keys, inverse = np.unique(index[:, 0] * (resolution + 1) + index[:, 1], return_inverse=True)
    counts = np.bincount(inverse, minlength=len(keys)).astype(np.float64)
    centroids = np.stack([np.bincount(inverse, fine[:, axis], len(keys)) for axis in (0, 1)], axis=1) / counts[:, None]
    weights = counts / counts.sum()
    # Centred on their own area centroid, which the sampling puts up to a few tenths of a cell off the plate's: a
    # uniform pressure then has its centre exactly at the centre of mass, as in Lynch's model.
    return centroids - weights @ centroids, weights, PATCH_RADIUS_OVER_CELL * cell


FEET_SIMPLIFY = 0.05
"""Tolerance of the convex hull's simplification in :func:`support_feet`, as a share of the footprint's longer side:
a polygon keeps its corners, a curved outline becomes a ring of about a dozen."""
_LOAD_BALANCE = 1e4
"""Weight of the load-centre rows in :func:`support_feet`'s non-negative least squares (balance to about 1e-8 m)."""


def support_feet(obj: PushObject) -> tuple[np.ndarray, np.ndarray]:
    """The corners of the footprint's convex hull as point supports, loaded so the object balances on them.

    The support of a plate whose base is not flat concentrates on the outermost points it can rest on: the corners
    of its footprint's convex hull, the extreme distributions that bound every pressure within the footprint
    (Peshkin and Sanderson 1988). The loads are those closest to equal shares that put their centre under the
    centre of mass (static balance), found by non-negative least squares.

    Args:
      obj: the object.

    Returns:
      (points [F, 2] the hull's corners relative to the footprint's area centroid (the uniform plate's centre of
      mass, as :func:`support_cells`), object axes, m; loads [F] >= 0 summing to 1 whose centre is that centroid).
    """
    outline = np.asarray(obj.outline, np.float64)
    extent = float((outline.max(axis=0) - outline.min(axis=0)).max())
    hull = shapely.Polygon(outline).convex_hull.simplify(FEET_SIMPLIFY * extent)
    points = np.asarray(hull.exterior.coords)[:-1] - obj.centroid
    equal = np.full(len(points), 1.0 / len(points))
    balance = np.vstack([np.ones(len(points)), points.T / extent])
    loads, _ = scipy.optimize.nnls(np.vstack([np.eye(len(points)), _LOAD_BALANCE * balance]),
                                   np.concatenate([equal, _LOAD_BALANCE * np.array([1.0, 0.0, 0.0])]))
    return points, loads / loads.sum()


def support(obj: PushObject) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The support the exact limit surface (``limit_surface``) needs: the footprint's cells and its hull's corners.

    Returns:
      (points [K, 2] the cells of :func:`support_cells` then the corners of :func:`support_feet`, relative to the
      uniform plate's centre of mass, object axes, m; area weights [K] (zero for the corners); corner loads [K]
      (zero for the cells); the cells' patch radius, m).
    """
    cells, areas, patch_radius = support_cells(obj)
    corners, loads = support_feet(obj)
    return (np.concatenate([cells, corners]), np.concatenate([areas, np.zeros(len(corners))]),
            np.concatenate([np.zeros(len(cells)), loads]), patch_radius)


def _polygon_object(name: str, vertices) -> PushObject:
    vertices = np.asarray(vertices, dtype=np.float64)
    if shapely.Polygon(vertices).exterior.is_ccw is False:
        vertices = vertices[::-1]
    sides = tuple(np.stack([vertices[k], vertices[(k + 1) % len(vertices)]]) for k in range(len(vertices)))
    return PushObject(name=name, outline=vertices, sides=sides)


def _rectangle(name: str, half_x: float, half_y: float) -> PushObject:
    return _polygon_object(name, [[half_x, -half_y], [half_x, half_y], [-half_x, half_y], [-half_x, -half_y]])


def _quarter_sides(outline: np.ndarray) -> tuple[np.ndarray, ...]:
    """Split a closed counter-clockwise outline into four arcs starting at its +x, +y, -x, -y extremes."""
    starts = [int(np.argmax(outline[:, 0])), int(np.argmax(outline[:, 1])),
              int(np.argmin(outline[:, 0])), int(np.argmin(outline[:, 1]))]
    n = len(outline)
    sides = []
    for k in range(4):
        begin, end = starts[k], starts[(k + 1) % 4]
        indices = np.arange(begin, begin + (end - begin) % n + 1) % n
        sides.append(outline[indices])
    return tuple(sides)


def _ellipse(name: str, a: float, b: float) -> PushObject:
    angles = np.linspace(0.0, 2 * np.pi, ELLIPSE_OUTLINE_POINTS, endpoint=False)
    outline = np.stack([a * np.cos(angles), b * np.sin(angles)], axis=-1)
    return PushObject(name=name, outline=outline, sides=_quarter_sides(outline), semi_axes=(a, b))


def _hexagon(name: str, circumradius: float) -> PushObject:
    angles = np.arange(6) * np.pi / 3
    return _polygon_object(name, circumradius * np.stack([np.cos(angles), np.sin(angles)], axis=-1))


def _butter() -> PushObject:
    text = importlib.resources.files("pushjax.geometry").joinpath("data/butter_outline.csv").read_text()
    outline = np.loadtxt(text.splitlines(), delimiter=",", skiprows=1)
    if np.array_equal(outline[0], outline[-1]):  # the file closes the ring; outlines do not
        outline = outline[:-1]
    if not shapely.Polygon(outline).exterior.is_ccw:
        outline = outline[::-1]
    return PushObject(name="butter", outline=outline, sides=_quarter_sides(outline))


@functools.cache
def get_object(name: str) -> PushObject:
    """The MIT push object called ``name`` (one of :data:`OBJECT_NAMES`)."""
    builders = {
        "rect1": lambda: _rectangle("rect1", 0.045, 0.045),
        "rect2": lambda: _rectangle("rect2", 0.045, 0.05625),
        "rect3": lambda: _rectangle("rect3", 0.0675, 0.045),
        "ellip1": lambda: _ellipse("ellip1", 0.0525, 0.0525),
        "ellip2": lambda: _ellipse("ellip2", 0.0525, 0.065445),
        "ellip3": lambda: _ellipse("ellip3", 0.0525, 0.0785),
        "tri1": lambda: _polygon_object("tri1", [[0.045, 0.045], [-0.0809, 0.045], [0.045, -0.08087]]),
        "tri2": lambda: _polygon_object("tri2", [[0.045, 0.045], [-0.106, 0.045], [0.045, -0.08087]]),
        "tri3": lambda: _polygon_object("tri3", [[0.045, 0.045], [-0.1315, 0.045], [0.045, -0.08061]]),
        "hex": lambda: _hexagon("hex", 0.0605),
        "butter": _butter,
    }
    if name not in builders:
        raise ValueError(f"object name: expected one of {', '.join(OBJECT_NAMES)}, got {name!r}")
    return builders[name]()


def all_objects() -> tuple[PushObject, ...]:
    return tuple(get_object(name) for name in OBJECT_NAMES)
