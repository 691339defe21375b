import jax
import jax.numpy as jnp
import pytest

from pushjax.models import (
    ERROR_OPTIONS, PHYSICS_VARIANTS, VARIANTS, VIEWS, ModelConfig, PushModel, config, heads, perception,
)

from .synthetic import synthetic_examples

SMALL = dict(
    glimpse_size=8, glimpse_features=(4, 4, 2), glimpse_kernel=3, locator_conv_features=(2, 3, 3, 3),
    locator_deconv_features=(3, 2), locator_kernel=3, head_features=(16,), error_features=(8,),
)
"""Sizes whose parameter shapes `_expected_parameter_shapes` spells out."""


def _expected_parameter_shapes(variant, view):
    """{path: shape} of the parameters of a SMALL model; the glimpse encoding has 1 * 1 * 2 entries."""
    channels = 1 if view == "top_down" else 3
    perception = {
        "glimpse/Conv_0/kernel": (3, 3, channels, 4), "glimpse/Conv_0/bias": (4,),
        "glimpse/BatchNorm_0/scale": (4,), "glimpse/BatchNorm_0/bias": (4,),
        "glimpse/Conv_1/kernel": (3, 3, 4, 4), "glimpse/Conv_1/bias": (4,),
        "glimpse/BatchNorm_1/scale": (4,), "glimpse/BatchNorm_1/bias": (4,),
        "glimpse/Conv_2/kernel": (3, 3, 4, 2), "glimpse/Conv_2/bias": (2,),
        "glimpse/BatchNorm_2/scale": (2,), "glimpse/BatchNorm_2/bias": (2,),
        "locator/Conv_0/kernel": (3, 3, channels, 2), "locator/Conv_0/bias": (2,),
        "locator/Conv_1/kernel": (3, 3, 2, 3), "locator/Conv_1/bias": (3,),
        "locator/Conv_2/kernel": (3, 3, 3, 3), "locator/Conv_2/bias": (3,),
        "locator/Conv_3/kernel": (3, 3, 3, 3), "locator/Conv_3/bias": (3,),
        "locator/ConvTranspose_0/kernel": (3, 3, 3, 3), "locator/ConvTranspose_0/bias": (3,),
        "locator/ConvTranspose_1/kernel": (3, 3, 3, 2), "locator/ConvTranspose_1/bias": (2,),
        "locator/ConvTranspose_2/kernel": (3, 3, 2, 1),
    }

    def stack(name, inputs, outputs, hidden):
        return {
            f"{name}/Dense_0/kernel": (inputs, hidden), f"{name}/Dense_0/bias": (hidden,),
            f"{name}/Dense_1/kernel": (hidden, outputs), f"{name}/Dense_1/bias": (outputs,),
        }

    # Head inputs: glimpse 2, object position 2, action 2, l 1; neural_dyn: contact 2, normal 2,
    # contact flag 1, action 2, l 1, mu 1.
    error_term = stack("error", 2 + 2 + 2 + 1, 3, 8)
    return {
        "neural": {**perception, **stack("head", 2 + 2 + 2 + 1, 3, 16)},
        "neural_dyn": stack("head", 2 + 2 + 1 + 2 + 1 + 1, 3, 16),
        "hybrid": {**perception, **stack("head", 2 + 2, 5, 16)},
        "simple": {**perception, **stack("head", 2 + 2, 4, 16)},
        "error": {**perception, **stack("head", 2 + 2, 5, 16), **error_term},
        "error_grad": {**perception, **stack("head", 2 + 2, 5, 16), **error_term},
        "error_norm": {**perception, **stack("head", 2 + 2, 5, 16), **error_term},
    }[variant]


@pytest.fixture(scope="module")
def batches():
    return {
        view: {name: jnp.asarray(value) for name, value in synthetic_examples(4, seed=2, view=view).items()}
        for view in VIEWS
    }


def _init(variant, view, batch):
    """The model and the shapes of its variables (traced, not computed: `jax.eval_shape`)."""
    model = PushModel(ModelConfig(variant=variant, view=view, **SMALL))
    return model, jax.eval_shape(lambda: model.init(jax.random.key(0), batch, train=False))


def _outputs(model, variables, batch):
    """The shapes of the model's outputs in eval mode (`jax.eval_shape`)."""
    return jax.eval_shape(lambda variables, batch: model.apply(variables, batch, train=False), variables, batch)


@pytest.mark.parametrize("view", VIEWS)
@pytest.mark.parametrize("variant", VARIANTS)
def test_parameter_tree_keeps_its_module_paths_and_shapes(variant, view, batches):
    _, variables = _init(variant, view, batches[view])
    shapes = {
        "/".join(key.key for key in path): leaf.shape
        for path, leaf in jax.tree_util.tree_leaves_with_path(variables["params"])
    }
    assert shapes == _expected_parameter_shapes(variant, view)


@pytest.mark.parametrize("view", VIEWS)
@pytest.mark.parametrize("variant", VARIANTS)
def test_outputs_are_the_ones_the_head_declares(variant, view, batches):
    model, variables = _init(variant, view, batches[view])
    outputs = _outputs(model, variables, batches[view])
    assert frozenset(outputs) == heads.HEADS[variant].output_names(view)


def test_declared_outputs_per_variant_and_view():
    perceived = {"object_pixel", "object_pos"}
    physics = perceived | {"motion", "contact", "normal", "s", "s_logit"}
    top_down = {
        "neural": perceived | {"motion"},
        "neural_dyn": {"motion"},
        "hybrid": physics,
        "simple": perceived | {"motion", "contact", "push_velocity"},
        "error": physics | {"error"},
        "error_grad": physics | {"error"},
        "error_norm": physics | {"error"},
    }
    separate_s = {"hybrid", "error", "error_grad", "error_norm"}
    for variant, names in top_down.items():
        assert heads.HEADS[variant].output_names("top_down") == names
        free_names = names | {"motion_given_contact"} if variant in separate_s else names
        assert heads.HEADS[variant].output_names("free") == free_names


def test_the_registries_implement_exactly_the_configurable_names():
    assert VARIANTS == ("neural", "neural_dyn", "hybrid", "simple", "error", "error_grad", "error_norm")
    assert VARIANTS == tuple(heads.HEADS)
    assert VIEWS == tuple(perception.VIEW_MAPPINGS)
    for view, mapping in perception.VIEW_MAPPINGS.items():
        assert ModelConfig(view=view).image_field == mapping.image_field
    assert PHYSICS_VARIANTS == ("hybrid", "simple", "error", "error_grad", "error_norm")
    assert ERROR_OPTIONS == {"error": (1.0, 0.0), "error_grad": (0.0, 0.0), "error_norm": (1.0, 1.0)}
    assert VIEWS == ("top_down", "free")


def test_a_registered_head_is_a_variant(batches, monkeypatch):
    class ConstantHead(heads.Head):
        """Predicts no motion from the glimpse."""

        def __call__(self, batch, scene, error_options=None):
            return {"motion": jnp.zeros((scene.glimpse.shape[0], 3))}

    monkeypatch.setitem(heads.HEADS, "constant", ConstantHead)
    monkeypatch.setattr(config, "VARIANTS", (*VARIANTS, "constant"))
    model, variables = _init("constant", "top_down", batches["top_down"])
    outputs = _outputs(model, variables, batches["top_down"])
    assert set(variables["params"]) == {"glimpse", "locator"}
    assert frozenset(outputs) == ConstantHead.output_names("top_down") == {"motion", "object_pixel", "object_pos"}
