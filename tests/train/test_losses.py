import jax.numpy as jnp
import numpy as np
import pytest

from pushjax.models import VARIANTS, VIEWS
from pushjax.train import losses


def _batch():
    return {
        "motion": jnp.array([[0.003, 0.004, 0.0], [0.0, 0.0, 0.0]]),
        "object_pos": jnp.array([[0.01, 0.0], [0.0, 0.02]]),
        "contact_flag": jnp.array([1.0, 0.0]),
    }


def test_perfect_prediction_has_only_the_weight_penalty():
    batch = _batch()
    params = {"dense": {"kernel": jnp.full((2, 2), 2.0), "bias": jnp.ones(2)}}
    loss, metrics = losses.loss_2d({"motion": batch["motion"], "object_pos": batch["object_pos"]}, batch, params, 1e-3)
    assert metrics["reg"] == pytest.approx(0.5 * 4 * 4.0)
    for name in ("trans", "mag", "rot", "pos"):
        assert metrics[name] == pytest.approx(0.0, abs=1e-3)
    assert loss == pytest.approx(1e-3 * 8.0, abs=5e-3)


def test_2d_loss_terms_are_in_mm_and_degrees():
    batch = _batch()
    predictions = {
        "motion": batch["motion"] + jnp.array([[0.001, 0.0, jnp.deg2rad(2.0)], [0.0, 0.0, 0.0]]),
        "object_pos": batch["object_pos"] + jnp.array([[0.0, 0.004], [0.0, 0.0]]),
    }
    loss, metrics = losses.loss_2d(predictions, batch, {}, 1e-3)
    assert metrics["trans"] == pytest.approx(0.5, abs=1e-3)  # 1 mm on one of two examples
    assert metrics["mag"] == pytest.approx(0.5 * (np.hypot(4, 4) - 5), abs=1e-3)
    assert metrics["rot"] == pytest.approx(1.0, abs=1e-4)
    assert metrics["pos"] == pytest.approx(2.0, abs=1e-3)
    assert loss == pytest.approx(metrics["trans"] + metrics["mag"] + metrics["rot"] + metrics["pos"])


def test_3d_loss_weights_motion_by_contact_and_adds_contact_cross_entropy():
    batch = _batch()
    predictions = {
        "motion_given_contact": batch["motion"] + jnp.array([[0.0, 0.0, 0.0], [0.01, 0.0, 1.0]]),
        "object_pos": batch["object_pos"],
        "s_logit": jnp.array([0.0, 0.0]),
    }
    loss, metrics = losses.loss_3d(predictions, batch, {}, 1e-3)
    assert metrics["trans"] == pytest.approx(0.0, abs=1e-3)  # the wrong motion has no contact
    assert metrics["rot"] == pytest.approx(0.0, abs=1e-6)
    assert metrics["contact_bce"] == pytest.approx(np.log(2.0), rel=1e-5)
    assert loss == pytest.approx(10 * np.log(2.0), abs=3e-3)


def test_loss_choice():
    assert losses.loss_for("hybrid", "free") is losses.loss_3d
    assert losses.loss_for("neural", "free") is losses.loss_2d
    assert losses.loss_for("hybrid", "top_down") is losses.loss_2d


@pytest.mark.parametrize("view", VIEWS)
@pytest.mark.parametrize("variant", VARIANTS)
def test_loss_choice_of_every_variant_and_view(variant, view):
    separate_contact_indicator = view == "free" and variant in ("hybrid", "error", "error_grad", "error_norm")
    assert losses.loss_for(variant, view) is (losses.loss_3d if separate_contact_indicator else losses.loss_2d)
