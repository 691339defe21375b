"""An experiment is resolved once: `make_spec` from a setup and the user's choices."""

import json

import pytest

from pushjax.data import configs as data_configs
from pushjax.paper import spec as spec_lib
from pushjax.train import configs as train_configs


def test_every_binary_has_a_setup_whose_models_are_known():
    assert set(spec_lib.SETUPS) == {"data_efficiency", "new_pushes", "velocities", "objects", "error_variants",
                                    "viewpoint", "visualize", "error_velocities", "rollouts"}
    for setup in spec_lib.SETUPS.values():
        assert spec_lib.parse_models(setup.models) == setup.models


def test_spec_takes_view_and_glimpse_from_the_dataset_and_the_schedule_from_the_scale():
    spec = spec_lib.make_spec(spec_lib.SETUPS["viewpoint"], "smoke", mode="unroll")
    dataset = data_configs.get_config("viewpoint", "smoke")
    assert spec.dataset == spec.test_dataset == dataset
    assert spec.train.model.view == "free" == dataset.camera
    assert spec.train.model.glimpse_size == dataset.glimpse_size
    assert spec.train.num_steps == train_configs.get_config(dataset).num_steps == 200
    assert spec.train_config("hybrid").model.variant == "hybrid"
    assert spec.variants == ("hybrid",) and spec.baselines == ("zero", "physics")
    assert spec.mode == "unroll"


def test_user_choices_replace_the_setup_defaults():
    spec = spec_lib.make_spec(spec_lib.SETUPS["data_efficiency"], "smoke", models=["error", "hybrid", "zero",
                              "error_norm"], sizes=["20", "40"], seeds=["0", "3"], num_steps=7)
    assert spec.variants == ("error", "hybrid", "error_norm") and spec.baselines == ("zero",)
    assert spec.sizes == (20, 40) and spec.seeds == (0, 3) and spec.train.num_steps == 7
    assert spec.sweep_groups() == [("hybrid",), ("error", "error_norm")]


def test_visualize_tests_on_the_repeated_push():
    spec = spec_lib.make_spec(spec_lib.SETUPS["visualize"], "smoke")
    assert spec.dataset.experiment == "data_efficiency" and spec.test_dataset.experiment == "repeated"
    assert spec.test_split_label("test") == "repeated/test"
    assert "scene_transform" in spec.test_fields
    assert spec.to_json()["test_dataset"]["experiment"] == "repeated"


def test_grown_test_splits_are_a_test_only_dataset_of_the_same_experiment():
    spec = spec_lib.make_spec(spec_lib.SETUPS["velocities"], "smoke", testbed="ideal", min_test_sequences=40)
    assert spec.dataset.name == "velocities_smoke_ideal" and spec.test_dataset.name == "velocities_smoke_ideal_test40"
    assert spec.test_split_label("test_20") == "test_20"
    assert spec.to_json()["test_dataset"]["min_test_sequences"] == 40
    with pytest.raises(ValueError, match="^min_test_sequences: the repeated experiment tests one push"):
        spec_lib.make_spec(spec_lib.SETUPS["visualize"], "smoke", min_test_sequences=40)


def test_datasets_are_simulated_on_the_realistic_testbed_unless_ideal_is_chosen():
    default = spec_lib.make_spec(spec_lib.SETUPS["visualize"], "smoke")
    assert default.dataset.testbed == default.test_dataset.testbed == default.to_json()["testbed"] == "realistic"
    ideal = spec_lib.make_spec(spec_lib.SETUPS["visualize"], "smoke", testbed="ideal")
    assert ideal.dataset == data_configs.get_config("data_efficiency", "smoke", testbed="ideal")
    assert ideal.test_dataset.name == "repeated_smoke_ideal" and ideal.to_json()["dataset"]["testbed"] == "ideal"


def test_l_scaled_models():
    spec = spec_lib.make_spec(spec_lib.SETUPS["error_variants"], "smoke")
    assert spec.runs_at("error_grad", 1.0) and not spec.runs_at("error_grad", 3.0) and spec.runs_at("error", 3.0)


def test_to_json_is_strict_json_and_keeps_the_variant_per_row():
    config = spec_lib.make_spec(spec_lib.SETUPS["data_efficiency"], "smoke").to_json()
    assert json.loads(json.dumps(config, allow_nan=False))["dataset"]["experiment"] == "data_efficiency"
    assert "variant" not in config["train"]["model"]
    assert config["dataset"]["scale"] == config["scale"] == "smoke"


@pytest.mark.parametrize("choices, message", [
    (dict(models=["transformer"]), "variants"),
    (dict(sizes=["0"]), "sizes"),
    (dict(seeds=["-1"]), "seeds"),
    (dict(num_steps=0), "num_steps"),
    (dict(mode="parallel"), "mode"),
    (dict(workers=0), "workers"),
    (dict(data_dir="/nonexistent/pushjax"), "data_dir"),
    (dict(testbed="lab"), "testbed"),
    (dict(min_test_sequences=-1), "min_test_sequences"),
])
def test_bad_choices_name_what_is_wrong(choices, message):
    with pytest.raises(ValueError, match=f"^{message}: "):
        spec_lib.make_spec(spec_lib.SETUPS["data_efficiency"], "smoke", **choices)


def test_unknown_scale_is_rejected():
    with pytest.raises(ValueError, match="scale"):
        spec_lib.make_spec(spec_lib.SETUPS["data_efficiency"], "huge")


@pytest.mark.parametrize("splits, message", [
    (dict(train_splits=("bogus",)),
     r"^train_split: 'bogus' is not a split of data_efficiency; choose from train, validation, test$"),
    (dict(test_splits=("train_20",)), r"^test_split: 'train_20' is not a split of data_efficiency"),
])
def test_unknown_splits_are_rejected_before_any_data_is_read(splits, message):
    setup = spec_lib.Setup("train", "data_efficiency", ("hybrid",), **splits)
    with pytest.raises(ValueError, match=message):
        spec_lib.make_spec(setup, "smoke")


def test_split_names_are_those_the_datasets_have_at_every_scale():
    for experiment in data_configs.EXPERIMENTS:
        assert set(spec_lib.split_names(experiment)) == set(
            data_configs.plan_splits(data_configs.get_config(experiment, "cpu"), "").splits)
    for setup in spec_lib.SETUPS.values():
        spec_lib.check_splits(setup)
