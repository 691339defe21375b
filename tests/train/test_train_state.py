import jax
import numpy as np
import pytest

from pushjax import train
from pushjax.models import PushModel
from tests.tiny_configs import TINY_SMOKE as SMOKE



@pytest.fixture(scope="module")
def setup(examples):
    model = PushModel(SMOKE.with_variant("hybrid", "top_down").model)
    optimizer = train.make_optimizer(SMOKE.learning_rate)
    batch = train.gather(examples, np.arange(SMOKE.batch_size), train.model_fields(model.config))
    return model, optimizer, batch


def _leaves(tree):
    return [np.asarray(leaf) for leaf in jax.tree.leaves(tree)]


def test_create_train_state_is_a_function_of_the_seed(setup):
    model, optimizer, batch = setup
    state = train.create_train_state(model, optimizer, batch, seed=3)
    assert int(state.step) == 0 and state.step.dtype == np.int32
    assert state.batch_stats  # the smoke model has batch norm
    for a, b in zip(_leaves(state.params), _leaves(train.create_train_state(model, optimizer, batch, 3).params)):
        np.testing.assert_array_equal(a, b)
    other = train.create_train_state(model, optimizer, batch, seed=4)
    assert any(not np.array_equal(a, b) for a, b in zip(_leaves(state.params), _leaves(other.params)))


def test_train_step_advances_the_state_and_reports_the_loss(setup):
    model, optimizer, batch = setup
    state = train.create_train_state(model, optimizer, batch, seed=0)
    train_step = jax.jit(train.make_train_step(model, optimizer, SMOKE.weight_decay))
    stepped, metrics = train_step(state, batch)
    assert int(stepped.step) == 1
    assert np.isfinite(float(metrics["loss"])) and {"trans", "rot"} <= set(metrics)
    assert any(not np.array_equal(a, b) for a, b in zip(_leaves(stepped.params), _leaves(state.params)))
    assert any(not np.array_equal(a, b)
               for a, b in zip(_leaves(stepped.batch_stats), _leaves(state.batch_stats)))
    assert jax.tree.structure(stepped) == jax.tree.structure(state)
    # The step is pure: the same inputs give the same outputs.
    again, _ = train_step(state, batch)
    for a, b in zip(_leaves(again), _leaves(stepped)):
        np.testing.assert_array_equal(a, b)
