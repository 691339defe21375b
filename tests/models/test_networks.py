import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.models import VARIANTS, ModelConfig, PushModel, count_parameters
from pushjax.train import losses
from pushjax.data import configs as data_configs
from pushjax.train.configs import get_config
from tests.tiny_configs import TINY_SMOKE

from .synthetic import synthetic_examples

TINY = TINY_SMOKE.model


@pytest.fixture(scope="module")
def batch():
    return {name: jnp.asarray(value) for name, value in synthetic_examples(8, seed=0).items()}


@pytest.fixture(scope="module")
def free_batch():
    return {name: jnp.asarray(value) for name, value in synthetic_examples(8, seed=1, view="free").items()}


def _model(variant, view="top_down", **changes):
    return PushModel(dataclasses.replace(TINY, variant=variant, view=view, **changes))


def _loss_and_grads(model, variables, batch, output=None):
    def objective(params):
        predictions, _ = model.apply(
            {**variables, "params": params}, batch, train=True, mutable=["batch_stats"]
        )
        if output is not None:
            return jnp.sum(predictions[output])
        loss_fn = losses.loss_for(model.config.variant, model.config.view)
        return loss_fn(predictions, batch, params, 1e-3)[0]

    return jax.value_and_grad(objective)(variables["params"])


def _perception_gradient_norm(grads):
    return float(sum(jnp.sum(g**2) for g in jax.tree.leaves({k: grads[k] for k in ("glimpse", "locator")})))


@pytest.mark.parametrize("variant", VARIANTS)
def test_every_variant_predicts_finite_motion_with_finite_gradients(variant, batch):
    model = _model(variant)
    variables = model.init(jax.random.key(0), batch, train=False)
    outputs = model.apply(variables, batch, train=False)
    assert outputs["motion"].shape == (8, 3)
    if variant != "neural_dyn":
        assert outputs["object_pos"].shape == (8, 2)
    if variant in ("hybrid", "error", "error_grad", "error_norm"):
        assert outputs["normal"].shape == (8, 2) and outputs["s"].shape == (8,)
    if variant == "simple":
        assert outputs["push_velocity"].shape == (8, 2)
    loss, grads = _loss_and_grads(model, variables, batch)
    assert np.isfinite(loss)
    assert all(np.all(np.isfinite(g)) for g in jax.tree.leaves(grads))


def test_hybrid_loss_gradients_reach_the_perception(batch):
    model = _model("hybrid")
    variables = model.init(jax.random.key(0), batch, train=False)
    _, grads = _loss_and_grads(model, variables, batch)
    for module in ("glimpse", "locator"):
        assert float(sum(jnp.sum(g**2) for g in jax.tree.leaves(grads[module]))) > 0, module


@pytest.mark.parametrize("variant, blocked", [("error", True), ("error_norm", True), ("error_grad", False)])
def test_error_term_gradient_to_perception(variant, blocked, batch):
    model = _model(variant)
    variables = model.init(jax.random.key(0), batch, train=False)
    _, grads = _loss_and_grads(model, variables, batch, output="error")
    norm = _perception_gradient_norm(grads)
    assert (norm == 0.0) if blocked else (norm > 0.0)


def test_error_options_reproduce_the_variants(batch):
    variables = _model("error").init(jax.random.key(0), batch, train=False)
    for variant, options in (("error_grad", [0.0, 0.0]), ("error_norm", [1.0, 1.0])):
        expected = _model(variant).apply(variables, batch, train=False)["motion"]
        overridden = _model("error").apply(
            variables, batch, train=False, error_options=jnp.asarray(options)
        )["motion"]
        np.testing.assert_allclose(overridden, expected, rtol=1e-6)


@pytest.mark.parametrize("variant", ["hybrid", "error"])
def test_free_view_variant_predicts_in_world_coordinates(variant, free_batch):
    model = _model(variant, view="free")
    variables = model.init(jax.random.key(0), free_batch, train=False)
    outputs = model.apply(variables, free_batch, train=False)
    np.testing.assert_allclose(
        outputs["motion"], outputs["s"][:, None] * (outputs["motion_given_contact"] - outputs.get("error", 0))
        + outputs.get("error", 0), rtol=1e-5, atol=1e-9,
    )
    # The object lies on the table within 15 cm of the origin; its pixel maps there.
    assert np.all(np.abs(outputs["object_pos"]) < 0.15)
    loss, grads = _loss_and_grads(model, variables, free_batch)
    assert np.isfinite(loss) and _perception_gradient_norm(grads) > 0


def test_physics_is_a_swappable_function(batch):
    def no_motion(contact, normal, action, l, mu, s):
        return jnp.zeros(contact.shape[:-1] + (3,))

    model = PushModel(dataclasses.replace(TINY, variant="hybrid"), physics=no_motion)
    variables = model.init(jax.random.key(0), batch, train=False)
    np.testing.assert_array_equal(model.apply(variables, batch, train=False)["motion"], 0.0)


def test_paper_scale_parameter_counts(batch):
    paper = get_config(data_configs.get_config("data_efficiency", "paper")).model
    images = {**batch, "depth": jnp.zeros((8, 128, 128, 1))}

    def counts(variant):
        model = PushModel(dataclasses.replace(paper, variant=variant))
        shapes = jax.eval_shape(lambda: model.init(jax.random.key(0), images, train=False))
        return count_parameters(shapes["params"])

    hybrid, error = counts("hybrid"), counts("error")
    assert 1.7e6 < hybrid["glimpse"] + hybrid["head"] < 1.9e6
    assert 2.6e6 < error["glimpse"] + error["head"] + error["error"] < 2.8e6


def test_config_rejects_unknown_variant_and_view():
    with pytest.raises(ValueError, match="variant"):
        ModelConfig(variant="lstm")
    with pytest.raises(ValueError, match="view"):
        ModelConfig(view="side")
