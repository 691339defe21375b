"""One name per metric: the closed loop's summaries use evaluation's names (`pushjax.train.evaluate`)."""

import numpy as np

from pushjax import stats
from pushjax.loop import metrics as loop_metrics
from pushjax.train import evaluate


def test_the_loop_and_evaluation_name_their_metrics_alike():
    rng = np.random.default_rng(0)
    motion = rng.normal(size=(6, 3))
    evaluated = evaluate.error_metrics({"motion": motion + 0.1}, {"motion": motion, "contact_flag": np.ones(6)})
    summary = loop_metrics.summarize(loop_metrics.window_errors(motion + 0.1, motion, np.arange(6)))
    assert set(loop_metrics.METRIC_KEYS) <= set(evaluated) and set(summary) == set(loop_metrics.METRIC_KEYS)
    for name in ("trans_percent", "rot_percent"):
        assert name in stats.SEQUENCE_RATIOS
        np.testing.assert_allclose(summary[name], evaluated[name], rtol=1e-9)
