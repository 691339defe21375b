import csv
import dataclasses

import jax
import numpy as np
import pytest

from pushjax.models import VARIANTS
from pushjax.train import evaluate, train
from pushjax.train.configs import get_config

SMOKE = get_config("smoke")


@pytest.fixture(scope="module")
def examples(smoke):
    return smoke["train"]


def _config(variant="hybrid", view="top_down", **changes):
    return dataclasses.replace(SMOKE.with_variant(variant, view), **changes)


def _params(result):
    return jax.tree.map(np.asarray, result.state.params)


def test_batch_order_walks_through_permuted_epochs():
    spec = train.ModelSpec("m", np.arange(100, 110), seed=3)
    batches = np.concatenate([train.batch_indices(spec, step, 4) for step in range(5)])
    assert sorted(batches[:10]) == list(range(100, 110))  # epoch 0
    assert sorted(batches[10:20]) == list(range(100, 110))  # epoch 1
    assert not np.array_equal(batches[:10], batches[10:20])
    np.testing.assert_array_equal(train.batch_indices(spec, 3, 4), batches[12:16])


def test_subset_specs():
    specs = train.subset_specs(50, sizes=[10, 20], seeds=[0, 1])
    assert [len(spec.train_indices) for spec in specs] == [10, 10, 20, 20]
    assert not np.array_equal(specs[0].train_indices, specs[1].train_indices)
    assert all(len(np.unique(spec.train_indices)) == len(spec.train_indices) for spec in specs)
    with pytest.raises(ValueError, match="sizes"):
        train.subset_specs(50, sizes=[51], seeds=[0])


@pytest.mark.parametrize(
    "variant, view", [(variant, "top_down") for variant in VARIANTS] + [("hybrid", "free")]
)
def test_every_variant_learns_without_nan(variant, view, smoke, smoke_viewpoint, tmp_path):
    splits = smoke_viewpoint if view == "free" else smoke
    examples = splits["train"]
    losses = []
    result = train.sweep(
        _config(variant, view), examples, train.subset_specs(len(examples["motion"]), [len(examples["motion"])], [0]), tmp_path,
        progress=False,
        step_callback=lambda step, metrics: losses.append(np.asarray(metrics["loss"])),
    )
    losses = np.concatenate(losses)
    assert len(losses) == 200 and np.all(np.isfinite(losses))
    assert all(np.all(np.isfinite(leaf)) for leaf in jax.tree.leaves(result.state))
    assert losses[-20:].mean() <= 0.7 * losses[:5].mean(), (losses[:5], losses[-20:])
    with (tmp_path / "metrics.csv").open() as file:
        rows = list(csv.DictReader(file))
    assert [int(row["step"]) for row in rows] == list(range(20, 201, 20))
    metrics = evaluate.evaluate_sweep(result, splits["test"], batch_size=64)[0]
    assert np.isfinite(metrics["trans_percent"]) and np.isfinite(metrics["rot_percent"])


def test_vmapped_sweep_equals_separate_runs(examples):
    config = _config("error", num_steps=12)
    specs = [
        train.ModelSpec("a", np.arange(0, 40), seed=0, variant="error"),
        train.ModelSpec("b", np.arange(50, 110), seed=1, variant="error_grad"),
        train.ModelSpec("c", np.arange(100, 140), seed=2, variant="error_norm"),
    ]
    separate = train.sweep(config, examples, specs, mode="sequential", progress=False)
    vmapped = train.sweep(config, examples, specs, mode="vmap", progress=False)
    unrolled = train.sweep(config, examples, specs, mode="unroll", progress=False)
    # Adam turns float-rounding differences of near-zero gradients into differences of up to a step
    # (learning rate 1e-3), hence the absolute tolerance of a tenth of one step.
    for together in (vmapped, unrolled):
        jax.tree.map(
            lambda a, b: np.testing.assert_allclose(a, b, rtol=1e-3, atol=1e-4), _params(together),
            _params(separate),
        )
    # The models differ, so the comparison is not trivially true.
    kernel = jax.tree.leaves(_params(vmapped))[0]
    assert not np.allclose(kernel[0], kernel[1])


class Killed(Exception):
    pass


@pytest.mark.parametrize("mode", ["vmap", "sequential"])
def test_killed_training_resumes_to_the_uninterrupted_parameters(mode, examples, tmp_path):
    config = _config("hybrid", num_steps=30, checkpoint_every=10, log_every=5)
    specs = train.subset_specs(256, [30, 100], [4])
    uninterrupted = train.sweep(config, examples, specs, tmp_path / "full", mode=mode, progress=False)

    def kill_at_step_23(step, metrics):
        if step == 23:
            raise Killed

    with pytest.raises(Killed):
        train.sweep(config, examples, specs, tmp_path / "killed", mode=mode, progress=False,
                    step_callback=kill_at_step_23)
    resumed_steps = []
    resumed = train.sweep(
        config, examples, specs, tmp_path / "killed", mode=mode, progress=False,
        step_callback=lambda step, metrics: resumed_steps.append(step),
    )
    assert resumed_steps[0] == 21  # restarted after the checkpoint at step 20
    jax.tree.map(np.testing.assert_array_equal, _params(resumed), _params(uninterrupted))
    jax.tree.map(
        np.testing.assert_array_equal, jax.tree.map(np.asarray, resumed.state.batch_stats),
        jax.tree.map(np.asarray, uninterrupted.state.batch_stats),
    )
    with (tmp_path / "killed" / "metrics.csv").open() as file:
        steps = [int(row["step"]) for row in csv.DictReader(file)]
    assert steps == [step for step in range(5, 31, 5) for _ in specs]

    with pytest.raises(ValueError, match="different models"):
        train.sweep(config, examples, train.subset_specs(256, [30], [5]), tmp_path / "killed", progress=False)


def test_error_metrics_against_the_zero_baseline(examples):
    zero = {"motion": np.zeros_like(examples["motion"])}
    metrics = evaluate.error_metrics(zero, examples)
    assert metrics["trans_percent"] == pytest.approx(100.0)
    assert metrics["rot_percent"] == pytest.approx(100.0)
    perfect = {name: examples[name] for name in ("motion", "object_pos", "contact", "normal")}
    perfect["s"] = examples["contact_flag"]
    metrics = evaluate.error_metrics(perfect, examples)
    for name in ("trans_percent", "rot_percent", "pos_mm", "contact_mm", "normal_deg", "s"):
        assert metrics[name] == pytest.approx(0.0, abs=1e-3), name
    assert metrics["push_velocity_deg"] < 0.1
