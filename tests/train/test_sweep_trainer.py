import csv
import dataclasses
import warnings

import jax
import numpy as np
import pytest

from pushjax import train
from tests.tiny_configs import TINY_SMOKE as SMOKE


def _config(variant="hybrid", view="top_down", **changes):
    return dataclasses.replace(SMOKE.with_variant(variant, view), **changes)


def _params(result):
    return jax.tree.map(np.asarray, result.state.params)


ERROR_SPECS = [
    train.ModelSpec("a", np.arange(0, 40), seed=0, variant="error"),
    train.ModelSpec("b", np.arange(50, 110), seed=1, variant="error_grad"),
    train.ModelSpec("c", np.arange(100, 140), seed=2, variant="error_norm"),
]
"""Three models of the three error variants; every test of this file trains them (or some of them) with the error
model's steps, so the file compiles one single-model step, one vmapped step of 3 and one unrolled step of 2."""


def test_vmapped_sweep_equals_separate_runs(examples):
    config = _config("error", num_steps=12)
    specs = ERROR_SPECS
    separate = train.sweep(config, examples, specs, mode="sequential", progress=False)
    vmapped = train.sweep(config, examples, specs, mode="vmap", progress=False)
    # Unrolled over two of the models: compiling the unrolled step costs a compilation per model.
    unrolled = train.sweep(config, examples, specs[:2], mode="unroll", progress=False)
    # Adam turns float-rounding differences of near-zero gradients into differences of up to a step
    # (learning rate 1e-3), hence the absolute tolerance of a tenth of one step.
    for together in (vmapped, unrolled):
        count = len(together.specs)
        jax.tree.map(
            lambda a, b: np.testing.assert_allclose(a, b[:count], rtol=1e-3, atol=1e-4), _params(together),
            _params(separate),
        )
    # The models differ, so the comparison is not trivially true.
    kernel = jax.tree.leaves(_params(vmapped))[0]
    assert not np.allclose(kernel[0], kernel[1])
    for result in (separate, vmapped, unrolled):
        np.testing.assert_array_equal(result.steps_trained, [12] * len(result.specs))
        assert result.final_metrics["loss"].shape == (len(result.specs),)


class Killed(Exception):
    pass


@pytest.mark.parametrize("mode", ["vmap", "sequential"])
def test_killed_training_resumes_to_the_uninterrupted_parameters(mode, examples, tmp_path):
    config = _config("error", num_steps=12, checkpoint_every=4, log_every=2)
    specs = ERROR_SPECS
    uninterrupted = train.sweep(config, examples, specs, tmp_path / "full", mode=mode, progress=False)

    def kill_at_step_9(step, metrics):
        if step == 9:
            raise Killed

    with pytest.raises(Killed):
        train.sweep(config, examples, specs, tmp_path / "killed", mode=mode, progress=False,
                    step_callback=kill_at_step_9)
    resumed_steps = []
    resumed = train.sweep(
        config, examples, specs, tmp_path / "killed", mode=mode, progress=False,
        step_callback=lambda step, metrics: resumed_steps.append(step),
    )
    assert resumed_steps[0] == 9  # restarted after the checkpoint at step 8
    jax.tree.map(np.testing.assert_array_equal, _params(resumed), _params(uninterrupted))
    jax.tree.map(
        np.testing.assert_array_equal, jax.tree.map(np.asarray, resumed.state.batch_stats),
        jax.tree.map(np.asarray, uninterrupted.state.batch_stats),
    )
    with (tmp_path / "killed" / "metrics.csv").open() as file:
        steps = [int(row["step"]) for row in csv.DictReader(file)]
    assert steps == [step for step in range(2, 13, 2) for _ in specs]
    np.testing.assert_array_equal(resumed.steps_trained, [12, 12, 12])

    with pytest.raises(ValueError, match="different models"):
        train.sweep(config, examples, train.subset_specs(256, [30], [5], ["error"]), tmp_path / "killed",
                    progress=False)


@pytest.mark.filterwarnings("ignore:workdir.*past the requested num_steps")  # test_resuming_past_the_requested_steps_warns
def test_resuming_a_finished_sweep_reports_the_restored_steps(examples, tmp_path):
    config = _config("error", num_steps=6, checkpoint_every=3, log_every=3)
    specs = ERROR_SPECS[:2]
    finished = train.sweep(config, examples, specs, tmp_path, mode="sequential", progress=False)
    np.testing.assert_array_equal(finished.steps_trained, [6, 6])
    # Rerun, or run with fewer steps than the checkpoint holds: nothing to train, and the restored
    # state comes back as it is, with its own step count.
    for num_steps in (6, 4):
        steps = []
        again = train.sweep(dataclasses.replace(config, num_steps=num_steps), examples, specs, tmp_path,
                            mode="vmap", progress=False, step_callback=lambda step, metrics: steps.append(step))
        assert steps == [] and again.final_metrics == {}
        np.testing.assert_array_equal(again.steps_trained, [6, 6])
        jax.tree.map(np.testing.assert_array_equal, _params(again), _params(finished))


def test_resuming_past_the_requested_steps_warns(examples, tmp_path):
    config = _config("error", num_steps=6, checkpoint_every=3, log_every=3)
    specs = ERROR_SPECS[:1]
    train.sweep(config, examples, specs, tmp_path, mode="sequential", progress=False)
    with pytest.warns(UserWarning) as caught:
        fewer = train.sweep(dataclasses.replace(config, num_steps=4), examples, specs, tmp_path, mode="sequential",
                            progress=False)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert str(tmp_path) in message and "step 6" in message and "num_steps 4" in message, message
    np.testing.assert_array_equal(fewer.steps_trained, [6])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        train.sweep(config, examples, specs, tmp_path, mode="sequential", progress=False)  # as requested


def test_sweep_rejects_bad_arguments(examples):
    specs = train.subset_specs(256, [30], [0])
    assert train.SWEEP_MODES == ("vmap", "unroll", "sequential")
    with pytest.raises(ValueError, match="mode"):
        train.sweep(SMOKE, examples, specs, mode="pmap", progress=False)
    with pytest.raises(ValueError, match="specs"):
        train.sweep(SMOKE, examples, [], progress=False)
    with pytest.raises(ValueError, match="outside"):
        train.sweep(SMOKE, examples, [train.ModelSpec("far", np.array([10**6]), seed=0)], progress=False)
    with pytest.raises(ValueError, match="error variant"):
        train.sweep(SMOKE, examples, [train.ModelSpec("e", np.arange(4), seed=0, variant="error")], progress=False)
