"""Object definitions against the MIT Push Dataset's meshes and facts, and limit-surface ratios."""

import json

import numpy as np
import pytest
import shapely
import trimesh

from pushjax.geometry import OBJECT_NAMES, get_object, limit_surface_ratio, support_cells, support_feet

# The dataset's .obj files are Y-up: the plate's plane is the mesh's (x, z), which maps to the
# object's (x, y) unchanged (the right-angle corner of the triangles is at mesh (+45, +45) mm).
_Y_UP_TO_PLANE = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


@pytest.fixture(scope="module")
def facts(shared_dir):
    return json.loads((shared_dir / "data" / "mit_push_facts.json").read_text())["objects"]


def mesh_footprint(path) -> shapely.Polygon:
    """Mid-height section of a dataset mesh in object (x, y), m, with its marker holes filled."""
    mesh = trimesh.load(path, force="mesh")
    section = mesh.section(plane_origin=[0.0, 0.0, 0.0], plane_normal=[0.0, 1.0, 0.0])
    planar, _ = section.to_2D(to_2D=_Y_UP_TO_PLANE)
    return shapely.union_all([shapely.Polygon(polygon.exterior) for polygon in planar.polygons_full])


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_footprint_matches_dataset_mesh(shared_dir, name):
    footprint = mesh_footprint(shared_dir / "data" / "mit_push_objects" / f"{name}.obj")
    polygon = get_object(name).polygon
    iou = footprint.intersection(polygon).area / footprint.union(polygon).area
    assert iou >= 0.99
    assert footprint.hausdorff_distance(polygon) < 1.1e-3


def test_butter_is_not_convex():
    butter = get_object("butter")
    assert butter.polygon.convex_hull.area > 1.1 * butter.area
    assert len(butter.outline) > 200
    assert not np.any(np.all(np.diff(butter.outline, axis=0, append=butter.outline[:1]) == 0, axis=1))


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_area_centroid_and_limit_surface_match_facts(facts, name):
    obj, expected = get_object(name), facts[name]
    # The facts come from the meshes, whose dimensions differ from the annotation script's by up to
    # 0.3 mm (e.g. tri3's short leg), hence 1 % on areas and 0.25 mm on centroids.
    np.testing.assert_allclose(obj.area * 1e4, expected["area_cm2"], rtol=0.01)
    np.testing.assert_allclose(obj.centroid * 1e3, expected["centroid_mm"], atol=0.25)
    np.testing.assert_allclose(limit_surface_ratio(obj) * 1e3, expected["l_uniform_mm"], rtol=0.01)


def test_triangle_frames_are_off_the_centre_of_mass():
    for name in ("tri1", "tri2", "tri3"):
        obj = get_object(name)
        np.testing.assert_allclose(obj.centroid, obj.outline.mean(axis=0), atol=1e-12)
        assert np.linalg.norm(obj.centroid) > 2e-3


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_mesh_is_a_watertight_plate_of_the_footprint(name):
    obj = get_object(name)
    mesh = obj.mesh
    assert mesh.is_watertight
    np.testing.assert_allclose(mesh.bounds[:, 2], [-obj.thickness / 2, obj.thickness / 2], atol=1e-12)
    footprint_area = obj.polygon.area  # ellipses are meshed from their sampled outline
    np.testing.assert_allclose(mesh.volume, footprint_area * obj.thickness, rtol=1e-9)
    np.testing.assert_allclose(footprint_area, obj.area, rtol=2e-4)
    np.testing.assert_allclose(obj.mass, obj.area * obj.thickness * obj.density)


def test_mesh_matches_dataset_mesh_volume(shared_dir):
    # The dataset meshes are not watertight; their section area times the thickness stands in.
    for name in ("rect1", "tri2", "hex"):
        footprint = mesh_footprint(shared_dir / "data" / "mit_push_objects" / f"{name}.obj")
        np.testing.assert_allclose(get_object(name).mesh.volume, footprint.area * 0.0127, rtol=0.01)


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_pressure_distribution_moves_limit_surface_ratio(name):
    obj = get_object(name)
    uniform = limit_surface_ratio(obj)
    corners = np.array([side[0] for side in obj.sides])
    at_corners = limit_surface_ratio(obj, support_points=corners)
    centre = obj.centroid
    at_centre = limit_surface_ratio(
        obj, pressure=lambda points: np.exp(-np.sum((points - centre) ** 2, axis=-1) / (2 * 0.01**2)))
    assert at_corners > 1.2 * uniform
    assert at_centre < 0.5 * uniform
    # A 2-D Gaussian pressure of width sigma has l = sigma sqrt(pi / 2).
    np.testing.assert_allclose(at_centre, 0.01 * np.sqrt(np.pi / 2), rtol=0.01)


def test_limit_surface_ratio_of_support_points():
    rect = get_object("rect1")
    corners = np.array([[0.045, 0.045], [-0.045, 0.045], [-0.045, -0.045], [0.045, -0.045]])
    np.testing.assert_allclose(limit_surface_ratio(rect, support_points=corners), 0.045 * np.sqrt(2))
    weighted = limit_surface_ratio(rect, support_points=[[0.0, 0.0], [0.03, 0.0]], support_weights=[1, 2])
    np.testing.assert_allclose(weighted, (1 * 0.02 + 2 * 0.01) / 3)


def test_bad_input_raises():
    rect = get_object("rect1")
    with pytest.raises(ValueError, match="object name"):
        get_object("cube")
    with pytest.raises(ValueError, match="support_points"):
        limit_surface_ratio(rect, support_points=np.zeros((4, 3)))
    with pytest.raises(ValueError, match="support_weights"):
        limit_surface_ratio(rect, support_points=np.zeros((4, 2)), support_weights=np.ones(3))
    with pytest.raises(ValueError, match="pressure weights"):
        limit_surface_ratio(rect, support_points=np.eye(2), support_weights=[1.0, -1.0])
    with pytest.raises(ValueError, match="pressure"):
        limit_surface_ratio(rect, pressure=lambda points: -np.ones(len(points)))
    with pytest.raises(ValueError, match="pressure and support_points"):
        limit_surface_ratio(rect, pressure=lambda points: np.ones(len(points)), support_points=np.eye(2))
    with pytest.raises(ValueError, match="side"):
        rect.side_point(4, 0.5)
    with pytest.raises(ValueError, match="point"):
        rect.side_point(0, 1.5)


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_side_point_lies_on_boundary_with_inward_normal(name):
    obj = get_object(name)
    boundary = obj.polygon.exterior
    for side in range(len(obj.sides)):
        for fraction in (0.1, 0.25, 0.5, 0.9):
            point, normal = obj.side_point(side, fraction)
            assert shapely.distance(boundary, shapely.Point(point)) < 1e-12
            np.testing.assert_allclose(np.linalg.norm(normal), 1.0)
            assert obj.polygon.contains(shapely.Point(point + 1e-4 * normal))
            assert not obj.polygon.contains(shapely.Point(point - 1e-4 * normal))


def test_sides_partition_the_boundary():
    for obj in map(get_object, OBJECT_NAMES):
        lengths = [np.linalg.norm(np.diff(side, axis=0), axis=1).sum() for side in obj.sides]
        np.testing.assert_allclose(sum(lengths), obj.polygon.exterior.length, rtol=1e-12)
        np.testing.assert_allclose(obj.side_point(0, 0.0)[0], obj.sides[0][0], atol=1e-15)
        np.testing.assert_allclose(obj.side_point(0, 1.0)[0], obj.sides[1][0], atol=1e-15)


def test_side_normal_of_rect_centre():
    point, normal = get_object("rect3").side_point(0, 0.5)
    np.testing.assert_allclose(point, [0.0675, 0.0], atol=1e-15)
    np.testing.assert_allclose(normal, [-1.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_support_cells_cover_the_footprint_with_its_area(name):
    obj = get_object(name)
    points, weights, radius = support_cells(obj)
    assert 20 <= len(points) <= 36 and points.shape == (len(points), 2)
    np.testing.assert_allclose(weights.sum(), 1.0)
    np.testing.assert_allclose(weights @ points, 0.0, atol=1e-12)  # centred: uniform pressure at the COM
    # The cells' torque intercept (each a patch turning about the centre) is the uniform plate's l, within the
    # cells' discretisation.
    intercept = weights @ np.sqrt(np.sum(points ** 2, axis=1) + radius ** 2)
    assert abs(intercept / limit_surface_ratio(obj) - 1) < 0.025
    assert 0 < radius < 0.015


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_support_feet_are_hull_corners_that_balance_the_object(name):
    obj = get_object(name)
    points, loads = support_feet(obj)
    assert 3 <= len(points) <= 16 and points.shape == (len(points), 2)
    assert np.all(loads >= 0) and loads.sum() == pytest.approx(1.0)
    np.testing.assert_allclose(loads @ points, 0.0, atol=1e-7)  # the load's centre under the centre of mass
    hull = shapely.Polygon(obj.outline).convex_hull
    on_hull = [hull.exterior.distance(shapely.Point(*(point + obj.centroid))) for point in points]
    assert max(on_hull) < 1e-9
    # The outermost support: every corner is farther from the centre of mass than the footprint's mean radius.
    cells, areas, _ = support_cells(obj)
    assert np.min(np.linalg.norm(points, axis=1)) > areas @ np.linalg.norm(cells, axis=1)


def test_support_feet_of_a_rectangle_are_its_corners_with_equal_loads():
    obj = get_object("rect1")
    points, loads = support_feet(obj)
    half = (obj.outline.max(axis=0) - obj.outline.min(axis=0)) / 2
    np.testing.assert_allclose(np.sort(np.abs(points), axis=0), np.tile(half, (4, 1)), atol=1e-12)
    np.testing.assert_allclose(loads, 0.25)
