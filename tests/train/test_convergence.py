"""The convergence criterion of issue 30's run, and one model trained by it on the smoke data."""

import dataclasses

import jax
import numpy as np
import pytest

from pushjax.train import convergence
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


@pytest.mark.parametrize("improvement, budget, converged", [(0.9, 40, True), (0.0, 10, False)])
def test_train_until_converged(smoke, improvement, budget, converged):
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=0", np.arange(64), seed=0)
    criterion = convergence.Criterion(eval_every=5, window=2, min_improvement=improvement, base_steps=budget,
                                      steps_per_example=0.0, max_steps=budget, min_decay_steps=3)
    lines = []
    model = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, criterion, log=lines.append)
    # Needing a 90 % improvement, the criterion ends the phase at its first chance (3 scores); the 10-step budget
    # ends it before the criterion can (2 scores).
    assert model.converged is converged
    assert model.constant_steps == (15 if converged else 10) and model.decay_steps == 3 and model.steps == \
        int(model.state.step)
    assert [step for step, *_ in model.validation] == ([5, 10, 15, 18] if converged else [5, 10, 13])
    assert len(lines) == len(model.validation) and np.isfinite(model.validation).all()
    learning_rate = float(model.state.opt_state.hyperparams["learning_rate"])
    assert learning_rate == pytest.approx(TINY_SMOKE.learning_rate * criterion.final_lr_fraction, rel=1e-5)
    assert model.validation[-1][1:] == pytest.approx(
        convergence.validation_errors(model.model, model.state, validation, 64))


class _Interrupted(Exception):
    pass


def test_a_resumed_model_ends_as_an_uninterrupted_one(smoke, tmp_path, monkeypatch):
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=1", np.arange(64), seed=1)
    criterion = convergence.Criterion(eval_every=5, window=2, min_improvement=0.0, base_steps=15,
                                      steps_per_example=0.0, max_steps=15, min_decay_steps=7)
    whole = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, criterion)
    folder = tmp_path / "resume"

    def killed_at_the_second_score(line, seen=[]):
        seen.append(line)
        if len(seen) == 2:
            raise _Interrupted(line)

    # Killed while scoring step 10: the state saved at step 5 is where it resumes.
    with pytest.raises(_Interrupted):
        convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, criterion,
                                          log=killed_at_the_second_score, resume_dir=folder)
    assert convergence.resumed_step(folder) == 5
    # Killed in the decay (15 constant steps, 7 of decay) before its step 21: saved at 20.
    batch_indices = convergence.batch_indices

    def killed_at_step_21(model_spec, step, batch_size):
        if step == 21:
            raise _Interrupted(step)
        return batch_indices(model_spec, step, batch_size)

    monkeypatch.setattr(convergence, "batch_indices", killed_at_step_21)
    with pytest.raises(_Interrupted):
        convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, criterion, resume_dir=folder)
    assert convergence.resumed_step(folder) == 20
    monkeypatch.setattr(convergence, "batch_indices", batch_indices)
    lines = []
    resumed = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, criterion, log=lines.append,
                                                resume_dir=folder)
    assert len(lines) == 1 and "step 22 (after the decay)" in lines[0]
    assert (resumed.converged, resumed.constant_steps, resumed.decay_steps) == (False, 15, 7)
    assert resumed.validation == whole.validation
    for got, expected in zip(jax.tree.leaves(resumed.state), jax.tree.leaves(whole.state), strict=True):
        np.testing.assert_array_equal(got, expected)
    assert convergence.resumed_step(tmp_path / "nothing") == 0


def test_a_fixed_budget_ignores_the_scores_and_continues_to_a_larger_one(smoke, tmp_path):
    examples, validation = smoke["train"], smoke["validation"]
    spec = ModelSpec("size=64/seed=2", np.arange(64), seed=2)
    # min_improvement=0.9 would stop the criterion at its first chance; a fixed budget records the scores only.
    short = dataclasses.replace(convergence.fixed_budget(10), eval_every=5, min_improvement=0.9)
    long = dataclasses.replace(short, base_steps=20, max_steps=20)
    assert convergence.PAPER_SCHEDULE.budget(190_080) == 75_000 and convergence.PAPER_SCHEDULE.decay_steps(75_000) == 0
    whole = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, long)
    assert (whole.converged, whole.constant_steps, whole.decay_steps) == (False, 20, 0)
    assert [step for step, *_ in whole.validation] == [5, 10, 15, 20]
    learning_rate = float(whole.state.opt_state.hyperparams["learning_rate"])
    assert learning_rate == pytest.approx(TINY_SMOKE.learning_rate)  # no decay
    folder = tmp_path / "state"
    first = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, short, resume_dir=folder)
    assert first.steps == 10 and [step for step, *_ in first.validation] == [5, 10]
    lines = []
    continued = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, long, log=lines.append,
                                                  resume_dir=folder)
    assert [line.split(": ", 1)[1] for line in lines] == [
        f"step {step} (constant) validation score {(trans + rot) / 2:.2f}" for step, trans, rot in whole.validation[2:]]
    assert continued.validation == whole.validation and continued.steps == 20
    for got, expected in zip(jax.tree.leaves(continued.state), jax.tree.leaves(whole.state), strict=True):
        np.testing.assert_array_equal(got, expected)
    # The same budget again trains nothing and scores nothing.
    again = convergence.train_until_converged(TINY_SMOKE, examples, spec, validation, long, resume_dir=folder)
    assert again.validation == whole.validation and again.steps == 20
