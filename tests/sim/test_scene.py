"""Tests for pushjax.sim.scene: naming convention, geometry, supports, contacts and the resting plate."""

import xml.dom.minidom
from pathlib import Path

import mujoco
import numpy as np
import pytest
import shapely

from pushjax.geometry import OBJECT_NAMES, PUSHER_RADIUS, get_object, limit_surface_ratio
from pushjax.sim import scene
from pushjax.sim.effects import Effects
from pushjax.sim.push import Simulator
from pushjax.sim.surfaces import SURFACE_NAMES, SURFACES


def test_surfaces_have_plausible_coefficients():
    for name in SURFACE_NAMES:
        assert 0.05 <= SURFACES[name].object_friction <= 0.6
    assert SURFACES["abs"].object_friction < SURFACES["plywood"].object_friction < SURFACES["pu"].object_friction
    with pytest.raises(ValueError, match="surface"):
        scene.build_model("rect1", "glass")


def test_naming_convention_for_the_renderer():
    model = scene.build_model("tri2", "plywood")
    assert model.geom("table").type[0] == mujoco.mjtGeom.mjGEOM_PLANE
    assert model.geom("table").pos[2] == 0.0
    assert model.geom("table").matid[0] >= 0
    assert model.joint("object_joint").type[0] == mujoco.mjtJoint.mjJNT_FREE
    assert model.joint("object_joint").bodyid[0] == model.body("object").id
    assert model.body("pusher").mocapid[0] >= 0
    pusher_geom = model.geom("pusher")
    assert pusher_geom.type[0] == mujoco.mjtGeom.mjGEOM_CYLINDER
    assert pusher_geom.size[0] == pytest.approx(PUSHER_RADIUS)
    assert model.camera("camera").bodyid[0] == 0


def test_surfaces_have_distinct_materials():
    textures = set()
    for name in SURFACE_NAMES:
        model = scene.build_model("rect1", name)
        textures.add(model.tex_data.tobytes())
    assert len(textures) == len(SURFACE_NAMES)


@pytest.mark.parametrize("name", ["rect1", "tri3", "butter"])
def test_inertial_properties_follow_the_geometry(name):
    obj = get_object(name)
    model = scene.build_model(name, "abs", Effects(com_offset=(0.01, -0.02)))
    body = model.body("object")
    assert body.mass[0] == pytest.approx(obj.mass)
    np.testing.assert_allclose(body.ipos[:2], obj.centroid + [0.01, -0.02], atol=1e-12)
    inertia = np.empty(9)
    mujoco.mju_quat2Mat(inertia, body.iquat)
    rotation = inertia.reshape(3, 3)
    np.testing.assert_allclose(rotation @ np.diag(body.inertia) @ rotation.T, obj.inertia_tensor, rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_convex_pieces_cover_the_outline(name):
    obj = get_object(name)
    pieces = scene.convex_pieces(obj)
    assert all(shapely.Polygon(piece).exterior.is_ccw for piece in pieces)
    assert all(scene._is_convex(piece) for piece in pieces)
    union = shapely.union_all([shapely.Polygon(piece) for piece in pieces])
    outline = shapely.Polygon(obj.outline)
    assert shapely.hausdorff_distance(union.exterior, outline.exterior) < 2e-5
    assert union.area == pytest.approx(outline.area, rel=1e-4)
    assert (len(pieces) == 1) == (name != "butter")


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_grid_supports_match_the_uniform_limit_surface(name):
    obj = get_object(name)
    points, weights = scene.support_points(obj, "grid")
    assert len(points) == scene.GRID_SUPPORTS
    assert np.all(shapely.contains_xy(shapely.Polygon(obj.outline), points[:, 0], points[:, 1]))
    assert weights.mean() == pytest.approx(1.0)
    l_supports = limit_surface_ratio(obj, support_points=points, support_weights=weights)
    assert l_supports == pytest.approx(limit_surface_ratio(obj), rel=0.03)


def test_hull_supports_sit_near_the_hull_corners():
    obj = get_object("rect2")
    points, weights = scene.support_points(obj, "hull")
    assert len(points) == 4 and np.all(weights == 1)
    corner_distance = np.linalg.norm(points[:, None] - obj.outline[None], axis=-1).min(axis=1)
    np.testing.assert_allclose(corner_distance, scene.HULL_INSET)
    with pytest.raises(ValueError, match="support: expected one of grid, hull, ring"):
        scene.support_points(obj, "feet")


@pytest.mark.parametrize("name", ["rect2", "butter"])
def test_ring_supports_run_along_the_outline_just_inside_it(name):
    obj = get_object(name)
    points, weights = scene.support_points(obj, "ring")
    assert len(points) == scene.RING_SUPPORTS and np.all(weights == 1)
    outline = shapely.Polygon(obj.outline)
    assert all(outline.contains(shapely.Point(*point)) for point in points)
    distance = [outline.exterior.distance(shapely.Point(*point)) for point in points]
    assert max(distance) <= scene.HULL_INSET + 1e-12 and min(distance) > 0.3 * scene.HULL_INSET
    # Equally spaced along the outline: consecutive points a sixteenth of the perimeter apart, to within the inset.
    gaps = np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1)
    assert np.max(gaps) <= outline.exterior.length / scene.RING_SUPPORTS + 2 * scene.HULL_INSET


def test_support_friction_realises_pressure_and_anisotropy():
    obj = get_object("rect1")
    mu = SURFACES["abs"].object_friction
    nominal = scene.support_friction(obj, "abs")
    _, areas = scene.support_points(obj)
    np.testing.assert_allclose(nominal, mu * areas[:, None] * [1, 1])
    rim = scene.support_friction(obj, "abs", Effects(pressure_rim=2.0))[:, 0]
    radius = np.linalg.norm(scene.support_points(obj)[0], axis=1)
    ratio = rim / areas / np.exp(2.0 * radius / radius.max())
    np.testing.assert_allclose(ratio, ratio[0])
    assert (rim / areas)[np.argmax(radius)] > 2 * (rim / areas)[np.argmin(radius)]
    anisotropic = scene.support_friction(obj, "abs", Effects(friction_anisotropy=(1.0, 2.5)))
    np.testing.assert_allclose(anisotropic[:, 1], 2.5 * anisotropic[:, 0])


def test_gravity_of_a_tilted_table():
    np.testing.assert_allclose(scene.gravity(), [0, 0, -9.81])
    g = scene.gravity(Effects(table_tilt_deg=30, table_tilt_azimuth_deg=90))
    np.testing.assert_allclose(g, [0, 9.81 / 2, -9.81 * np.sqrt(3) / 2], atol=1e-12)


def test_support_contact_frames_turn_with_the_object():
    """Plane–capsule contacts take the capsule axis (the object's x axis) as first tangent."""
    sim = Simulator("rect1", "abs", Effects(friction_anisotropy=(1.0, 2.0)))
    model, data = sim.model, sim.data
    yaw = 0.7
    mujoco.mj_resetData(model, data)
    data.qpos[:7] = [0, 0, sim._settled_object[2], np.cos(yaw / 2), 0, 0, np.sin(yaw / 2)]
    data.qpos[7:9] = [1.0, 1.0]
    mujoco.mj_forward(model, data)
    table = model.geom("table").id
    frames = [data.contact.frame[i] for i in range(data.ncon) if table in data.contact.geom[i]]
    assert len(frames) == scene.GRID_SUPPORTS
    for frame in frames:
        np.testing.assert_allclose(frame[:3], [0, 0, 1], atol=1e-9)
        assert abs(frame[3:6] @ [np.cos(yaw), np.sin(yaw), 0]) == pytest.approx(1.0, abs=1e-9)
    friction = [data.contact.friction[i][:2] for i in range(data.ncon) if table in data.contact.geom[i]]
    np.testing.assert_allclose([f[1] / f[0] for f in friction], 2.0)


def test_pusher_friction_acts_in_the_table_plane():
    """The pusher tip hangs on a soft vertical spring, so no vertical friction force gets locked in."""
    sim = Simulator("hex", "abs")
    model, data = sim.model, sim.data
    point, inward = get_object("hex").side_point(2, 0.3)
    mujoco.mj_resetData(model, data)
    data.qpos[:7] = sim._settled_object
    data.qpos[7:9] = point - (PUSHER_RADIUS + 1e-3) * inward
    model.opt.timestep = 0.002
    forces = []
    target = data.qpos[7:9].copy()
    for step in range(500):
        if step:
            target = target + 0.02 * model.opt.timestep * inward
        data.ctrl[:] = [*target, *(0.02 * inward)]
        mujoco.mj_step(model, data)
        forces.append(data.sensordata[:3].copy())
    forces = np.array(forces[250:])
    assert np.all(np.linalg.norm(forces[:, :2], axis=1) > 0.5)
    assert np.abs(forces[:, 2]).max() < 0.05 * np.linalg.norm(forces[:, :2], axis=1).min()


def test_object_at_rest_stays_at_rest():
    sim = Simulator("tri1", "delrin")
    model, data = sim.model, sim.data
    mujoco.mj_resetData(model, data)
    data.qpos[:7] = sim._settled_object
    data.qpos[7:9] = data.ctrl[:2] = [1.0, 1.0]
    model.opt.timestep = 0.002
    start = data.qpos[:3].copy()
    mujoco.mj_step(model, data, nstep=1000)
    assert np.linalg.norm(data.qpos[:3] - start) < 1e-4
    assert 0 < get_object("tri1").thickness / 2 - data.qpos[2] < 3e-4  # resting, sunk < 0.3 mm


def test_tilted_table_beyond_the_friction_angle_lets_a_free_object_slide_downhill():
    # abs: mu = 0.13, friction angle 7.4°.
    sim = Simulator("rect1", "abs", Effects(table_tilt_deg=10.0, table_tilt_azimuth_deg=135.0))
    model, data = sim.model, sim.data
    mujoco.mj_resetData(model, data)
    data.qpos[:7] = sim._settled_object
    data.qpos[7:9] = data.ctrl[:2] = [1.0, 1.0]
    model.opt.timestep = 0.002
    mujoco.mj_step(model, data, nstep=250)
    displacement = data.qpos[:2]
    downhill = np.array([np.cos(np.radians(135)), np.sin(np.radians(135))])
    expected = 0.5 * 9.81 * (np.sin(np.radians(10)) - 0.13 * np.cos(np.radians(10))) * 0.5 ** 2
    assert displacement @ downhill == pytest.approx(expected, rel=0.1)
    assert abs(displacement @ [-downhill[1], downhill[0]]) < 1e-3


def test_write_scene_round_trips(tmp_path):
    path = scene.write_scene(tmp_path / "scene.xml", "butter", "pu", Effects(table_tilt_deg=2.0), support="hull")
    xml.dom.minidom.parseString(path.read_text())  # well-formed XML
    model = mujoco.MjModel.from_xml_path(str(path))
    reference = scene.build_model("butter", "pu", Effects(table_tilt_deg=2.0), support="hull")
    assert model.ngeom == reference.ngeom and model.npair == reference.npair
    np.testing.assert_allclose(model.opt.gravity, reference.opt.gravity, rtol=1e-5)  # MJCF: 6 significant digits
    np.testing.assert_allclose(model.pair_friction, reference.pair_friction, rtol=1e-5)


@pytest.mark.parametrize("name, surface, effects, support", [
    ("butter", "abs", Effects(com_offset=(0.01, -0.005), pressure_rim=-2.0, friction_anisotropy=(1.0, 1.5),
                              table_tilt_deg=4.0, table_tilt_azimuth_deg=30.0, pusher_friction=0.6), "grid"),
    ("tri2", "plywood", Effects(), "hull"),
])
def test_the_spec_builds_the_model_and_simulation_of_the_mjcf_it_replaced(name, surface, effects, support):
    # mjcf_before_mjspec/ holds the MJCF text that scene_xml wrote before the scenes were built with MjSpec:
    # a non-convex outline on grid supports with every physical effect, and a convex one on hull supports.
    path = Path(__file__).parent / "mjcf_before_mjspec" / f"{name}_{surface}_{support}.xml"
    before = mujoco.MjModel.from_xml_path(str(path))
    model = scene.build_model(name, surface, effects, support)

    def saved(model):
        buffer = np.zeros(mujoco.mj_sizeModel(model), np.uint8)
        mujoco.mj_saveModel(model, None, buffer)
        return buffer.tobytes()

    assert saved(model) == saved(before)

    def push(model):
        """Pushes the resting plate along x at 20 mm/s for 1 s; the object's and the pusher's states and the
        contact sensor at every step."""
        obj = get_object(name)
        data = mujoco.MjData(model)
        data.qpos[2] = obj.thickness / 2
        y = obj.centroid[1] + 5e-3
        side = shapely.LineString([(-1.0, y), (1.0, y)]).intersection(shapely.Polygon(obj.outline)).bounds[0]
        start = np.array([side - PUSHER_RADIUS - 2e-3, y])
        data.qpos[7:9] = start
        states = []
        for k in range(500):
            data.ctrl[:] = [*(start + [0.02 * k * model.opt.timestep, 0.0]), 0.02, 0.0]
            mujoco.mj_step(model, data)
            states.append(np.concatenate([data.qpos, data.qvel, data.sensordata]))
        return np.array(states)

    pushed = push(model)
    assert np.linalg.norm(pushed[-1, :2] - pushed[0, :2]) > 1e-3  # the pusher moved the plate
    assert pushed.tobytes() == push(before).tobytes()
