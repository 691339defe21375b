"""The controller's model: built from an object and effects, bad parameters named, predicting the rollout."""

import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.control import model
from pushjax.geometry import outline_jax
from pushjax.physics import rollout


def test_make_model_fills_the_effects_parameters_and_rejects_bad_ones():
    built = model.make_model("tri2", mu=0.3, effects=("friction_ratio",), params={"friction_ratio": {"log_scale": 0.2}})
    assert built.effects == ("friction_ratio",)
    assert float(built.params["friction_ratio"]["log_scale"]) == pytest.approx(0.2)
    with pytest.raises(ValueError, match="params: effect"):
        model.make_model("tri2", params={"inertia": {"inverse_deceleration": 0.1}})
    with pytest.raises(ValueError, match="no parameter"):
        model.make_model("tri2", effects=("friction_ratio",), params={"friction_ratio": {"scale": 1.0}})
    with pytest.raises(ValueError, match="mu, l"):
        model.make_model("tri2", mu=-0.1)
    with pytest.raises(ValueError, match="unknown"):
        model.make_model("tri2", effects=("wind",))


def test_predict_is_the_rollout_with_the_models_effects():
    built = model.make_model("rect1", effects=("friction_ratio",), params={"friction_ratio": {"log_scale": 0.5}})
    path = jnp.stack([jnp.linspace(-0.06, -0.02, 11), jnp.full(11, 0.01)], axis=-1)
    got = model.predict(built, jnp.zeros(3), path).poses
    expected = rollout.rollout(outline_jax.outline("rect1"), jnp.zeros(3), path, built.l, built.mu, built.params,
                               effects=("friction_ratio",)).poses
    np.testing.assert_allclose(got, expected)
    plain = model.predict(model.make_model("rect1"), jnp.zeros(3), path).poses
    assert abs(float(got[-1, 2]) - float(plain[-1, 2])) > 1e-4  # the effect changes the prediction


def test_a_model_with_the_exact_limit_surface_carries_the_objects_support():
    built = model.make_model("rect1", effects=("limit_surface",), params={"limit_surface": {"rim": 1.0}})
    assert built.support is not None and model.make_model("rect1").support is None
    path = jnp.stack([jnp.linspace(-0.06, -0.02, 11), jnp.full(11, 0.01)], axis=-1)
    got = model.predict(built, jnp.zeros(3), path).poses
    expected = rollout.rollout(outline_jax.outline("rect1"), jnp.zeros(3), path, built.l, built.mu, built.params,
                               effects=("limit_surface",), support=rollout.object_support("rect1")).poses
    np.testing.assert_allclose(got, expected, atol=1e-8)
    plain = model.predict(model.make_model("rect1"), jnp.zeros(3), path).poses
    assert abs(float(got[-1, 2]) - float(plain[-1, 2])) > 1e-4
