"""The convergence criterion of issue 30's run, and one model trained by it on the smoke data."""

import dataclasses

import jax
import numpy as np
import pytest

from pushjax import train
from pushjax.train import checkpoint, convergence, evaluate, sweep_trainer
from pushjax.train.batching import ModelSpec
from tests.tiny_configs import TINY_SMOKE


def test_budget_grows_with_size_and_is_capped():
    criterion = convergence.Criterion(eval_every=1000, base_steps=10_000, steps_per_example=0.25, max_steps=60_000)
    budgets = [criterion.budget(size) for size in (2_500, 20_000, 100_000, 190_080)]
    assert budgets == [11_000, 15_000, 35_000, 58_000]
    assert criterion.budget(10**7) == 60_000 and all(b % 1000 == 0 for b in budgets)


def test_plateau_needs_a_window_without_relative_improvement():
    criterion = convergence.Criterion(window=3, min_improvement=0.01)
    assert not criterion.plateaued([50.0, 49.0, 48.0])  # no evaluation before the window yet
    assert not criterion.plateaued([50.0, 40.0, 35.0, 34.0, 33.0])  # still improving by > 1 %
    assert criterion.plateaued([50.0, 40.0, 39.9, 40.5, 39.7])  # best 39.7 vs 40.0 before: 0.75 % < 1 %
    assert not criterion.plateaued([50.0, 40.0, 39.9, 40.5, 39.5])  # 1.25 % better: still improving
    assert criterion.plateaued([30.0, 31.0, 32.0, 33.0])  # worse over the window
    assert criterion.decay_steps(40_000) == 4_000 and criterion.decay_steps(3_000) == 1_000


def _train(examples, spec, validation, criterion, workdir=None, **kwargs):
    return train.sweep(TINY_SMOKE, examples, [spec], workdir, mode="sequential", progress=False, criterion=criterion,
                       validation=validation, **kwargs)


def _assert_same_state(got, expected):
    for got_leaf, expected_leaf in zip(jax.tree.leaves(got), jax.tree.leaves(expected), strict=True):
        np.testing.assert_array_equal(got_leaf, expected_leaf)


@pytest.mark.parametrize("improvement, budget, converged", [(0.9, 40, True), (0.0, 10, False)])
def test_a_criterion_or_its_budget_ends_the_constant_phase(smoke, improvement, budget, converged):
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=0", np.arange(64), seed=0)
    criterion = convergence.Criterion(eval_every=5, window=2, min_improvement=improvement, base_steps=budget,
                                      steps_per_example=0.0, max_steps=budget, min_decay_steps=3)
    lines = []
    result = _train(examples, spec, validation, criterion, log=lines.append)
    phases = result.phases
    # Needing a 90 % improvement, the criterion ends the phase at its first chance (3 scores); the 10-step budget
    # ends it before the criterion can (2 scores).
    assert phases.converged is converged
    assert phases.constant_steps == (15 if converged else 10) and phases.decay_steps == 3 and phases.steps == \
        int(result.steps_trained[0])
    assert [step for step, *_ in phases.validation] == ([5, 10, 15, 18] if converged else [5, 10, 13])
    assert len(lines) == len(phases.validation) and np.isfinite(phases.validation).all()
    learning_rate = float(result.model_state(0).opt_state.hyperparams["learning_rate"])
    assert learning_rate == pytest.approx(TINY_SMOKE.learning_rate * criterion.final_lr_fraction, rel=1e-5)
    assert phases.validation[-1][1:] == pytest.approx(
        evaluate.validation_errors(result.model, result.model_state(0), validation, 64))


def test_a_criterion_judges_one_model_on_a_validation_set(smoke):
    specs = train.subset_specs(64, [32], [0, 1])
    with pytest.raises(ValueError, match="criterion: judges one model's validation score; got 2 models"):
        train.sweep(TINY_SMOKE, smoke["train"], specs, criterion=convergence.CRITERION, validation=smoke["validation"])
    with pytest.raises(ValueError, match="got 1 models and no validation set"):
        train.sweep(TINY_SMOKE, smoke["train"], specs[:1], criterion=convergence.CRITERION)


class _Interrupted(Exception):
    pass


def test_a_resumed_model_ends_as_an_uninterrupted_one(smoke, tmp_path, monkeypatch):
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=1", np.arange(64), seed=1)
    criterion = convergence.Criterion(eval_every=5, window=2, min_improvement=0.0, base_steps=15,
                                      steps_per_example=0.0, max_steps=15, min_decay_steps=7)
    whole = _train(examples, spec, validation, criterion)
    folder = tmp_path / "resume"

    def killed_at_the_second_score(line, seen=[]):
        seen.append(line)
        if len(seen) == 2:
            raise _Interrupted(line)

    # Killed while scoring step 10: the state saved at step 5 is where it resumes.
    with pytest.raises(_Interrupted):
        _train(examples, spec, validation, criterion, folder, log=killed_at_the_second_score)
    assert train.resumed_step(folder) == 5
    # Killed in the decay (15 constant steps, 7 of decay) before its step 21: saved at 20.
    batch_indices = sweep_trainer.batch_indices

    def killed_at_step_21(model_spec, step, batch_size):
        if step == 21:
            raise _Interrupted(step)
        return batch_indices(model_spec, step, batch_size)

    monkeypatch.setattr(sweep_trainer, "batch_indices", killed_at_step_21)
    with pytest.raises(_Interrupted):
        _train(examples, spec, validation, criterion, folder)
    assert train.resumed_step(folder) == 20
    monkeypatch.setattr(sweep_trainer, "batch_indices", batch_indices)
    lines = []
    resumed = _train(examples, spec, validation, criterion, folder, log=lines.append)
    assert len(lines) == 1 and "step 22 (after the decay)" in lines[0]
    assert (resumed.phases.converged, resumed.phases.constant_steps, resumed.phases.decay_steps) == (False, 15, 7)
    assert resumed.phases.validation == whole.phases.validation
    _assert_same_state(resumed.state, whole.state)
    assert train.resumed_step(tmp_path / "nothing") == 0


def test_a_fixed_budget_ignores_the_scores_and_continues_to_a_larger_one(smoke, tmp_path):
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=2", np.arange(64), seed=2)
    # min_improvement=0.9 would stop the criterion at its first chance; a fixed budget records the scores only.
    short = dataclasses.replace(convergence.fixed_budget(10), eval_every=5, min_improvement=0.9)
    long = dataclasses.replace(short, base_steps=20, max_steps=20)
    assert convergence.PAPER_SCHEDULE.budget(190_080) == 75_000 and convergence.PAPER_SCHEDULE.decay_steps(75_000) == 0
    whole = _train(examples, spec, validation, long)
    assert (whole.phases.converged, whole.phases.constant_steps, whole.phases.decay_steps) == (False, 20, 0)
    assert [step for step, *_ in whole.phases.validation] == [5, 10, 15, 20]
    learning_rate = float(whole.model_state(0).opt_state.hyperparams["learning_rate"])
    assert learning_rate == pytest.approx(TINY_SMOKE.learning_rate)  # no decay
    folder = tmp_path / "state"
    first = _train(examples, spec, validation, short, folder)
    assert first.phases.steps == 10 and [step for step, *_ in first.phases.validation] == [5, 10]
    lines = []
    continued = _train(examples, spec, validation, long, folder, log=lines.append)
    assert [line.split(": ", 1)[1] for line in lines] == [
        f"step {step} (constant) validation score {(trans + rot) / 2:.2f}"
        for step, trans, rot in whole.phases.validation[2:]]
    assert continued.phases.validation == whole.phases.validation and continued.phases.steps == 20
    _assert_same_state(continued.state, whole.state)
    # The same budget again trains nothing and scores nothing.
    again = _train(examples, spec, validation, long, folder)
    assert again.phases.validation == whole.phases.validation and again.phases.steps == 20


def test_a_state_kept_by_the_criterions_former_trainer_continues_to_the_same_model(smoke, tmp_path):
    """The states of `pushjax.paper.full_run` committed before the one trainer: one model's state without a model axis
    and the criterion's progress as the metadata, directly in the model's folder. The trainer continues them as its
    own and keeps them in its layout from its first save on."""
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=3", np.arange(64), seed=3)
    short = dataclasses.replace(convergence.fixed_budget(10), eval_every=5)
    long = dataclasses.replace(short, base_steps=20, max_steps=20)
    whole = _train(examples, spec, validation, long)
    kept = _train(examples, spec, validation, short, tmp_path / "new", keep_checkpoints=1)
    reader = checkpoint.Checkpointer(tmp_path / "new" / sweep_trainer.CHECKPOINTS, read_only=True)
    assert reader.all_steps() == [10]
    _, metadata = reader.restore_arrays(10)
    reader.close()
    legacy = tmp_path / "legacy"
    writer = checkpoint.Checkpointer(legacy, max_to_keep=1)
    writer.save(10, kept.model_state(0), metadata["progress"])
    writer.close()
    assert train.resumed_step(legacy) == 10
    continued = _train(examples, spec, validation, long, legacy)
    assert continued.phases.validation == whole.phases.validation and continued.phases.steps == 20
    _assert_same_state(continued.state, whole.state)
    assert not (legacy / "10").exists() and train.resumed_step(legacy) == 20
