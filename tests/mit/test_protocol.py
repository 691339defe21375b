"""Tests for pushjax.mit.protocol: the MIT grid and the pusher's path and motion."""

import numpy as np
import pytest

from pushjax.geometry import PUSHER_RADIUS, get_object
from pushjax.mit import protocol
from pushjax.mit.files import PushParams


def params(shape="rect1", side=0, point=0.5, angle=0.0, velocity=20.0, acceleration=0.0, surface="abs"):
    return PushParams(surface=surface, shape=shape, acceleration=acceleration, velocity=velocity, side=side,
                      point=point, angle=angle)


def test_sample_push_draws_from_the_mit_grid():
    rng = np.random.default_rng(0)
    drawn = [protocol.sample_push("hex", "pu", rng, velocities=(20.0, 50.0), accelerations=(0.0, 500.0))
             for _ in range(1000)]
    assert {p.side for p in drawn} == set(range(6))
    assert {p.point for p in drawn} == {k / 10 for k in range(11)}
    assert {p.angle for p in drawn} == {round(a, 3) for a in protocol.MIT_ANGLES}
    assert {p.velocity for p in drawn} == {20.0, 50.0} and {p.acceleration for p in drawn} == {0.0, 500.0}
    assert all(p.surface == "pu" and p.shape == "hex" for p in drawn)
    again = protocol.sample_push("hex", "pu", np.random.default_rng(0), velocities=(20.0, 50.0),
                                 accelerations=(0.0, 500.0))
    assert again == drawn[0]
    assert set(protocol.side_points("ellip1")) == {k / 10 for k in range(10)}
    assert len(protocol.side_points("tri2")) == 11


def test_pusher_line_starts_before_the_contact():
    obj = get_object("tri2")
    p = params("tri2", side=1, point=0.3, angle=0.5)
    start, direction = protocol.pusher_line(obj, p)
    point, inward = obj.side_point(1, 0.3)
    assert np.linalg.norm(direction) == pytest.approx(1.0)
    assert direction @ inward == pytest.approx(np.cos(0.5))
    assert inward[0] * direction[1] - inward[1] * direction[0] == pytest.approx(np.sin(0.5))
    np.testing.assert_allclose(start + protocol.APPROACH_DISTANCE * direction, point - PUSHER_RADIUS * inward)


def test_pusher_motion_constant_and_accelerating():
    constant = params(velocity=50.0)
    distance, speed = protocol.pusher_motion(constant, np.array([0.0, 0.5, 2.0]))
    np.testing.assert_allclose(distance, [0.0, 0.025, protocol.APPROACH_DISTANCE + protocol.PUSH_DISTANCE])
    np.testing.assert_allclose(speed, [0.05, 0.05, 0.0])
    accelerating = params(velocity=300.0, acceleration=500.0)
    distance, speed = protocol.pusher_motion(accelerating, np.array([0.0, 0.2, 10.0]))
    np.testing.assert_allclose(distance, [0.0, 0.5 * 0.5 * 0.2 ** 2, 0.053])
    np.testing.assert_allclose(speed, [0.0, 0.1, 0.0])
    assert protocol.push_duration(accelerating) == pytest.approx(np.sqrt(2 * 0.053 / 0.5))
