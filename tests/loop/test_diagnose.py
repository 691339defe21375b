"""Tests of the residual diagnosis on synthetic residuals of known structure."""

import numpy as np
import pytest

from pushjax.loop import diagnose
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes


@pytest.fixture(scope="module")
def examples(record):
    return build_examples(iter_pushes(record("clean")))[0]


def _noisy_prediction(examples, seed):
    """The target plus noise that is independent of every variable (one draw per window)."""
    rng = np.random.default_rng(seed)
    return examples.target + rng.normal(size=examples.target.shape) * np.array([5e-4, 5e-4, np.radians(0.5)])


def test_a_residual_that_depends_on_the_push_angle_is_found(examples):
    prediction = _noisy_prediction(examples, 0)
    # The model misses a rotation proportional to the push angle: 1 deg per 20 deg.
    prediction[:, 2] -= np.radians(examples.variables["push angle"] / 20.0)
    variables = ["push angle", "contact position along the side", "pushed side", "time in the push"]
    result = diagnose.diagnose(examples, prediction, variables, n_bootstrap=300)
    assert result[0].variable == "push angle" and result[0].beyond_noise
    assert result[0].strength > 0.3
    assert not any(d.beyond_noise for d in result[1:])


def test_noise_alone_is_not_structure(examples):
    variables = ["push angle", "contact position along the side", "pushed side", "object orientation in the world",
                 "time in the push", "contact versus no contact", "push direction in the world"]
    result = diagnose.diagnose(examples, _noisy_prediction(examples, 1), variables, n_bootstrap=300)
    assert not any(d.beyond_noise for d in result)
    assert all(d.strength < 0.05 for d in result)
    assert [d.strength for d in result] == sorted((d.strength for d in result), reverse=True)


def test_fold_count_is_checked(examples):
    with pytest.raises(ValueError, match="folds"):
        diagnose.diagnose(examples, examples.target, ["push angle"], folds=1)
