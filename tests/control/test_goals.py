"""Goals within their ranges and reproducible per object; the success criterion; Wilson intervals."""

import math

import numpy as np
import pytest

from pushjax.control import goals


def test_goals_are_in_range_and_reproducible_per_object():
    drawn = goals.draw_goals(["rect1", "tri2"], 20, seed=3)
    assert [(g.obj, g.index) for g in drawn[:2]] == [("rect1", 0), ("rect1", 1)] and len(drawn) == 40
    for goal in drawn:
        assert goal.start == (0.0, 0.0, 0.0)
        assert goals.TRANSLATION_RANGE[0] <= math.hypot(*goal.goal[:2]) <= goals.TRANSLATION_RANGE[1]
        assert abs(math.degrees(goal.goal[2])) <= goals.MAX_ROTATION_DEG
    assert goals.draw_goals(["tri2"], 20, seed=3) == drawn[20:]  # another object's goals do not change them
    assert goals.draw_goals(["tri2"], 20, seed=4) != drawn[20:]
    with pytest.raises(ValueError, match="per_object"):
        goals.draw_goals(["rect1"], 0, seed=0)


def test_success_criterion():
    assert goals.succeeded(0.0049, math.radians(-4.9))
    assert not goals.succeeded(0.0051, 0.0)
    assert not goals.succeeded(0.0, math.radians(5.1))


def test_wilson_interval_known_values():
    np.testing.assert_allclose(goals.wilson_interval(5, 10), (0.2366, 0.7634), atol=1e-4)
    np.testing.assert_allclose(goals.wilson_interval(0, 10), (0.0, 0.2775), atol=1e-4)
    np.testing.assert_allclose(goals.wilson_interval(10, 10), (0.7225, 1.0), atol=1e-4)
    assert goals.wilson_interval(0, 0) == (0.0, 1.0)
