"""Tests of the noise model of the loop's decisions: the sign-flip test and predictive scores."""

import numpy as np

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
