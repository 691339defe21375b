"""Candidate contacts lie on the outline with inward normals; the best candidate for a goal ahead pushes from
behind; the detour to another side never touches the object."""

import jax.numpy as jnp
import numpy as np
import pytest
import shapely

from pushjax.control import contact, cost, model
from pushjax.geometry.objects import PUSHER_RADIUS, get_object
from pushjax.studies import episode


@pytest.mark.parametrize("name", ["rect1", "ellip2", "butter"])
def test_candidates_lie_on_the_outline_with_inward_normals(name):
    shape = model.make_model(name).shape
    points, normals = (np.asarray(value, np.float64) for value in contact.candidates(shape, 24))
    polygon = shapely.Polygon(get_object(name).outline)
    assert max(polygon.exterior.distance(shapely.Point(p)) for p in points) < 1e-6
    np.testing.assert_allclose(np.linalg.norm(normals, axis=-1), 1.0, atol=1e-6)
    assert all(polygon.contains(shapely.Point(p + 1e-4 * n)) for p, n in zip(points, normals))
    pose = np.array([0.1, -0.05, 0.7])
    approach, _ = contact.approach_points(shape, jnp.asarray(pose, jnp.float32), points, normals, 0.008)
    local = np.asarray(contact.rotate(jnp.asarray(approach) - pose[:2], -pose[2]))
    distances = [polygon.exterior.distance(shapely.Point(p)) for p in local]
    np.testing.assert_allclose(distances, 0.008, atol=2e-5)


def test_a_goal_straight_ahead_is_pushed_from_behind():
    push_model = model.make_model("rect1")
    costs, approach, normals, plans = contact.score_candidates(
        push_model, jnp.zeros(3), jnp.array([0.04, 0.0, 0.0]), 10, 0.004, cost.CostWeights(), 16, 3, 0.4, 0.003, (10,))
    assert costs.shape == (16, 3) and plans.shape == (16, 3, 10, 2)
    best = int(jnp.argmin(costs)) // 3
    np.testing.assert_allclose(normals[best], [1.0, 0.0], atol=1e-6)  # the -x side, pushing along +x
    assert float(approach[best, 0]) < -0.045


@pytest.mark.parametrize("name, target_index", [("rect1", 5), ("tri2", 9), ("ellip2", 12)])
def test_the_detour_does_not_touch_the_object(name, target_index):
    push_model = model.make_model(name)
    pose = jnp.array([0.02, 0.01, 0.4])
    points, normals = contact.candidates(push_model.shape, 16)
    approach, world_normals = contact.approach_points(push_model.shape, pose, points, normals,
                                                      PUSHER_RADIUS + 0.003)
    pusher = approach[0] + 0.002 * world_normals[0]  # touching the first candidate's side
    waypoints = contact.detour(push_model.shape, pose, pusher, approach[target_index], world_normals[target_index],
                               push_model.radius, 0.01, 16)
    np.testing.assert_allclose(waypoints[-1], approach[target_index])
    path = episode.waypoint_targets(np.asarray(pusher), np.asarray(waypoints), 5e-4, 1)
    path = jnp.asarray(np.concatenate([np.asarray(pusher)[None], path]), jnp.float32)
    steps = model.predict(push_model, pose, path).steps
    assert not bool(steps.touches[1:].any())  # only the first step, leaving the contact, touches
