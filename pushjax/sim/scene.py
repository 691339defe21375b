"""MuJoCo scenes of the MIT Push Dataset set-up: a steel plate on a table, pushed by a vertical cylinder.

Naming convention (shared with :mod:`pushjax.render.renderer`): geom ``table`` (a plane, top surface at z = 0,
one procedural material per surface); body ``object`` with the free joint ``object_joint``, whose body frame IS
the object's tracked frame (origin on the mid-plane of the plate, z up); mocap body ``pusher`` holding a
vertical cylinder of radius 4.76 mm; fixed world camera ``camera``.

Bodies:

* ``object``: the plate's mass and full 3×3 inertia tensor from its geometry (12.7 mm stainless steel), centre
  of mass at the footprint centroid in the tracked frame (plus ``Effects.com_offset``).
* ``pusher_carriage`` → ``pusher_tip``: the simulated pusher. MuJoCo treats mocap bodies as fixed (their
  contacts see no velocity and lag behind), so the pusher that touches the plate is a 20 kg carriage on two
  horizontal slide joints, driven by a stiff PD servo (1e6 N/m, critically damped) with velocity feed-forward,
  carrying a 50 g capsule tip (radius 4.76 mm) on a soft vertical spring (100 N/m). The spring lets the tip
  follow the plate's micrometre vertical motion, so pusher–object friction acts in the table plane (a rigid
  tip can lock an arbitrary vertical friction force against the plate, a static indeterminacy that the
  soft-contact solver would resolve by the contact's history, eating into the horizontal friction cone).
  The mocap body ``pusher`` only mirrors the commanded position for rendering; its geom never collides.

Geometry and contacts:

* Walls (what the pusher touches): exact prisms over the outline. MuJoCo collides meshes through their convex
  hulls, so a non-convex outline (butter) is simplified by 0.01 mm (digitisation wiggles) and cut into convex
  pieces (constrained Delaunay triangulation merged back into convex polygons, Hertel & Mehlhorn 1983);
  ellipses use the 256-gon of the outline (sagitta < 0.02 mm). Walls collide only with the pusher tip.
* Supports (what touches the table): ``support="grid"`` places 24 points at the centroids of a centroidal
  Voronoi tessellation of the footprint (Lloyd's algorithm), each standing for the area of its cell, so that
  the limit-surface ratio of the discrete supports is within ~2 % of the uniform-pressure value (the distributed
  pressure of a flat plate); ``support="hull"`` places one support 1 mm inside each corner of the outline's
  convex hull (simplified to 0.5 mm for curved outlines), as for a plate on stiff feet; ``support="ring"`` places 16
  supports 1 mm inside the outline at equal spacing along it, as for a plate with a dished base resting on its
  edge. Each support is a
  tiny capsule with its axis along the object's x axis, raised by 10° so that only its lower end touches the
  table: MuJoCo's plane–capsule contact takes the capsule axis as the first tangent of the contact frame, which
  ties the friction ellipse of anisotropic contacts to the OBJECT frame (checked in tests/sim).
* All contacts are explicit contact pairs (every geom has ``contype = conaffinity = 0``): table–support
  pairs carry the per-support coefficients ``(mu_x_i, mu_y_i)`` (surface coefficient × area weight × pressure
  weight × anisotropy), tip–wall pairs the isotropic pusher–object coefficient. ``condim`` 3: torsional
  friction of the plate arises from the distributed supports, as in the limit-surface model.

Solver settings and why (see ``tests/sim`` for the resulting behaviour):

* Time step 2 ms for pushes up to 50 mm/s and shorter for faster ones (``pushjax.sim.push`` keeps the pusher's
  advance per step below 0.1 mm; the 4 ms recording period is always a whole number of steps), with the
  ``implicitfast`` integrator, which integrates the servo's velocity gain implicitly.
* ``cone="elliptic"``: isotropic Coulomb friction in the tangent plane (pyramids depend on the world axes) and
  the per-axis coefficients of anisotropic friction. ``impratio`` 100 makes the friction dimensions stiff
  relative to the normal one, suppressing the slow creep of MuJoCo's soft friction: a plate at rest stays at
  rest (< 1 µm in 2 s) and a plate loaded with 90 % of its friction limit creeps ~10 µm in 2 s.
* ``solref = (4 ms, 1)`` on every contact (critically damped, 2 × the largest step). Support ``solimp`` starts
  at d0 = 0.1: a sliding contact under MuJoCo's soft elliptic cone pushes the plate up in proportion to the
  sliding speed, and with stiffer impedances the plate lifts off, drops and bounces every few steps (micrometres,
  but the friction drops out each time); d0 = 0.1 keeps sliding smooth up to ~50 mm/s at the price of a 0.2 mm
  rest penetration (a soft table, invisible in the recorded planar poses; ``pushjax.render.renderer`` places the
  plate on the table itself). Faster pushes still rock the plate slightly. Pusher contacts use d0 = 0.5.
* ``noslip_iterations`` 0 (NoSlip does not act on sliding contacts, and the creep is small without it) and the
  CG solver, which converges here to the same forces as Newton at about 60 % of the cost.

With these contacts Coulomb friction is rate independent, so slow pushes (10–20 mm/s, kinetic energy ~1e-4 J
against ~1 N of friction) are quasi-static — the plate stops within 0.5 mm when the pusher stops and follows
the quasi-static model (``pushjax.sim.quasi_static``) to ~5–10 % — while fast pushes (150–500 mm/s) slide on for
centimetres.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

import mujoco
import numpy as np
import shapely

from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, footprint_grid, get_object
from pushjax.sim.effects import Effects
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION, Surface, get_surface

TIMESTEP = 2e-3
"""Default simulation step in s (the step of slow pushes; ``pushjax.sim.push`` sets it per push)."""
SUPPORT_MODES = ("grid", "hull", "ring")
GRID_SUPPORTS = 24
"""Number of support points in ``support="grid"`` mode."""
SUPPORT_RADIUS = 1e-4
"""Radius of a support capsule in m."""
SUPPORT_HALF_LENGTH = 1e-3
"""Half length of a support capsule's axis in m."""
SUPPORT_RAISE_DEG = 10.0
"""Angle between a support capsule's axis and the plate's bottom face, so only its lower end touches."""
HULL_INSET = 1e-3
"""Distance in m by which ``support="hull"`` and ``"ring"`` points are moved from the outline towards the centroid."""
RING_SUPPORTS = 16
"""Number of support points in ``support="ring"`` mode."""
PUSHER_HALF_HEIGHT = 0.05
"""Half height of the pusher cylinder in m (a 10 cm probe)."""
PUSHER_MASS = 20.0
"""Mass of the simulated pusher carriage in kg (heavy, like the robot arm behind it)."""
PUSHER_KP = 1e6
"""Position gain of the carriage's servo in N/m."""
PUSHER_KV = 2 * (PUSHER_KP * PUSHER_MASS) ** 0.5
"""Velocity gain of the carriage's servo in N s/m (critical damping)."""
TIP_MASS = 0.05
"""Mass of the pusher tip that hangs on the vertical spring, kg."""
TIP_STIFFNESS = 100.0
"""Vertical spring of the pusher tip, N/m."""
TIP_DAMPING = 2 * (TIP_STIFFNESS * TIP_MASS) ** 0.5
"""Vertical damping of the pusher tip, N s/m (critical)."""
PUSHER_CLEARANCE = 1e-3
"""Gap between the table and the bottom of the pusher in m (as ``pushjax.render.renderer`` places it)."""
CONTACT_SOLREF = (0.004, 1.0)
"""(time constant s, damping ratio) of every contact."""
SUPPORT_SOLIMP = (0.1, 0.95, 0.001, 0.5, 2.0)
"""Impedance (d0, dwidth, width m, midpoint, power) of the support contacts."""
PUSHER_SOLIMP = (0.5, 0.95, 0.001, 0.5, 2.0)
"""Impedance of the pusher–object contacts."""
IMPRATIO = 100.0
"""Ratio of frictional to normal constraint impedance (elliptic cones)."""
TORSIONAL_FRICTION = 0.0
"""Torsional coefficient (m) of the point contacts: spin friction comes from the distributed supports."""
TABLE_HALF_SIZE = 0.3048
"""Half width of the visible table in m (the MIT surfaces are 24 inch squares); the plane is infinite."""
OUTLINE_TOLERANCE = 1e-5
"""Simplification tolerance (m) applied to a non-convex outline before cutting it into convex pieces."""
CONVEX_TOLERANCE = 1e-12
"""Cross product (m^2) below which three outline vertices count as collinear when testing convexity."""

_CONTACT_DATA = sum(1 << int(field) for field in (mujoco.mjtConDataField.mjCONDATA_FORCE,
                                                   mujoco.mjtConDataField.mjCONDATA_TORQUE,
                                                   mujoco.mjtConDataField.mjCONDATA_POS))
"""What the pusher's contact sensor reads (MJCF ``data="force torque pos"``)."""
_CONTACT_NETFORCE = 3
"""The contact sensor's ``reduce="netforce"`` (MJCF's order: none, mindist, maxforce, netforce)."""

_CVT_FINE_RESOLUTION = 80
_CVT_ITERATIONS = 40


def support_points(obj: PushObject | str, support: str = "grid") -> tuple[np.ndarray, np.ndarray]:
    """Support points of an object and the share of the footprint each one carries.

    Args:
      obj: the object or its name.
      support: ``"grid"`` (distributed over the footprint), ``"hull"`` (convex-hull corners) or ``"ring"`` (along
        the outline).

    Returns:
      ([K, 2] points in m in the tracked frame, [K] weights with mean 1: the cell areas relative to the
      mean cell area for ``"grid"``, ones for ``"hull"`` and ``"ring"``).
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    if support not in SUPPORT_MODES:
        raise ValueError(f"support: expected one of {', '.join(SUPPORT_MODES)}, got {support!r}")
    points, weights = {"grid": _grid_supports, "hull": _hull_supports, "ring": _ring_supports}[support](obj)
    return points.copy(), weights.copy()


@functools.cache
def _grid_supports(obj: PushObject) -> tuple[np.ndarray, np.ndarray]:
    """Centroidal Voronoi tessellation of the footprint by Lloyd's algorithm, deterministic start."""
    fine = footprint_grid(obj, _CVT_FINE_RESOLUTION)
    count = GRID_SUPPORTS
    # Farthest-point start from the sample nearest the centroid.
    chosen = [int(np.argmin(np.sum((fine - fine.mean(axis=0)) ** 2, axis=1)))]
    distance = np.sum((fine - fine[chosen[0]]) ** 2, axis=1)
    for _ in range(count - 1):
        chosen.append(int(np.argmax(distance)))
        distance = np.minimum(distance, np.sum((fine - fine[chosen[-1]]) ** 2, axis=1))
    points = fine[chosen]
    for _ in range(_CVT_ITERATIONS):
        label = np.argmin(np.sum((fine[:, None] - points[None]) ** 2, axis=-1), axis=1)
        counts = np.bincount(label, minlength=count)
        points = np.stack([np.bincount(label, fine[:, k], minlength=count) / counts for k in range(2)], axis=-1)
    label = np.argmin(np.sum((fine[:, None] - points[None]) ** 2, axis=-1), axis=1)
    counts = np.bincount(label, minlength=count).astype(np.float64)
    return points, counts / counts.mean()


@functools.cache
def _hull_supports(obj: PushObject) -> tuple[np.ndarray, np.ndarray]:
    hull = shapely.Polygon(obj.outline).convex_hull.simplify(5e-4)
    corners = np.asarray(hull.exterior.coords)[:-1]
    return _inset(corners, obj.centroid), np.ones(len(corners))


@functools.cache
def _ring_supports(obj: PushObject) -> tuple[np.ndarray, np.ndarray]:
    outline = shapely.Polygon(obj.outline).exterior
    points = np.array([outline.interpolate(k / RING_SUPPORTS, normalized=True).coords[0]
                       for k in range(RING_SUPPORTS)])
    return _inset(points, obj.centroid), np.ones(RING_SUPPORTS)


def _inset(points: np.ndarray, centroid: np.ndarray) -> np.ndarray:
    """[K, 2] ``points`` moved by :data:`HULL_INSET` towards ``centroid``."""
    towards_centroid = centroid - points
    return points + HULL_INSET * towards_centroid / np.linalg.norm(towards_centroid, axis=1, keepdims=True)


def support_friction(obj: PushObject | str, surface: str, effects: Effects = Effects(),
                     support: str = "grid") -> np.ndarray:
    """[K, 2] friction coefficients of the support contacts along the object's x and y axes.

    ``mu_i = mu_surface * area weight_i * pressure weight_i * anisotropy``, see :mod:`pushjax.sim.effects`.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    points, area_weights = support_points(obj, support)
    radius = np.linalg.norm(points - obj.centroid, axis=1)
    pressure = np.exp(effects.pressure_rim * radius / radius.max())
    weights = area_weights * pressure
    weights = weights / weights.mean()
    mu = get_surface(surface).object_friction
    return mu * weights[:, None] * np.asarray(effects.friction_anisotropy)[None, :]


def pusher_friction(effects: Effects = Effects()) -> float:
    """Pusher–object Coulomb coefficient under ``effects``."""
    return PUSHER_OBJECT_FRICTION if effects.pusher_friction is None else effects.pusher_friction


def gravity(effects: Effects = Effects()) -> np.ndarray:
    """[3] gravity in m/s² in the world (table) frame for a table tilted as ``effects`` say."""
    tilt = np.radians(effects.table_tilt_deg)
    azimuth = np.radians(effects.table_tilt_azimuth_deg)
    g = 9.81
    return np.array([g * np.sin(tilt) * np.cos(azimuth), g * np.sin(tilt) * np.sin(azimuth), -g * np.cos(tilt)])


@functools.cache
def convex_pieces(obj: PushObject) -> tuple[np.ndarray, ...]:
    """The outline cut into convex counter-clockwise polygons ([P_i, 2] in m), one piece if convex."""
    outline = np.asarray(obj.outline, dtype=np.float64)
    if _is_convex(outline):
        return (outline,)
    # Digitised outlines wiggle by micrometres; those wiggles would each need a cut.
    simplified = shapely.Polygon(outline).simplify(OUTLINE_TOLERANCE, preserve_topology=True)
    outline = np.asarray(simplified.exterior.coords)[:-1]
    if not simplified.exterior.is_ccw:
        outline = outline[::-1]
    index = {tuple(point): k for k, point in enumerate(outline)}
    pieces: dict[int, list[int]] = {}
    owner: dict[tuple[int, int], int] = {}
    for key, triangle in enumerate(shapely.constrained_delaunay_triangles(shapely.Polygon(outline)).geoms):
        corners = [index[tuple(point)] for point in np.asarray(triangle.exterior.coords)[:-1]]
        if not shapely.Polygon(outline[corners]).exterior.is_ccw:
            corners.reverse()
        pieces[key] = corners
        owner.update({edge: key for edge in _edges(corners)})
    # Hertel–Mehlhorn: one sweep over the diagonals, dropping each one whose removal keeps the union convex.
    for a, b in sorted(edge for edge in owner if edge[0] < edge[1] and (edge[1], edge[0]) in owner):
        first, second = owner[(a, b)], owner[(b, a)]
        candidate = _merge_across(pieces[first], pieces[second], a, b)
        if _is_convex(outline[candidate]):
            pieces[first] = candidate
            del pieces[second]
            owner.update({edge: first for edge in _edges(candidate)})
    return tuple(outline[pieces[key]] for key in sorted(pieces))


def _edges(corners: list[int]) -> list[tuple[int, int]]:
    return list(zip(corners, corners[1:] + corners[:1]))


def _merge_across(first: list[int], second: list[int], a: int, b: int) -> list[int]:
    """Union of two CCW polygons sharing the edge a->b of ``first`` (b->a of ``second``)."""
    i = first.index(b)
    from_b = first[i:] + first[:i]  # b ... a
    j = second.index(a)
    from_a = second[j:] + second[:j]  # a ... b
    return from_b + from_a[1:-1]


def _is_convex(polygon: np.ndarray) -> bool:
    edges = np.roll(polygon, -1, axis=0) - polygon
    turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
    return bool(np.all(turns >= -CONVEX_TOLERANCE))


def _as_written(values) -> np.ndarray:
    """``values`` rounded to 10 significant digits, as the MJCF text that built the scenes before
    :func:`scene_spec` wrote them: data sets recorded with either are byte-identical."""
    return np.array([float(f"{float(v):.10g}") for v in np.ravel(values)])


def _written(value: float) -> float:
    return float(_as_written([value])[0])


def scene_spec(obj: PushObject | str, surface: str, effects: Effects = Effects(), support: str = "grid") -> mujoco.MjSpec:
    """One scene as an editable MuJoCo model specification (meshes inline).

    Args:
      obj: the object or its name (see ``pushjax.geometry.OBJECT_NAMES``).
      surface: support surface name (``abs``, ``delrin``, ``plywood`` or ``pu``).
      effects: physical effects; the tracking effects do not change the scene.
      support: one of :data:`SUPPORT_MODES`, see the module docstring.

    Returns:
      The specification; ``.compile()`` gives the model, ``.to_xml()`` its MJCF.
    """
    if isinstance(obj, str):
        obj = get_object(obj)
    if not isinstance(effects, Effects):
        raise ValueError(f"effects: expected an Effects, got {type(effects).__name__}")
    surface_spec = get_surface(surface)
    points, _ = support_points(obj, support)
    friction = support_friction(obj, surface, effects, support)
    pieces = convex_pieces(obj)

    spec = mujoco.MjSpec()
    spec.modelname = f"mit_push_{obj.name}_{surface}"
    _set_options(spec, effects)
    _add_assets(spec, obj, surface_spec)
    world = spec.worldbody
    world.add_light(name="top", pos=[0, 0, 1.5], dir=[0, 0, -1], diffuse=[0.6, 0.6, 0.6])
    world.add_camera(name="camera", pos=[0, 0, 0.8], fovy=45)
    world.add_geom(name="table", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[_written(TABLE_HALF_SIZE)] * 2 + [0.01],
                   material="table_material", contype=0, conaffinity=0)
    _add_plate(spec, obj, effects, pieces, points)
    _add_pusher(spec)
    _add_contacts(spec, friction, len(pieces), pusher_friction(effects))
    return spec


def _set_options(spec: mujoco.MjSpec, effects: Effects) -> None:
    """The compiler's, the solver's (see the module docstring), the viewer's and the statistics' settings."""
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    spec.option.timestep = _written(TIMESTEP)
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = _written(IMPRATIO)
    spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    spec.option.solver = mujoco.mjtSolver.mjSOL_CG
    spec.option.gravity = _as_written(gravity(effects))
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.5, 0.5, 0.5]
    spec.visual.global_.offwidth = 640
    spec.visual.global_.offheight = 480
    spec.stat.center = [0.0, 0.0, 0.02]
    spec.stat.extent = 0.4


def _add_assets(spec: mujoco.MjSpec, obj: PushObject, surface_spec: Surface) -> None:
    """The table's texture and material, the plate's and the pusher's materials and the plate's visual mesh."""
    spec.add_texture(name="table_texture", type=mujoco.mjtTexture.mjTEXTURE_2D,
                     builtin=getattr(mujoco.mjtBuiltin, f"mjBUILTIN_{surface_spec.texture.upper()}"),
                     mark=getattr(mujoco.mjtMark, f"mjMARK_{surface_spec.mark.upper()}"), random=0.05,
                     rgb1=_as_written(surface_spec.rgb), rgb2=_as_written(surface_spec.rgb2),
                     markrgb=_as_written(surface_spec.rgb2), width=512, height=512)
    textures = [""] * mujoco.mjtTextureRole.mjNTEXROLE
    textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "table_texture"
    spec.add_material(name="table_material", textures=textures, texrepeat=[4, 4], texuniform=True, reflectance=0.05)
    spec.add_material(name="steel", rgba=[0.72, 0.73, 0.75, 1], specular=0.8, shininess=0.6, reflectance=0.1)
    spec.add_material(name="pusher_material", rgba=[0.35, 0.36, 0.4, 1], specular=0.5)
    spec.add_mesh(name="object_visual", uservert=_as_written(obj.mesh.vertices),
                  userface=np.ravel(obj.mesh.faces).astype(int).tolist())


def _add_plate(spec: mujoco.MjSpec, obj: PushObject, effects: Effects, pieces: tuple[np.ndarray, ...],
               points: np.ndarray) -> None:
    """The body ``object``: its free joint, mass and inertia (centre of mass moved by ``Effects.com_offset``), visual
    mesh, walls (one prism per convex piece) and support capsules at ``points``."""
    half_thickness = _written(obj.thickness / 2)
    plate = spec.worldbody.add_body(name="object", pos=[0, 0, half_thickness])
    plate.add_freejoint(name="object_joint")
    inertia = obj.inertia_tensor
    plate.explicitinertial = True
    plate.ipos = _as_written([*(obj.centroid + np.asarray(effects.com_offset)), 0.0])
    plate.mass = _written(obj.mass)
    plate.fullinertia = _as_written([inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2],
                                     inertia[1, 2]])
    plate.add_geom(name="object_visual", type=mujoco.mjtGeom.mjGEOM_MESH, meshname="object_visual", material="steel",
                   contype=0, conaffinity=0, mass=0)
    for k, piece in enumerate(pieces):
        prism = np.concatenate([np.c_[piece, np.full(len(piece), -half_thickness)],
                                np.c_[piece, np.full(len(piece), half_thickness)]])
        spec.add_mesh(name=f"wall{k}", uservert=_as_written(prism))
        plate.add_geom(name=f"wall{k}", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"wall{k}", group=3, contype=0,
                       conaffinity=0, mass=0, rgba=[0.8, 0.2, 0.2, 0.3])
    raise_angle = np.radians(SUPPORT_RAISE_DEG)
    # Capsule axis in the body frame: along +x, raised; its lower end's sphere rests on the plate's bottom.
    axis = np.array([np.cos(raise_angle), 0.0, np.sin(raise_angle)])
    capsule_quat = _as_written([np.cos((np.pi / 2 - raise_angle) / 2), 0.0, np.sin((np.pi / 2 - raise_angle) / 2), 0.0])
    for k, point in enumerate(points):
        lower_end_centre = np.array([point[0], point[1], -half_thickness + SUPPORT_RADIUS])
        plate.add_geom(name=f"support{k}", type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                       size=[*_as_written([SUPPORT_RADIUS, SUPPORT_HALF_LENGTH]), 0.0],
                       pos=_as_written(lower_end_centre + SUPPORT_HALF_LENGTH * axis), quat=capsule_quat, group=3,
                       contype=0, conaffinity=0, mass=0, rgba=[0.2, 0.8, 0.2, 1])


def _add_pusher(spec: mujoco.MjSpec) -> None:
    """The mocap body ``pusher`` (rendering only), the carriage ``pusher_carriage`` on its slide joints with the tip
    ``pusher_tip`` on its vertical spring, and the carriage's position and velocity servos."""
    world = spec.worldbody
    pusher_z = _written(PUSHER_CLEARANCE + PUSHER_HALF_HEIGHT)
    pusher_size = _as_written([PUSHER_RADIUS, PUSHER_HALF_HEIGHT])
    world.add_body(name="pusher", mocap=True, pos=[0, 0, pusher_z]).add_geom(
        name="pusher", type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[*pusher_size, 0.0], material="pusher_material",
        contype=0, conaffinity=0)
    carriage = world.add_body(name="pusher_carriage", pos=[0, 0, pusher_z], gravcomp=1)
    carriage.add_joint(name="pusher_x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0])
    carriage.add_joint(name="pusher_y", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 1, 0])
    carriage.add_geom(name="pusher_carriage", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[pusher_size[0], 0, 0],
                      mass=_written(PUSHER_MASS), group=3, contype=0, conaffinity=0)
    tip = carriage.add_body(name="pusher_tip", gravcomp=1)
    tip.add_joint(name="pusher_z", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 0, 1],
                  stiffness=[_written(TIP_STIFFNESS), 0, 0], damping=[_written(TIP_DAMPING), 0, 0])
    tip.add_geom(name="pusher_tip", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[*pusher_size, 0.0],
                 mass=_written(TIP_MASS), group=3, contype=0, conaffinity=0, rgba=[0.2, 0.2, 0.8, 1])

    for axis_name in ("x", "y"):
        spec.add_actuator(name=f"pusher_{axis_name}", target=f"pusher_{axis_name}",
                          trntype=mujoco.mjtTrn.mjTRN_JOINT).set_to_position(kp=_written(PUSHER_KP))
    for axis_name in ("x", "y"):
        spec.add_actuator(name=f"pusher_v{axis_name}", target=f"pusher_{axis_name}",
                          trntype=mujoco.mjtTrn.mjTRN_JOINT).set_to_velocity(kv=_written(PUSHER_KV))


def _add_contacts(spec: mujoco.MjSpec, friction: np.ndarray, walls: int, mu_pusher: float) -> None:
    """The explicit contact pairs (table–support with the supports' [K, 2] ``friction``, tip–wall with ``mu_pusher``)
    and the pusher's contact sensor."""
    for k in range(len(friction)):
        spec.add_pair(geomname1="table", geomname2=f"support{k}", condim=3, solref=_as_written(CONTACT_SOLREF),
                      solimp=_as_written(SUPPORT_SOLIMP),
                      friction=_as_written([friction[k, 0], friction[k, 1], TORSIONAL_FRICTION, 0, 0]))
    for k in range(walls):
        spec.add_pair(geomname1="pusher_tip", geomname2=f"wall{k}", condim=3, solref=_as_written(CONTACT_SOLREF),
                      solimp=_as_written(PUSHER_SOLIMP),
                      friction=_as_written([mu_pusher, mu_pusher, TORSIONAL_FRICTION, 0, 0]))
    spec.add_sensor(name="pusher_contact", type=mujoco.mjtSensor.mjSENS_CONTACT, objtype=mujoco.mjtObj.mjOBJ_BODY,
                    objname="pusher_tip", reftype=mujoco.mjtObj.mjOBJ_BODY, refname="object",
                    intprm=[_CONTACT_DATA, _CONTACT_NETFORCE, 1])


def scene_xml(obj: PushObject | str, surface: str, effects: Effects = Effects(), support: str = "grid") -> str:
    """MJCF of one scene, self-contained (meshes inline), for MuJoCo's viewer; arguments as in :func:`scene_spec`.

    MuJoCo's MJCF writer keeps 6 significant digits: simulate :func:`build_model`, not this text.
    """
    return scene_spec(obj, surface, effects, support).to_xml()


def build_model(obj: PushObject | str, surface: str, effects: Effects = Effects(),
                support: str = "grid") -> mujoco.MjModel:
    """The compiled scene; arguments as in :func:`scene_spec`."""
    return scene_spec(obj, surface, effects, support).compile()


def write_scene(path: str | os.PathLike, obj: PushObject | str, surface: str, effects: Effects = Effects(),
                support: str = "grid") -> Path:
    """Writes :func:`scene_xml` to ``path`` (e.g. ``rect1_abs.xml`` for ``python -m mujoco.viewer``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(scene_xml(obj, surface, effects, support))
    return path
