"""``--config.<field>=<value>``: any training-config field replaced from the command line, recorded in results."""

import json

import pytest

from pushjax.paper import spec as spec_lib
from pushjax.train import configs as train_configs

SETUP = spec_lib.SETUPS["data_efficiency"]


def test_overrides_replace_fields_and_are_recorded():
    spec = spec_lib.make_spec(SETUP, "smoke", num_steps=7, config_overrides={
        "learning_rate": "3e-4", "model.head_features": "16,8", "schedule": "cosine", "batch_size": "4"})
    assert (spec.train.learning_rate, spec.train.model.head_features, spec.train.schedule, spec.train.batch_size,
            spec.train.num_steps) == (3e-4, (16, 8), "cosine", 4, 7)
    assert spec.train_config("neural").model.head_features == (16, 8)
    config = json.loads(json.dumps(spec.to_json()))
    assert config["config_overrides"] == {"learning_rate": "3e-4", "model.head_features": "16,8",
                                          "schedule": "cosine", "batch_size": "4"}
    assert config["train"]["learning_rate"] == 3e-4 and config["train"]["model"]["head_features"] == [16, 8]
    assert spec_lib.make_spec(SETUP, "smoke").to_json()["config_overrides"] == {}


@pytest.mark.parametrize(("overrides", "message"), [
    ({"batch_size": "x"}, "config.batch_size: expected an integer, got 'x'"),
    ({"learning_rate": "fast"}, "config.learning_rate: expected a number, got 'fast'"),
    ({"learning_rate": "-1"}, "config.learning_rate: expected > 0"),
    ({"model.error_features": "1,b"}, "config.model.error_features: expected comma-separated integers"),
    ({"model.head_features": "64,,32"}, r"config.model.head_features: expected comma-separated integers > 0 \(e.g. "
                                        r"64,32; no empty item\), got '64,,32'"),
    ({"model.head_features": "64,"}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"model.head_features": ",64"}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"model.head_features": ""}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"model.head_features": "64,0"}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"model.head_features": "64,-32"}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"model.head_features": "64,3.5"}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"model.head_features": "64;32"}, "config.model.head_features: expected comma-separated integers > 0"),
    ({"learning_rate": "nan"}, "config.learning_rate: expected a finite number, got 'nan'"),
    ({"learning_rate": "inf"}, "config.learning_rate: expected a finite number, got 'inf'"),
    ({"weight_decay": "-1"}, "config.weight_decay: expected >= 0"),
    ({"num_steps": "1e3"}, "config.num_steps: expected an integer, got '1e3'"),
    ({"model.glimpse_kernel": "0"}, "config.model.glimpse_kernel: expected a positive kernel side"),
    ({"model.batch_norm_momentum": "1.5"}, r"config.model.batch_norm_momentum: expected a decay in \[0, 1\]"),
    ({"model.glimpse_features": "8,8"}, "config.model.glimpse_features: expected 3 conv layers"),
    ({"bogus": "1"}, "config.bogus: no such training-config field; expected one of model.glimpse_size"),
    ({"model.variant": "neural"}, r"config.model.variant: no such training-config field \(set by the run itself\)"),
])
def test_bad_overrides_name_the_field(overrides, message):
    with pytest.raises(ValueError, match=message) as error:
        train_configs.override(train_configs.get_config(spec_lib.data_configs.get_config("data_efficiency", "smoke")),
                               overrides)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(("text", "value"), [("64,32", (64, 32)), (" 64 , 32 ", (64, 32)), ("8", (8,)),
                                             ("+16,8", (16, 8))])
def test_integer_lists_accept_what_they_should(text, value):
    config = train_configs.override(train_configs.get_config(spec_lib.data_configs.get_config("data_efficiency",
                                                                                               "smoke")),
                                    {"model.head_features": text})
    assert config.model.head_features == value
