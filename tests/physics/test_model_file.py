"""A pushing model on disk: written and read back exactly, parameters filled up, bad files named in one line."""

import json

import numpy as np
import pytest

from pushjax.physics import model_file


def test_a_model_is_read_back_as_written_with_missing_parameters_at_their_no_effect_values(tmp_path):
    model = model_file.AugmentedModel.create(("table_tilt", "limit_surface"),
                                             {"table_tilt": {"drift_force": [0.05, -0.01]},
                                              "limit_surface": {"rim": 0.2}}, 0.26)
    assert model.effects == ("table_tilt", "limit_surface")
    assert float(model.params["limit_surface"]["feet"]) == 0.0
    again = model_file.read(model_file.write(tmp_path / "model.json", model))
    assert again.as_dict() == model.as_dict() and again.mu == 0.26
    np.testing.assert_array_equal(again.params["table_tilt"]["drift_force"], [0.05, -0.01])


@pytest.mark.parametrize("content, message", [
    ("not json", "expected a pushing model file"),
    (json.dumps({"effects": []}), "effects, params and pusher_friction"),
    (json.dumps({"effects": ["wind"], "params": {}, "pusher_friction": 0.3}), "unknown 'wind'"),
    (json.dumps({"effects": [], "params": {"inertia": {}}, "pusher_friction": 0.3}), "not among the composed"),
    (json.dumps({"effects": ["inertia"], "params": {"inertia": {"k": 1}}, "pusher_friction": 0.3}), "no parameter"),
    (json.dumps({"effects": ["table_tilt"], "params": {"table_tilt": {"drift_force": 1.0}}, "pusher_friction": 0.3}),
     "table_tilt.drift_force expected"),
    (json.dumps({"effects": [], "params": {}, "pusher_friction": -1}), "pusher_friction"),
])
def test_bad_files_are_named_in_one_line(tmp_path, content, message):
    path = tmp_path / "model.json"
    path.write_text(content)
    with pytest.raises(ValueError, match=message) as error:
        model_file.read(path)
    assert str(path) in str(error.value) and "\n" not in str(error.value)
    with pytest.raises(ValueError, match="expected a pushing model file"):
        model_file.read(tmp_path / "missing.json")
