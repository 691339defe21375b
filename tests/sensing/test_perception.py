"""pushjax.sensing.perception: the trained network's position readings of rendered scenes."""

from pathlib import Path

import numpy as np
import pytest

from pushjax.data import configs as data_configs
from pushjax.sensing import perception

MODEL = Path(__file__).resolve().parents[2] / "results" / "track_perception" / "model"


@pytest.fixture(scope="module")
def sensor():
    return perception.load(MODEL, data_configs.get_config("data_efficiency", "cpu_full"))


def test_a_reading_does_not_depend_on_the_batch_it_is_read_in(sensor):
    # 35 scenes: a full batch of 32 and a batch of 3 padded to 4; each reading alone is padded to nothing.
    rng = np.random.default_rng(0)
    poses = np.column_stack([rng.uniform(-0.02, 0.02, (35, 2)), rng.uniform(-0.5, 0.5, 35)])
    pushers = poses[:, :2] + np.array([-0.07, 0.0])
    together = sensor.locate("rect1", poses, pushers)
    assert together.shape == (35, 2)
    alone = np.concatenate([sensor.locate("rect1", poses[i:i + 1], pushers[i:i + 1]) for i in (0, 31, 32, 34)])
    np.testing.assert_allclose(together[[0, 31, 32, 34]], alone, atol=1e-5)
    assert sensor.locate("rect1", np.zeros((0, 3)), np.zeros((0, 2))).shape == (0, 2)


def test_bad_shapes_name_both_arguments(sensor):
    with pytest.raises(ValueError, match=r"poses, pushers: expected \[N, 3\] and \[N, 2\]"):
        sensor.locate("rect1", np.zeros((2, 2)), np.zeros((2, 2)))
