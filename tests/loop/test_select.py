"""Tests of forward selection's decisions that need no fit (``pushjax.loop.select``)."""

import numpy as np

from pushjax.loop import select


def test_rivals_are_the_passing_candidates_the_accepted_one_does_not_beat():
    rng = np.random.default_rng(0)
    accepted = 1.0 + 0.1 * rng.standard_normal(40)
    per_sequence = np.stack([
        accepted,
        accepted + 0.05 * rng.standard_normal(40),  # the same gain up to noise: a rival
        accepted - 0.5,  # smaller in every sequence: beaten
        accepted + 0.05 * rng.standard_normal(40),  # as good, but not beyond noise or the floor: not a candidate
    ])
    points = per_sequence.sum(axis=1)
    points[1] = min(points[1], points[0])  # a rival has the smaller total by construction of the round
    rivals = select._rivals(per_sequence, points, np.array([0, 1, 2]), 0, ["a", "b", "c", "d"], alpha=0.05, seed=0)
    assert list(rivals) == ["b"] and rivals["b"] > 0.05
    assert select._rivals(per_sequence, points, np.array([0, 1, 2]), None, ["a", "b", "c", "d"], 0.05, 0) == {}
    assert select._rivals(per_sequence, points, np.array([0]), 0, ["a", "b", "c", "d"], 0.05, 0) == {}
