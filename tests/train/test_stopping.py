"""The trend stopping rule: it stops flat noisy curves and keeps training curves that still fall."""

import numpy as np
import pytest

from pushjax.train import stopping


def _curve(gain_per_10k, noise, steps=40, seed=0):
    """Scores every 1 000 steps falling by `gain_per_10k` points per 10 000 steps, with Gaussian `noise`."""
    rng = np.random.default_rng(seed)
    x = np.arange(1, steps + 1) * 1_000
    return x, 40.0 - gain_per_10k * x / 10_000 + rng.normal(0.0, noise, x.shape)


def test_trend_recovers_the_slope_and_its_standard_error():
    rule = stopping.TrendRule()
    x = np.arange(1, 21) * 1_000
    trend = rule.trend(x, 30.0 - 0.2 * x / 1_000)  # exactly 2 points per 10 000 steps
    assert trend is None  # 19 000 steps: the window is not spanned yet
    x = np.arange(0, 21) * 1_000
    trend = rule.trend(x, 30.0 - 0.2 * x / 1_000)
    assert trend.evaluations == 21 and trend.gain == pytest.approx(2.0) and trend.gain_se == pytest.approx(0.0)
    assert rule.stops(x, 30.0 + 0 * x) and not rule.stops(x, 30.0 - 0.2 * x / 1_000)


def test_the_rule_stops_noise_and_not_a_falling_curve():
    rule = stopping.RULE
    # Flat curves with the noise seen between evaluations (0.3-0.8 points): stopped once the window is spanned, at
    # most seeds.
    flat = [rule.first_stop(*_curve(0.0, 0.5, seed=seed)) for seed in range(20)]
    assert sum(stop is not None for stop in flat) >= 15
    assert all(stop is None or stop >= 20_000 for stop in flat)
    # Falling by 1.3 points per 10 000 steps (neural at 190 080 when the criterion stopped it): never stopped.
    assert all(rule.first_stop(*_curve(1.3, 0.5, seed=seed)) is None for seed in range(20))
    x, y = _curve(1.3, 0.5, seed=3)
    trend = rule.trend(x, y)
    assert trend.gain_lower > 0 and trend.gain_lower < 1.3 < trend.gain_upper


def test_long_run_continues_when_any_seed_still_falls():
    flat, falling = _curve(0.0, 0.3, seed=1), _curve(2.0, 0.3, seed=2)
    assert stopping.long_run_continues([flat, falling]) and not stopping.long_run_continues([flat, flat])


def test_bad_rule_and_curves():
    with pytest.raises(ValueError, match="max_gain: expected > 0"):
        stopping.TrendRule(max_gain=0.0)
    with pytest.raises(ValueError, match="min_evaluations: a trend's uncertainty needs at least 3"):
        stopping.TrendRule(min_evaluations=2)
    with pytest.raises(ValueError, match="steps and scores: expected two"):
        stopping.RULE.trend([1, 2], [1.0])
