"""Every model variant trains on the smoke data without NaN, lowers its loss and evaluates to finite errors
(its own file: the longest of the trainer's tests, run beside the others on another pytest-xdist worker)."""

import csv
import dataclasses

import jax
import numpy as np
import pytest

from pushjax import train
from pushjax.models import VARIANTS
from tests.tiny_configs import TINY_SMOKE as SMOKE

ERROR_VARIANTS = ("error", "error_grad", "error_norm")
VARIANT_SWEEPS = [(variant,) for variant in VARIANTS if variant not in ERROR_VARIANTS] + [ERROR_VARIANTS]
"""Every variant once; the three error variants share one model and so one sweep (per-model error options)."""
NUM_STEPS = 100
"""Half the smoke config's: every variant lowers its loss by at least 30 % in it (by 49-79 % on 2026-11-26)."""


@pytest.mark.parametrize("variants, view", [(variants, "top_down") for variants in VARIANT_SWEEPS] + [(("hybrid",), "free")])
def test_every_variant_learns_without_nan(variants, view, smoke, smoke_viewpoint, tmp_path):
    splits = smoke_viewpoint if view == "free" else smoke
    examples = splits["train"]
    size = len(examples["motion"])
    specs = train.subset_specs(size, [size], [0], variants if len(variants) > 1 else (None,))
    losses = []
    result = train.sweep(
        dataclasses.replace(SMOKE.with_variant(variants[0], view), num_steps=NUM_STEPS), examples, specs, tmp_path,
        progress=False, step_callback=lambda step, metrics: losses.append(np.asarray(metrics["loss"])),
    )
    losses = np.stack(losses)  # [steps, models]
    assert losses.shape == (NUM_STEPS, len(variants)) and np.all(np.isfinite(losses))
    assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree.leaves(result.state))
    assert np.all(losses[-20:].mean(0) <= 0.7 * losses[:5].mean(0)), (losses[:5], losses[-20:])
    with (tmp_path / "metrics.csv").open() as file:
        rows = list(csv.DictReader(file))
    assert sorted({int(row["step"]) for row in rows}) == list(range(20, NUM_STEPS + 1, 20))
    assert len(rows) == NUM_STEPS // 20 * len(variants)
    for metrics in result.evaluate(splits["test"], batch_size=64):
        assert np.isfinite(metrics["trans_percent"]) and np.isfinite(metrics["rot_percent"])
    np.testing.assert_array_equal(result.steps_trained, [NUM_STEPS] * len(variants))
