"""Contact annotation: hand-computed cases, invariances and a brute-force reference for all objects."""

import dataclasses

import numpy as np
import pytest
import shapely
from shapely import affinity

from pushjax.geometry import (
    NO_CONTACT_FRACTION,
    OBJECT_NAMES,
    PUSHER_RADIUS,
    PushObject,
    annotate,
    get_object,
)

R = PUSHER_RADIUS
HALF = 0.045  # rect1's half side, m


def rotation(angle: float) -> np.ndarray:
    return np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])


def nearest_boundary_point(obj: PushObject, point: np.ndarray) -> np.ndarray:
    """Closest point of the object's boundary to ``point`` [2], object frame, by brute force."""
    if not obj.is_ellipse:
        return np.asarray(shapely.shortest_line(shapely.Point(point), obj.polygon.exterior).coords[1])
    a, b = obj.semi_axes

    def distance(theta):
        return np.hypot(a * np.cos(theta) - point[0], b * np.sin(theta) - point[1])

    def slope(theta):  # half the derivative of the squared distance: negative before the minimum
        return (a * np.cos(theta) - point[0]) * -a * np.sin(theta) + (b * np.sin(theta) - point[1]) * b * np.cos(theta)

    step = 2 * np.pi / 20000
    grid = np.arange(20000) * step
    low = grid[np.argmin(distance(grid))] - step
    high = low + 2 * step
    for _ in range(100):  # bisection on the sign of the slope, bracketing the sampled minimum
        middle = 0.5 * (low + high)
        low, high = (middle, high) if slope(middle) < 0 else (low, middle)
    theta = 0.5 * (low + high)
    return np.array([a * np.cos(theta), b * np.sin(theta)])


def to_object_frame(pose: np.ndarray, points: np.ndarray) -> np.ndarray:
    return (points - pose[:2]) @ rotation(pose[2])


def assert_no_contact(annotation):
    assert not annotation.touches
    assert annotation.first_contact_fraction == NO_CONTACT_FRACTION
    for field in ("contact_world", "contact_rel_com", "normal", "action_from_contact"):
        np.testing.assert_array_equal(getattr(annotation, field), 0.0)


def test_central_push_on_rect_side():
    annotation = annotate("rect1", [0.0, 0.0, 0.0], [-0.1, 0.0], [0.1, 0.0])
    assert annotation.touches
    t = (0.1 - HALF - R) / 0.1
    np.testing.assert_allclose(annotation.first_contact_fraction, t, rtol=1e-14)
    np.testing.assert_allclose(annotation.contact_world, [-HALF, 0.0], atol=1e-15)
    np.testing.assert_allclose(annotation.contact_rel_com, [-HALF, 0.0], atol=1e-15)
    np.testing.assert_allclose(annotation.normal, [1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(annotation.action_from_contact, [(1 - t) * 0.1, 0.0], atol=1e-15)


def test_push_on_moved_and_rotated_rect():
    # rect1 at (1, 2) turned by 90 degrees: pushing down onto its top face from above.
    annotation = annotate("rect1", [1.0, 2.0, np.pi / 2], [1.01, 2.2], [0.0, -0.2])
    np.testing.assert_allclose(annotation.first_contact_fraction, (0.2 - HALF - R) / 0.2, rtol=1e-12)
    np.testing.assert_allclose(annotation.contact_world, [1.01, 2.0 + HALF], atol=1e-12)
    np.testing.assert_allclose(annotation.contact_rel_com, [0.01, HALF], atol=1e-12)
    np.testing.assert_allclose(annotation.normal, [0.0, -1.0], atol=1e-12)


@pytest.mark.parametrize(
    "start, action",
    [
        ([-0.1, HALF + R + 1e-6], [0.2, 0.0]),  # passes just above the top face
        ([-0.1, 0.0], [0.1 - HALF - R - 1e-6, 0.0]),  # stops just short
        ([-0.1, 0.0], [-0.05, 0.0]),  # moves away
        ([-0.1, 0.0], [0.0, 0.0]),  # does not move
    ],
)
def test_push_that_misses(start, action):
    assert_no_contact(annotate("rect1", [0.0, 0.0, 0.0], start, action))


def test_push_that_just_reaches():
    annotation = annotate("rect1", [0.0, 0.0, 0.0], [-0.1, 0.0], [0.1 - HALF - R, 0.0])
    assert annotation.touches
    np.testing.assert_allclose(annotation.first_contact_fraction, 1.0)
    np.testing.assert_allclose(annotation.action_from_contact, [0.0, 0.0], atol=1e-17)


@pytest.mark.parametrize("gap", [0.5 * R, R])
def test_start_already_touching(gap):
    action = np.array([0.03, 0.01])
    annotation = annotate("rect1", [0.0, 0.0, 0.0], [-HALF - gap, 0.01], action)
    assert annotation.touches
    assert annotation.first_contact_fraction == 0.0
    np.testing.assert_allclose(annotation.contact_world, [-HALF, 0.01], atol=1e-15)
    np.testing.assert_allclose(annotation.normal, [1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(annotation.action_from_contact, action)


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_pusher_placed_at_the_radius_touches(name):
    obj = get_object(name)
    rng = np.random.default_rng(6)
    points, normals = zip(*(obj.side_point(side, fraction) for side in range(len(obj.sides))
                            for fraction in rng.uniform(0.05, 0.95, 20)))
    points, normals = np.array(points), np.array(normals)
    centres = points - R * normals
    annotation = annotate(obj, [0.0, 0.0, 0.0], centres, np.zeros_like(points))
    assert np.all(annotation.touches)
    assert np.all(annotation.first_contact_fraction == 0.0)
    # The side point itself where the boundary curves less than the pusher (not in butter's waist,
    # nor for the ellipses, whose side points lie on the sampled outline).
    nearest = np.array([nearest_boundary_point(obj, centre) for centre in centres])
    np.testing.assert_allclose(annotation.contact_world, nearest, atol=1e-12)
    np.testing.assert_allclose(annotation.normal, (nearest - centres) / np.linalg.norm(nearest - centres, axis=-1,
                                                                                        keepdims=True), atol=1e-9)
    if obj.name in ("rect1", "tri3", "hex"):
        np.testing.assert_allclose(annotation.contact_world, points, atol=1e-15)
        np.testing.assert_allclose(annotation.normal, normals, atol=1e-12)


def test_start_touching_even_when_moving_away():
    annotation = annotate("rect1", [0.0, 0.0, 0.0], [-HALF - 0.5 * R, 0.0], [-0.05, 0.0])
    assert annotation.touches and annotation.first_contact_fraction == 0.0


@pytest.mark.parametrize("name", ["rect1", "tri2", "ellip2", "ellip1", "butter"])
def test_start_inside_the_object(name):
    # Penetration (noisy data): contact at the closest boundary point, normal into the object.
    obj = get_object(name)
    pose = np.array([0.1, 0.2, 0.3])
    for side in range(len(obj.sides)):
        point, inward = obj.side_point(side, 0.4)
        start_local = point + 0.003 * inward
        start = pose[:2] + rotation(pose[2]) @ start_local
        annotation = annotate(obj, pose, start, [0.0, 0.02])
        assert annotation.touches and annotation.first_contact_fraction == 0.0
        nearest = nearest_boundary_point(obj, start_local)
        np.testing.assert_allclose(to_object_frame(pose, annotation.contact_world), nearest, atol=1e-10)
        inward_at_nearest = (start_local - nearest) / np.linalg.norm(start_local - nearest)
        np.testing.assert_allclose(rotation(pose[2]).T @ annotation.normal, inward_at_nearest, atol=1e-8)
    deep = annotate(obj, pose, pose[:2] + rotation(pose[2]) @ obj.centroid, [0.0, 0.02])
    assert deep.touches and deep.first_contact_fraction == 0.0
    nearest = nearest_boundary_point(obj, obj.centroid)
    np.testing.assert_allclose(np.linalg.norm(to_object_frame(pose, deep.contact_world) - obj.centroid),
                               np.linalg.norm(nearest - obj.centroid), atol=1e-10)


@pytest.mark.parametrize("name", ["ellip1", "ellip2", "ellip3"])
def test_start_inside_ellipse_near_its_axes(name):
    # Just off an axis the closest-point equation is badly conditioned; results must stay exact.
    obj = get_object(name)
    starts = np.array([[0.01, 1e-13], [1e-13, 0.01], [0.03, -1e-300], [1e-20, 1e-20], [0.0, 0.0], [-0.02, 0.0]])
    annotation = annotate(obj, [0.0, 0.0, 0.0], starts, [0.0, 0.01])
    assert np.all(annotation.touches) and np.all(annotation.first_contact_fraction == 0.0)
    for start, contact in zip(starts, annotation.contact_world):
        a, b = obj.semi_axes
        assert abs((contact[0] / a) ** 2 + (contact[1] / b) ** 2 - 1.0) < 1e-14
        np.testing.assert_allclose(np.linalg.norm(contact - start),
                                   np.linalg.norm(nearest_boundary_point(obj, start) - start), atol=1e-15)


def test_corner_hit_along_the_diagonal():
    corner = np.array([HALF, HALF])
    start, action = np.array([0.1, 0.1]), np.array([-0.1, -0.1])
    annotation = annotate("rect1", [0.0, 0.0, 0.0], start, action)
    t = (np.linalg.norm(start - corner) - R) / np.linalg.norm(action)
    np.testing.assert_allclose(annotation.first_contact_fraction, t, rtol=1e-13)
    np.testing.assert_allclose(annotation.contact_world, corner, atol=1e-15)
    np.testing.assert_allclose(annotation.normal, [-np.sqrt(0.5), -np.sqrt(0.5)], atol=1e-14)


def test_corner_hit_off_the_path():
    # Moving along -x at height HALF + R/2 the disc clips the corner (HALF, HALF).
    height = 0.5 * R
    annotation = annotate("rect1", [0.0, 0.0, 0.0], [0.1, HALF + height], [-0.1, 0.0])
    reach = np.sqrt(R**2 - height**2)
    np.testing.assert_allclose(annotation.first_contact_fraction, (0.1 - HALF - reach) / 0.1, rtol=1e-13)
    np.testing.assert_allclose(annotation.contact_world, [HALF, HALF], atol=1e-15)
    np.testing.assert_allclose(annotation.normal, [-reach / R, -height / R], atol=1e-13)


def test_triangle_contact_relative_to_centre_of_mass():
    # tri1's frame is not its centre of mass: contact_rel_com must subtract the centroid.
    tri = get_object("tri1")
    pose = np.array([0.3, -0.2, 0.7])
    start_local = np.array([0.1, tri.centroid[1]])
    start = pose[:2] + rotation(pose[2]) @ start_local
    action = rotation(pose[2]) @ np.array([-0.1, 0.0])
    annotation = annotate(tri, pose, start, action)
    np.testing.assert_allclose(annotation.first_contact_fraction, (0.1 - HALF - R) / 0.1, rtol=1e-12)
    np.testing.assert_allclose(annotation.contact_rel_com, rotation(pose[2]) @ [HALF - tri.centroid[0], 0.0],
                               atol=1e-12)
    np.testing.assert_allclose(annotation.normal, rotation(pose[2]) @ [-1.0, 0.0], atol=1e-12)


def test_annotation_feeds_lynch_model():
    lynch = pytest.importorskip("pushjax.physics.lynch")
    tri = get_object("tri1")
    pose = np.array([0.3, -0.2, 0.7])
    start = pose[:2] + rotation(pose[2]) @ np.array([0.1, tri.centroid[1]])
    action = rotation(pose[2]) @ np.array([-0.1, 0.0])
    annotation = annotate(tri, pose, start, action)
    twist = np.asarray(lynch.predict(annotation.contact_rel_com, annotation.normal,
                                     annotation.action_from_contact, 0.04, 0.3))
    # A push through the centre of mass along the normal translates the object without turning it.
    np.testing.assert_allclose(twist[:2], annotation.action_from_contact, rtol=1e-5)
    np.testing.assert_allclose(twist[2], 0.0, atol=1e-6)


@pytest.mark.parametrize("name", ["ellip1", "ellip2", "ellip3"])
def test_ellipse_hit_is_exact_and_matches_brute_force(name):
    obj = get_object(name)
    a, b = obj.semi_axes
    angles = np.linspace(0, 2 * np.pi, 20000, endpoint=False)
    outline = shapely.Polygon(np.stack([a * np.cos(angles), b * np.sin(angles)], -1))
    rng = np.random.default_rng(1)
    for _ in range(5):
        pose = np.array([*rng.uniform(-0.1, 0.1, 2), rng.uniform(-np.pi, np.pi)])
        bearing = rng.uniform(-np.pi, np.pi)
        start = pose[:2] + 0.12 * np.array([np.cos(bearing), np.sin(bearing)])
        heading = bearing + np.pi + rng.uniform(-0.3, 0.3)
        action = 0.1 * np.array([np.cos(heading), np.sin(heading)])
        annotation = annotate(obj, pose, start, action)
        assert annotation.touches
        # Exact: the contact lies on the ellipse and the pusher centre sits r along its normal.
        contact = to_object_frame(pose, annotation.contact_world)
        centre = to_object_frame(pose, start + annotation.first_contact_fraction * action)
        outward = contact / np.array([a * a, b * b])
        outward /= np.linalg.norm(outward)
        assert abs((contact[0] / a) ** 2 + (contact[1] / b) ** 2 - 1.0) < 1e-12
        np.testing.assert_allclose(centre, contact + R * outward, atol=1e-12)
        np.testing.assert_allclose(rotation(pose[2]).T @ annotation.normal, -outward, atol=1e-12)
        # Brute force: the first of 401 samples of t within r of a 20000-gon, refined by bisection.
        world = affinity.affine_transform(outline, [*rotation(pose[2]).ravel(), *pose[:2]])
        t = np.linspace(0.0, 1.0, 401)
        distance = shapely.distance(world, shapely.points(start + t[:, None] * action))
        first = np.argmax(distance <= R)
        assert first > 0
        low, high = t[first - 1], t[first]
        for _ in range(40):
            middle = 0.5 * (low + high)
            inside = shapely.distance(world, shapely.Point(start + middle * action)) <= R
            low, high = (low, middle) if inside else (middle, high)
        assert abs(high - annotation.first_contact_fraction) * 0.1 < 1e-5
        nearest = np.asarray(shapely.shortest_line(shapely.Point(start + high * action), world.exterior).coords[1])
        np.testing.assert_allclose(annotation.contact_world, nearest, atol=1e-5)


def test_ellipse_tangent_push():
    # Along x at height b + r the disc touches the top of ellip3 at t = 0.5. A tangent is a double
    # root, which pins the angle of the contact down to about sqrt(float64 eps) only.
    a, b = get_object("ellip3").semi_axes
    annotation = annotate("ellip3", [0.0, 0.0, 0.0], [-0.1, b + R], [0.2, 0.0])
    assert annotation.touches
    np.testing.assert_allclose(annotation.first_contact_fraction, 0.5, atol=1e-6)
    np.testing.assert_allclose(annotation.contact_world, [0.0, b], atol=1e-7)
    np.testing.assert_allclose(annotation.normal, [0.0, -1.0], atol=1e-7)
    assert_no_contact(annotate("ellip3", [0.0, 0.0, 0.0], [-0.1, b + R + 1e-9], [0.2, 0.0]))


def test_butter_concavity():
    # Butter's sides at +-x curve inwards: pushing along the x axis reaches deep into the waist,
    # where a convex-hull method would stop at the hull's chord about 2 cm earlier.
    butter = get_object("butter")
    start, action = np.array([0.08, 0.0]), np.array([-0.06, 0.0])
    annotation = annotate(butter, [0.0, 0.0, 0.0], start, action)
    assert annotation.touches
    assert annotation.contact_world[0] < 0.029
    centre = start + annotation.first_contact_fraction * action
    np.testing.assert_allclose(shapely.distance(butter.polygon, shapely.Point(centre)), R, rtol=1e-12)
    hull_outline = np.asarray(shapely.orient_polygons(butter.polygon.convex_hull).exterior.coords)[:-1]
    hull = PushObject(name="butter hull", outline=hull_outline, sides=())
    hull_annotation = annotate(hull, [0.0, 0.0, 0.0], start, action)
    assert hull_annotation.first_contact_fraction < annotation.first_contact_fraction - 0.25


def random_pushes(count: int, rng):
    pose = np.concatenate([rng.uniform(-0.2, 0.2, (count, 2)), rng.uniform(-np.pi, np.pi, (count, 1))], -1)
    bearing = rng.uniform(-np.pi, np.pi, count)
    start = pose[:, :2] + rng.uniform(0.0, 0.15, (count, 1)) * np.stack([np.cos(bearing), np.sin(bearing)], -1)
    heading = bearing + np.pi + rng.uniform(-0.8, 0.8, count)
    action = rng.uniform(0.0, 0.1, (count, 1)) * np.stack([np.cos(heading), np.sin(heading)], -1)
    return pose, start, action


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_rigid_motion_invariance(name):
    rng = np.random.default_rng(2)
    pose, start, action = random_pushes(200, rng)
    annotation = annotate(name, pose, start, action)
    angle, shift = 1.234, np.array([0.5, -0.3])
    turn = rotation(angle)
    moved = annotate(name, np.concatenate([pose[:, :2] @ turn.T + shift, pose[:, 2:] + angle], -1),
                     start @ turn.T + shift, action @ turn.T)
    np.testing.assert_array_equal(moved.touches, annotation.touches)
    np.testing.assert_allclose(moved.first_contact_fraction, annotation.first_contact_fraction, atol=1e-9)
    contact = np.where(annotation.touches[:, None], annotation.contact_world @ turn.T + shift, 0.0)
    np.testing.assert_allclose(moved.contact_world, contact, atol=1e-10)
    for field in ("contact_rel_com", "normal", "action_from_contact"):
        np.testing.assert_allclose(getattr(moved, field), getattr(annotation, field) @ turn.T, atol=1e-9)


@pytest.mark.parametrize("name", OBJECT_NAMES)
def test_random_pushes_match_brute_force(name):
    """Reference: shapely distances along 401 samples of t, refined by bisection on the first touch."""
    obj = get_object(name)
    if obj.is_ellipse:
        # A 4000-gon: off the ellipse by < 3e-8 m, so its first touch is within about 1e-5 m.
        a, b = obj.semi_axes
        angles = np.linspace(0.0, 2 * np.pi, 4000, endpoint=False)
        footprint, tolerance = shapely.Polygon(np.stack([a * np.cos(angles), b * np.sin(angles)], -1)), 1e-5
    else:
        footprint, tolerance = obj.polygon, 1e-10
    pose, start, action = random_pushes(40, np.random.default_rng(3))
    annotation = annotate(obj, pose, start, action)
    t = np.linspace(0.0, 1.0, 401)
    checked = 0
    for k in range(len(pose)):
        world = affinity.affine_transform(footprint, [*rotation(pose[k, 2]).ravel(), *pose[k, :2]])
        distance = shapely.distance(world, shapely.points(start[k] + t[:, None] * action[k]))
        if abs(distance.min() - R) < 1e-5:
            continue  # a grazing touch that the samples cannot decide
        checked += 1
        touches = distance.min() <= R
        assert annotation.touches[k] == touches
        if not touches:
            continue
        first = np.argmax(distance <= R)
        low, high = (t[first - 1], t[first]) if first > 0 else (0.0, 0.0)
        for _ in range(50):
            middle = 0.5 * (low + high)
            inside = shapely.distance(world, shapely.Point(start[k] + middle * action[k])) <= R
            low, high = (low, middle) if inside else (middle, high)
        fraction = annotation.first_contact_fraction[k]
        assert abs(fraction - high) * np.linalg.norm(action[k]) < tolerance
        np.testing.assert_allclose(annotation.action_from_contact[k], (1 - fraction) * action[k], rtol=1e-12)
        # The contact is the boundary point closest to the pusher centre, r away unless touching at
        # the start, and the normal points from the centre to it (into the object).
        centre = to_object_frame(pose[k], start[k] + fraction * action[k])
        contact = to_object_frame(pose[k], annotation.contact_world[k])
        np.testing.assert_allclose(contact, nearest_boundary_point(obj, centre), atol=1e-10)
        normal = rotation(pose[k, 2]).T @ annotation.normal[k]
        if fraction > 0:
            np.testing.assert_allclose(np.linalg.norm(contact - centre), R, rtol=1e-9)
            np.testing.assert_allclose(normal, (contact - centre) / R, atol=1e-8)
    assert checked >= 35


def test_batch_shapes_broadcast():
    pose = np.zeros((3, 1, 3))
    start = np.array([[-0.1, 0.0], [-0.1, 0.2]])
    annotation = annotate("hex", pose, start, [0.1, 0.0])
    assert annotation.touches.shape == (3, 2)
    assert annotation.contact_world.shape == (3, 2, 2)
    np.testing.assert_array_equal(annotation.touches, [[True, False]] * 3)
    single = annotate("hex", [0.0, 0.0, 0.0], [-0.1, 0.0], [0.1, 0.0])
    assert single.touches.shape == () and single.normal.shape == (2,)
    empty = annotate("butter", np.zeros((0, 3)), np.zeros((0, 2)), np.zeros((0, 2)))
    assert empty.contact_world.shape == (0, 2)


def test_large_batch_crosses_chunks():
    rng = np.random.default_rng(4)
    pose, start, action = random_pushes(20000, rng)
    whole = annotate("butter", pose, start, action)
    part = annotate("butter", pose[-50:], start[-50:], action[-50:])
    for field in dataclasses.fields(whole):
        np.testing.assert_array_equal(getattr(whole, field.name)[-50:], getattr(part, field.name))


def test_zero_radius_is_a_point_pusher():
    annotation = annotate("rect1", [0.0, 0.0, 0.0], [-0.1, 0.0], [0.1, 0.0], radius=0.0)
    np.testing.assert_allclose(annotation.first_contact_fraction, 0.55)
    corner = annotate("rect1", [0.0, 0.0, 0.0], [0.1, 0.1], [-0.1, -0.1], radius=0.0)
    np.testing.assert_allclose(corner.contact_world, [HALF, HALF])


@pytest.mark.parametrize(
    "arguments, message",
    [
        (([0.0, 0.0], [0.1, 0.0], [0.1, 0.0]), "object_pose"),
        (([0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.0]), "pusher_xy"),
        (([0.0, 0.0, 0.0], [0.1, 0.0], 0.1), "action"),
        (([0.0, 0.0, np.nan], [0.1, 0.0], [0.1, 0.0]), "object_pose"),
        (([0.0, 0.0, 0.0], [np.inf, 0.0], [0.1, 0.0]), "pusher_xy"),
        (([0.0, 0.0, 0.0], [0.1, 0.0], [np.nan, 0.0]), "action"),
        (([0.0, 0.0, 0.0], [0.1, 0.0], "right"), "action"),
        ((np.zeros((2, 3)), np.zeros((3, 2)), [0.1, 0.0]), "batch shapes"),
    ],
)
def test_bad_input_raises(arguments, message):
    with pytest.raises(ValueError, match=message):
        annotate("rect1", *arguments)


def test_bad_radius_and_name_raise():
    with pytest.raises(ValueError, match="radius"):
        annotate("rect1", [0.0, 0.0, 0.0], [0.1, 0.0], [0.1, 0.0], radius=-1.0)
    with pytest.raises(ValueError, match="radius"):
        annotate("rect1", [0.0, 0.0, 0.0], [0.1, 0.0], [0.1, 0.0], radius=np.nan)
    with pytest.raises(ValueError, match="object name"):
        annotate("sphere", [0.0, 0.0, 0.0], [0.1, 0.0], [0.1, 0.0])
