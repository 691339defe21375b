"""``leading_edge``'s load shift (pushjax.physics.effects) against the MuJoCo testbed's support normal forces."""

import numpy as np
import pytest

from pushjax import planar
from pushjax.geometry import PUSHER_RADIUS, get_object, limit_surface_ratio
from pushjax.mit.files import PushParams
from pushjax.physics import effects
from pushjax.sim.push import Simulator
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION, SURFACES


def _measured_and_predicted(surface: str, point: float):
    """([S, 2] the centre of the supports' normal forces, [S, 2] leading_edge_shift with ``lever = mu_table t / 2``),
    object axes, m, at the samples where rect1 slides under the pusher on its side 0 (the face x = +45 mm, pushed
    towards -x at 20 mm/s from ``point`` along the side)."""
    obj = get_object("rect1")
    simulator = Simulator(obj, surface)
    centres = []

    def record(sim):
        forces = sim.support_normal_forces()
        centres.append(forces @ sim.support_points / forces.sum())

    params = PushParams(surface=surface, shape="rect1", acceleration=0.0, velocity=20.0, side=0, point=point, angle=0.0)
    recording = simulator.run(params, on_step=record)
    pose, tip = recording.true_object_pose[:, 1:], recording.tip_pose[:, 1:3]
    steps_per_sample = len(centres) // (len(pose) - 1)
    centres = np.array(centres)[steps_per_sample - 1::steps_per_sample]  # [T - 1]: at the end of each sample's steps
    # The pusher's position and motion over the next sample, object axes; the contact on the face x = 45 mm.
    local_tip = planar.rotate(tip - pose[:, :2], -pose[:, 2])
    action = planar.rotate(np.diff(tip, axis=0), -pose[:-1, 2])
    contact = np.column_stack([local_tip[:-1, 0] - PUSHER_RADIUS, local_tip[:-1, 1]])
    touching = contact[:, 0] < 0.0455
    moving = np.linalg.norm(np.diff(pose[:, :2], axis=0), axis=1) > 0.5 * np.linalg.norm(np.diff(tip, axis=0), axis=1)
    sliding = touching & moving
    lever = SURFACES[surface].object_friction * obj.thickness / 2
    predicted = effects.leading_edge_shift(np.float64(lever), contact, np.array([-1.0, 0.0]), action,
                                           np.float64(limit_surface_ratio(obj)), np.float64(PUSHER_OBJECT_FRICTION))
    return centres[sliding], np.asarray(predicted)[sliding]


@pytest.mark.parametrize("surface", ["delrin", "pu"])
def test_a_central_push_moves_the_load_forward_by_mu_table_times_half_the_thickness(surface):
    # Pushed through its centre the plate slides straight: the force is the whole friction force (|f| = 1).
    measured, predicted = _measured_and_predicted(surface, point=0.5)
    assert len(measured) > 100
    expected = SURFACES[surface].object_friction * get_object("rect1").thickness / 2
    np.testing.assert_allclose(np.median(predicted, axis=0), [-expected, 0.0], atol=0.05 * expected)
    np.testing.assert_allclose(np.median(measured, axis=0), np.median(predicted, axis=0), atol=0.2 * expected)


@pytest.mark.parametrize("point", [0.2, 0.8])
def test_an_off_centre_push_moves_the_load_along_the_pushing_force(point):
    # Pushed off centre the plate turns: the force is smaller than the friction force and leans off the push, towards
    # the side of the contact (the centre of pressure moves sideways by a fifth of a millimetre in the testbed).
    measured, predicted = _measured_and_predicted("pu", point)
    assert len(measured) > 100
    full = SURFACES["pu"].object_friction * get_object("rect1").thickness / 2
    assert np.median(np.linalg.norm(predicted, axis=1)) < 0.95 * full
    measured, predicted = np.median(measured, axis=0), np.median(predicted, axis=0)
    assert np.sign(measured[1]) == np.sign(predicted[1]) == np.sign(0.5 - point) and abs(measured[1]) > 0.05 * full
    assert np.linalg.norm(measured - predicted) < 0.1 * full
