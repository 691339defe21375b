"""The studies' worlds: seeded magnitudes, and oracles that know the effect."""

import math

import numpy as np
import pytest

from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION
from pushjax.studies import worlds


def test_worlds_are_seeded_and_their_oracles_know_the_effect():
    objects = ("rect1", "tri1")
    for effect in worlds.EFFECTS:
        first, again = worlds.draw_world(effect, 3, objects), worlds.draw_world(effect, 3, objects)
        assert (first.magnitude, first.effects, first.testbed) == (again.magnitude, again.effects, again.testbed)
        assert {obj: spec.as_dict() for obj, spec in first.oracle.items()} == {
            obj: spec.as_dict() for obj, spec in again.oracle.items()}
        assert worlds.draw_world(effect, 3, objects).magnitude != worlds.draw_world(effect, 4, objects).magnitude
    tilt = worlds.draw_world("tilt", 0, objects)
    degrees, azimuth = tilt.magnitude["tilt_deg"], math.radians(tilt.magnitude["azimuth_deg"])
    assert worlds.TILT_DEG[0] <= degrees <= worlds.TILT_DEG[1] and tilt.effects["rect1"].table_tilt_deg == degrees
    drift = tilt.oracle["rect1"].params["table_tilt"]["drift_force"]
    np.testing.assert_allclose(drift, math.tan(math.radians(degrees)) / 0.13 * np.array([math.cos(azimuth),
                                                                                          math.sin(azimuth)]))
    com = worlds.draw_world("com_offset", 0, objects)
    for obj in objects:
        np.testing.assert_allclose(com.oracle[obj].params["cof_offset"]["offset"], com.effects[obj].com_offset)
    assert np.linalg.norm(com.effects["tri1"].com_offset) < np.linalg.norm(com.effects["rect1"].com_offset)
    low = worlds.draw_world("pusher_friction", 0, objects)
    assert low.oracle["rect1"].mu == low.effects["rect1"].pusher_friction < PUSHER_OBJECT_FRICTION
    spread = worlds.draw_world("friction_variability", 0, objects)
    sigma = spread.testbed.pusher_friction_sigma
    assert worlds.FRICTION_SIGMA[0] <= sigma <= worlds.FRICTION_SIGMA[1]
    assert spread.oracle["rect1"].mu == pytest.approx(PUSHER_OBJECT_FRICTION * math.exp(sigma ** 2 / 2))
