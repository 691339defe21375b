"""Tests of the noise model of the loop's decisions: the sign-flip test and predictive scores."""

import numpy as np
import pytest

from pushjax.loop import metrics


def test_sign_flip_p_values_are_exact_for_few_sequences():
    # Every one of 8 sequences improves: only the identity pattern reaches the sum, p = 2^-8.
    assert metrics.sign_flip_pvalues(np.ones((1, 8)))[0] == 2.0 ** -8 == metrics.smallest_pvalue(8)
    # Gains (3, -1): the sums over patterns are 2, 4, -4, -2; two of four reach 2.
    np.testing.assert_allclose(metrics.sign_flip_pvalues(np.array([[3.0, -1.0]])), [0.5])


def test_sign_flip_test_holds_its_level_on_noise():
    rng = np.random.default_rng(0)
    p_values = metrics.sign_flip_pvalues(rng.standard_t(3, size=(400, 40)), n_flips=2000, seed=1)
    assert 0.02 < np.mean(p_values <= 0.05) < 0.09
    assert metrics.sign_flip_pvalues(rng.normal(0.5, 1.0, size=(1, 40)), seed=1)[0] < 0.01


def test_predictive_scores_of_a_calibrated_gaussian():
    rng = np.random.default_rng(0)
    count = 20000
    std = np.column_stack([rng.uniform(1e-4, 1e-3, count), rng.uniform(1e-4, 1e-3, count),
                           rng.uniform(1e-3, 1e-2, count)])
    yaw = rng.uniform(-np.pi, np.pi, count)
    local = rng.normal(size=(count, 3)) * std
    world = np.column_stack([np.cos(yaw) * local[:, 0] - np.sin(yaw) * local[:, 1],
                             np.sin(yaw) * local[:, 0] + np.cos(yaw) * local[:, 1], local[:, 2]])
    scores = metrics.predictive_scores(np.zeros((count, 3)), std, world, yaw)
    assert abs(scores["coverage_68"] - 0.68) < 0.01 and abs(scores["coverage_95"] - 0.95) < 0.01
    too_narrow = metrics.predictive_scores(np.zeros((count, 3)), 0.5 * std, world, yaw)
    assert too_narrow["nlpd"] > scores["nlpd"] and too_narrow["coverage_95"] < 0.9


def test_conformal_multipliers_restore_the_coverage_of_a_misspecified_distribution():
    # Heavy-tailed residuals (Student t, 3 degrees of freedom) under a standard deviation 0.7 of their scale: the
    # Gaussian intervals miss; the multipliers from one half make the other half's intervals reach their level.
    rng = np.random.default_rng(1)
    count = 40000
    std = np.column_stack([np.full(count, 1e-3), np.full(count, 1e-3), np.full(count, 1e-2)])
    yaw = rng.uniform(-np.pi, np.pi, count)
    local = rng.standard_t(3, size=(count, 3)) * std / 0.7
    world = np.column_stack([np.cos(yaw) * local[:, 0] - np.sin(yaw) * local[:, 1],
                             np.sin(yaw) * local[:, 0] + np.cos(yaw) * local[:, 1], local[:, 2]])
    half = count // 2
    z = metrics.standardised_residuals(np.zeros((half, 3)), std[:half], world[:half], yaw[:half])
    np.testing.assert_allclose(z, local[:half] / std[:half], rtol=1e-9)
    multipliers = metrics.interval_multipliers(z)
    assert multipliers.shape == (2, 3) and np.all(multipliers[1] > multipliers[0])
    scores = metrics.predictive_scores(np.zeros((half, 3)), std[half:], world[half:], yaw[half:], multipliers)
    assert abs(scores["coverage_68"] - 0.68) > 0.05 or abs(scores["coverage_95"] - 0.95) > 0.05, scores
    assert abs(scores["calibrated_coverage_68"] - 0.68) < 0.01, scores
    assert abs(scores["calibrated_coverage_95"] - 0.95) < 0.01, scores


def test_random_effects_pool_agreeing_groups_and_shrink_an_imprecise_one():
    agreeing = metrics.random_effects([1.0, 1.02, 0.98], [0.1, 0.1, 0.1])
    assert agreeing.tau == 0.0 and agreeing.p_value > 0.5
    np.testing.assert_allclose(agreeing.shrunk, agreeing.mean)
    np.testing.assert_allclose(agreeing.mean, 1.0)
    # Two precise groups that differ (a real spread) and one imprecise group far out: the precise ones keep their
    # values, the imprecise one is pulled most of the way to the shared value.
    spread = metrics.random_effects([1.0, 2.0, 5.0], [0.01, 0.01, 3.0])
    assert spread.p_value < 1e-6 and 0.5 < spread.tau < 1.0
    np.testing.assert_allclose(spread.shrunk[:2], [1.0, 2.0], atol=1e-3)
    assert abs(spread.shrunk[2] - spread.mean) < 0.2 * abs(5.0 - spread.mean)
    assert np.all(spread.shrunk_std <= np.array([0.01, 0.01, 3.0]))
    # Agreeing groups borrow everything: each keeps the shared value's standard error, not zero.
    np.testing.assert_allclose(agreeing.shrunk_std, agreeing.mean_std)


def test_paule_mandel_recovers_a_large_spread_over_unequal_errors_where_dersimonian_laird_falls_short():
    # The force sensor's readings on the fresh set-up's variability_l pushes: errors of 0.0006-0.01 under a spread of
    # about 0.1, the larger readings the less precise (correlation 0.27 with the error's log).
    rng = np.random.default_rng(0)
    estimates, outside = {name: [] for name in metrics.TAU_ESTIMATORS}, {name: 0 for name in metrics.TAU_ESTIMATORS}
    for _ in range(100):
        z = rng.normal(size=120)
        std = 0.002 * np.exp(z + 0.7 * rng.normal(size=120))
        value = 0.28 + 0.1 * z + rng.normal(0, std)
        for name in metrics.TAU_ESTIMATORS:
            pooled = metrics.random_effects(value, std, estimator=name)
            estimates[name].append(pooled.tau)
            outside[name] += not pooled.tau_interval[0] <= pooled.tau <= pooled.tau_interval[1]
    assert abs(np.mean(estimates["paule_mandel"]) / 0.1 - 1) < 0.03 and outside["paule_mandel"] == 0
    assert np.mean(estimates["dersimonian_laird"]) < 0.9 * 0.1 and outside["dersimonian_laird"] > 50
    # With equal errors the two are the same moment estimate: the values' variance less the error's.
    value, std = rng.normal(1.0, 0.4, 40), np.full(40, 0.1)
    taus = [metrics.random_effects(value, std, estimator=name).tau for name in metrics.TAU_ESTIMATORS]
    np.testing.assert_allclose(taus, np.sqrt(np.var(value, ddof=1) - 0.01), rtol=1e-6)
    with pytest.raises(ValueError, match="estimator: expected one of dersimonian_laird, paule_mandel, got 'reml'"):
        metrics.random_effects(value, std, estimator="reml")


def test_holm_steps_down_from_the_smallest_p_value():
    rejected, levels = metrics.holm(np.array([0.04, 0.001, 0.015, 0.3]), alpha=0.05)
    np.testing.assert_allclose(levels, [0.05 / 2, 0.05 / 4, 0.05 / 3, 0.05])
    # 0.001 <= 0.0125 and 0.015 <= 0.0167 pass; 0.04 > 0.025 stops the procedure, so 0.3 fails too.
    np.testing.assert_array_equal(rejected, [False, True, True, False])
    # Bonferroni would keep only the smallest; Holm passes every p-value below its level in turn.
    assert metrics.holm(np.array([0.01, 0.02]), alpha=0.05)[0].all()


def _repeated_windows(rng, sequences, repeats, windows, spread):
    """Targets of `repeats` pushes per sequence whose windows share an expected motion, plus Gaussian spread."""
    expected = rng.normal(0, [5e-3, 5e-3, 0.05], size=(sequences, windows, 3))
    target = expected[:, None] + rng.normal(size=(sequences, repeats, windows, 3)) * spread
    index = np.indices((sequences, repeats, windows)).reshape(3, -1)
    return target.reshape(-1, 3), expected[index[0], index[2]], index[0], index[0] * repeats + index[1], index[2]


def test_noise_floor_from_repeats_is_the_error_of_the_true_expected_motion():
    rng = np.random.default_rng(0)
    spread = np.array([4e-4, 4e-4, 0.004])
    target, expected, sequence, push, window = _repeated_windows(rng, 60, 3, 8, spread)
    floor = metrics.noise_floor(target, sequence, push, window, np.zeros((len(target), 3)))
    oracle = metrics.summarize(metrics.window_errors(expected, target, sequence))
    assert floor.source == "repeats" and floor.n_windows == len(target)
    assert abs(floor.trans_percent - oracle["trans_percent"]) < 0.05 * oracle["trans_percent"]
    assert abs(floor.rot_percent - oracle["rot_percent"]) < 0.05 * oracle["rot_percent"]
    for key in ("trans_percent", "rot_percent"):
        low, high = floor.interval[key]
        assert low < getattr(floor, key) < high


def test_noise_floor_without_repeats_comes_from_the_tracking_noise():
    rng = np.random.default_rng(1)
    noise = np.array([3e-4, 3e-4, 0.003])
    target, expected, sequence, push, window = _repeated_windows(rng, 80, 1, 8, np.zeros(3))
    # Each target is the difference of two poses with white noise: sqrt(2) times the per-pose noise per axis.
    measured = target + rng.normal(size=target.shape) * np.sqrt(2) * noise
    floor = metrics.noise_floor(measured, sequence, push, window, np.broadcast_to(noise, target.shape))
    oracle = metrics.summarize(metrics.window_errors(expected, measured, sequence))
    assert floor.source == "tracking"
    assert abs(floor.trans_percent - oracle["trans_percent"]) < 0.1 * oracle["trans_percent"]
    assert abs(floor.rot_percent - oracle["rot_percent"]) < 0.1 * oracle["rot_percent"]


@pytest.mark.parametrize("tau", [0.0, 0.5])
def test_random_effects_spread_interval_covers_the_true_spread(tau):
    rng = np.random.default_rng(0)
    std = rng.uniform(0.2, 0.4, 30)
    intervals = np.array([metrics.random_effects(rng.normal(1.0, tau, 30) + rng.normal(0, std), std).tau_interval
                          for _ in range(300)])
    covered = np.mean((intervals[:, 0] <= tau) & (tau <= intervals[:, 1]))
    assert 0.92 < covered <= 0.98 if tau else covered >= 0.95
    if not tau:  # groups that differ by their errors alone: the interval reaches zero
        assert np.mean(intervals[:, 0] == 0) >= 0.95
