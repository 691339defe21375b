"""Push-to-push variability (pushjax.loop.variability): the spread of the pusher friction over pushes, apart from the
force sensor's measurement noise, on realistic testbed pushes whose pusher friction is drawn per push."""

import math

import numpy as np
import pytest

from pushjax.loop import variability
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.sim.dataset import RecordingConfig, record_pushes
from pushjax.sim.testbed import IDEAL, REALISTIC


@pytest.mark.parametrize("profile, sigma", [(IDEAL, 0.0), (REALISTIC, 0.0), (REALISTIC, 0.4)])
def test_the_pusher_friction_spread_is_recovered_from_the_force_sensor(profile, sigma, tmp_path):
    # 40 pushes of rect1 on pu at 20 mm/s, on the realistic testbed with every other mechanism (pressure, friction
    # fields, tracking noise); about 30 of them slide long enough for a reading with a standard error. Without tracking
    # noise (ideal) the readings of one coefficient scatter more than their samples do: the floor of their error.
    testbed = profile.with_overrides(f"pusher_friction_sigma={sigma}")
    record_pushes(tmp_path, ["rect1"], ["pu"], 40, RecordingConfig(seed=0, velocities=(20.0,), testbed=testbed),
                  workers=1, progress=False)
    examples, _ = build_examples(iter_pushes(tmp_path))
    found = variability.measure(examples)["pusher_friction"]
    assert found.n_pushes >= 25 and found.measurement_relative_sd < 0.02
    true = math.sqrt(math.exp(sigma ** 2) - 1)  # the log-normal draw's relative standard deviation
    if sigma == 0:
        assert found.interval[0] == 0.0 and found.relative_sd < 0.01
    else:
        assert found.relative_sd == pytest.approx(true, rel=0.25)
        assert found.interval[0] < true < found.interval[1]
        # The windows' motion varies with it where the pusher slides along the object, and not without contact.
        spread = variability.window_spread(None, examples, {"pusher_friction": found})
        assert np.all(spread[np.asarray(examples.inputs.s) == 0] == 0) and np.any(spread > 1e-4)
    assert variability.window_spread(None, examples, {}).tolist() == np.zeros((len(examples), 3)).tolist()


def test_readings_without_a_standard_error_are_left_out_and_too_few_give_none():
    value = np.array([0.25, 0.26, np.nan, 0.24, 0.25, 0.27, 0.23, 0.25, 0.26, 0.3])
    std = np.array([0.01, 0.01, np.nan, 0.01, 0.01, 0.01, 0.01, 0.01, np.nan, 0.01])
    found = variability.spread(value, std, "test")
    assert found.n_pushes == 8 and found.source == "test"
    assert variability.spread(value[:8], std[:8], "test") is None  # 7 readings with a standard error
