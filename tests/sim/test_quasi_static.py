"""Slow simulated pushes agree with the quasi-static model of Lynch et al. (pushjax.physics.lynch)."""

import numpy as np

from pushjax.sim.quasi_static import quasi_static_agreement


def test_slow_pushes_are_quasi_static():
    """20 mm/s, distributed support: median prediction error below 25 % of the median motion."""
    agreement = quasi_static_agreement("rect1", "abs", pushes=25, windows_per_push=10, seed=0)
    assert len(agreement.simulated) >= 200
    assert agreement.median_motion > 1e-3
    assert agreement.relative_error < 0.25
    # The model and the simulation agree on the direction, too.
    moving = np.linalg.norm(agreement.simulated, axis=1) > 1e-3
    simulated, predicted = agreement.simulated[moving], agreement.predicted[moving]
    cosine = np.sum(simulated * predicted, axis=1) / (
        np.linalg.norm(simulated, axis=1) * np.linalg.norm(predicted, axis=1) + 1e-12)
    assert np.median(cosine) > 0.98
