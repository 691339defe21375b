"""``python -m experiments.push_to_goal --scale=smoke`` end to end, resuming, and the model and parameter syntax."""

import dataclasses
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pushjax.studies import episode, push_to_goal

REPOSITORY = Path(__file__).resolve().parents[2]


def test_smoke_run_writes_results_and_resumes(tmp_path):
    # A process of its own: the binary's flags clash with the paper binaries' (absl), which tests import.
    result = subprocess.run([sys.executable, "-m", "experiments.push_to_goal", "--scale=smoke",
                             f"--workdir={tmp_path}"], cwd=REPOSITORY, env={**os.environ, "MUJOCO_GL": "egl"},
                            capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stderr[-3000:]
    assert f"wrote {tmp_path / 'results.json'}" in result.stdout
    results = json.loads((tmp_path / "results.json").read_text())
    scale = push_to_goal.SCALES["smoke"]
    assert results["settings"]["scale"] == "smoke"
    episodes = results["episodes"]
    assert len(episodes) == scale.goals_per_object and {row["object"] for row in episodes} == set(scale.objects)
    for row in episodes:
        assert np.isfinite(row["position_error_mm"]) and row["path_length_m"] > 0.05
        assert row["success"] == (row["position_error_mm"] < 5 and abs(row["yaw_error_deg"]) < 5)
    summary = results["summary"]["lynch/gradient"]
    assert summary["goals"] == scale.goals_per_object and 0 <= summary["wilson_95"][0] <= summary["success_rate"]
    assert "| lynch/gradient |" in (tmp_path / "results.md").read_text()
    assert (tmp_path / "trajectories.png").stat().st_size > 5000
    log = (tmp_path / "episodes.jsonl").read_text()
    # The run again with the binary's settings, in this process: every episode is in the log, nothing is simulated.
    again = push_to_goal.run(push_to_goal.PushToGoalConfig.from_scale("smoke"), tmp_path)
    assert (tmp_path / "episodes.jsonl").read_text() == log
    assert again["episodes"] == episodes and json.loads(json.dumps(again["settings"])) == results["settings"]


def test_model_names_and_effect_parameters():
    assert push_to_goal.model_effects("lynch") == ()
    assert push_to_goal.model_effects("lynch+pusher_friction+friction_ratio") == ("pusher_friction", "friction_ratio")
    assert push_to_goal.model_effects("lynch+limit_surface+table_tilt") == ("limit_surface", "table_tilt")
    for bad in ("newton", "lynch+", "lynch+wind", "lynch+limit_surface+friction_ratio"):
        with pytest.raises(ValueError):
            push_to_goal.model_effects(bad)
    params = push_to_goal.parse_effect_params("friction_ratio.log_scale=0.3; cof_offset.offset=0.01,-0.002")
    assert float(params["friction_ratio"]["log_scale"]) == 0.3
    np.testing.assert_allclose(params["cof_offset"]["offset"], [0.01, -0.002])
    for bad, message in (("friction_ratio=0.3", "effect.parameter"), ("wind.speed=1", "unknown effect"),
                         ("friction_ratio.scale=1", "no parameter"), ("cof_offset.offset=1", "2 finite"),
                         ("friction_ratio.log_scale=x", "numbers")):
        with pytest.raises(ValueError, match=message):
            push_to_goal.parse_effect_params(bad)


def _config(**changes) -> push_to_goal.PushToGoalConfig:
    return push_to_goal.PushToGoalConfig(**{"objects": ("rect1",), "goals_per_object": 1, "models": ("lynch",),
                                            "planners": ("gradient",), "seed": 0, "setup": episode.EpisodeConfig(),
                                            **changes})


def test_the_loop_model_needs_its_file(tmp_path):
    with pytest.raises(ValueError, match="loop_model"):
        _config(models=["lynch", "loop"])
    (tmp_path / "model.json").write_text('{"effects": ["wind"], "params": {}, "pusher_friction": 0.3}')
    with pytest.raises(push_to_goal.ModelFileError, match="model.json: effects: unknown 'wind'"):
        push_to_goal.run(_config(models=["loop"], loop_model=tmp_path / "model.json"), tmp_path)
    assert not (tmp_path / "episodes.jsonl").exists()


def test_state_sources_name_the_rows_and_perception_needs_a_source():
    assert push_to_goal.label("lynch", "mocap", ["mocap"]) == "lynch"  # the default keeps the rows' names
    assert push_to_goal.label("lynch", "mocap", ["mocap", "perception"]) == "lynch (mocap)"
    assert push_to_goal.label("loop", "mocap+perception", ["mocap+perception"]) == "loop (mocap + perception)"
    for states, message in ((["perception"], "position source"), (["mocap", "mocap"], "no repeats"),
                            (["camera"], "expected a non-empty list"), ([], "expected a non-empty list")):
        with pytest.raises(ValueError, match=message):
            _config(states=states)


@pytest.mark.parametrize("field, value", [
    ("objects", ()), ("objects", ("box",)), ("objects", ("rect1", "rect1")), ("goals_per_object", 0),
    ("goals_per_object", 1.5), ("models", ()), ("models", ("newton",)), ("models", ("lynch+wind",)),
    ("planners", ("newton",)), ("planners", ("gradient", "gradient")), ("planners", ()), ("seed", -1),
    ("seed", True), ("setup.max_time", math.nan), ("setup.max_time", 0.5), ("effect_params", "friction_ratio=1"),
    ("effect_params", "wind.speed=1"), ("states", ("camera",)), ("looks", 0), ("looks", 6)])
def test_a_bad_field_is_a_value_error_naming_it(field, value):
    change = ({"setup": episode.EpisodeConfig(max_time=value)} if field == "setup.max_time" else {field: value})
    with pytest.raises(ValueError, match=rf"^{re.escape(field)}: "):
        _config(**change)


def test_scales_are_configs_with_their_overrides():
    smoke = push_to_goal.PushToGoalConfig.from_scale("smoke")
    assert smoke == dataclasses.replace(push_to_goal.SCALES["smoke"], scale="smoke")
    assert (smoke.objects, smoke.goals_per_object, smoke.planners, smoke.setup.max_time) == (
        ("rect1",), 2, ("gradient",), 30.0)
    changed = push_to_goal.PushToGoalConfig.from_scale("cpu", objects=["tri1"], goals_per_object=None, max_time=12.0,
                                                       surface="delrin", models=["lynch", "lynch+friction_ratio"])
    assert changed.objects == ("tri1",) and changed.models == ("lynch", "lynch+friction_ratio")
    assert changed.goals_per_object == push_to_goal.SCALES["cpu"].goals_per_object  # None keeps the scale's
    assert changed.setup == episode.EpisodeConfig(max_time=12.0, surface="delrin")
    with pytest.raises(ValueError, match="^scale: "):
        push_to_goal.PushToGoalConfig.from_scale("huge")
    with pytest.raises(ValueError, match="^setup.max_time: "):
        push_to_goal.PushToGoalConfig.from_scale("smoke", max_time=math.inf)
    with pytest.raises(dataclasses.FrozenInstanceError):
        smoke.seed = 1
