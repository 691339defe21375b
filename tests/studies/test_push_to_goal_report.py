"""The report: summaries per model/planner and object with Wilson intervals, the table and the figure."""

import json

import numpy as np
import pytest

from pushjax.control import goals
from pushjax.studies import push_to_goal


def _row(model, obj, index, position_mm, yaw_deg):
    poses = np.array([[0.0, 0.0, 0.0, 0.0], [1.0, 0.05, 0.0, 0.2]])
    return {"model": model, "planner": "gradient", "object": obj, "index": index, "start": [0.0, 0.0, 0.0],
            "goal": [0.05, 0.0, 0.2], "final_pose": [0.05, 0.0, 0.2], "position_error_mm": position_mm,
            "yaw_error_deg": yaw_deg, "success": goals.succeeded(position_mm / 1e3, np.radians(yaw_deg)),
            "path_length_m": 0.3, "time_s": 10.0, "wall_s": 2.0, "plans": 20, "repositions": 2, "stop": "reached",
            "trajectory": {"poses": poses.tolist(), "pusher": [[0.0, -0.06, 0.0], [1.0, -0.01, 0.0]]}}


def test_summaries_tables_and_figure(tmp_path):
    rows = [_row("lynch", "rect1", 0, 1.0, 0.5), _row("lynch", "rect1", 1, 7.0, 0.5),
            _row("lynch", "tri2", 0, 2.0, -6.0), _row("lynch+friction_ratio", "rect1", 0, 1.0, 1.0)]
    results = push_to_goal.summarise(rows, {"seed": 0, "loop": {"max_time": 60.0}})
    lynch = results["summary"]["lynch/gradient"]
    assert (lynch["goals"], lynch["successes"]) == (3, 1)
    np.testing.assert_allclose(lynch["wilson_95"], goals.wilson_interval(1, 3))
    assert lynch["position_error_mm_median"] == 2.0 and lynch["yaw_error_deg_median"] == 0.5
    assert results["per_object"]["lynch/gradient"]["rect1"]["successes"] == 1
    assert results["criterion"] == {"position_mm": 5.0, "yaw_deg": 5.0, "comparison_standard_errors": 2.0}
    assert [entry["goals"] for entry in results["comparisons"]] == [1]
    paths = push_to_goal.write(results, tmp_path)
    assert json.loads(paths[0].read_text())["summary"]["lynch/gradient"]["goals"] == 3
    text = paths[1].read_text()
    assert "| lynch/gradient | 1/3 | 33 % [6, 79] |" in text and "| lynch/gradient, tri2 | 0/1 |" in text
    assert paths[2].stat().st_size > 5000


def test_a_model_that_reaches_the_same_goals_sooner_is_better_and_a_failure_counts_as_the_time_limit():
    rows = []
    for index in range(6):
        rows.append(_row("lynch", "rect1", index, 1.0, 0.5) | {"time_s": 30.0 + index})
        rows.append(_row("loop", "rect1", index, 1.0, 0.5) | {"time_s": 20.0 + 2 * index})
    better = push_to_goal.compare(rows, "lynch", "loop", max_time=60.0)
    assert better["goals"] == 6 and better["verdict"] == "better"
    np.testing.assert_allclose(better["time_to_success_difference_s"]["mean"], -7.5)
    assert push_to_goal.compare(rows, "loop", "lynch", max_time=60.0)["verdict"] == "worse"
    # One failure of the faster model (at 25 s, 7 mm off) costs it the time limit: 60 - 35 = +25 s on that goal.
    rows[-1] = rows[-1] | {"success": False, "position_error_mm": 7.0, "time_s": 25.0}
    mixed = push_to_goal.compare(rows, "lynch", "loop", max_time=60.0)
    np.testing.assert_allclose(mixed["time_to_success_difference_s"]["mean"], (-10 - 9 - 8 - 7 - 6 + 25) / 6)
    assert mixed["verdict"] == "not decided" and mixed["only_baseline_succeeded"] == 1
    text = push_to_goal.table(push_to_goal.summarise(rows, {"loop": {"max_time": 60.0}}))
    assert "| loop − lynch | 6 |" in text and "not decided" in text


def test_a_goal_planned_by_two_planners_is_one_independent_unit():
    rows = [_row(model, "rect1", index, 1.0, 0.5) | {"planner": planner, "time_s": time + index}
            for index in range(4) for planner in ("gradient", "sampling")
            for model, time in (("lynch", 30.0), ("loop", 28.0 if planner == "gradient" else 26.0))]
    result = push_to_goal.compare(rows, "lynch", "loop", max_time=60.0)
    assert result["goals"] == 4
    np.testing.assert_allclose(result["time_to_success_difference_s"]["mean"], -3.0)
    assert result["time_to_success_difference_s"]["standard_error"] == 0.0


def test_a_second_look_needs_pococks_bound():
    # Paired differences -0.355, -3.645, ... s: a mean of -2 s at 2.1 standard errors, beyond 2 but not 2.178.
    rows = []
    for index, difference in enumerate((-0.355, -3.645, -0.355, -3.645)):
        rows.append(_row("lynch", "rect1", index, 1.0, 0.5) | {"time_s": 30.0})
        rows.append(_row("loop", "rect1", index, 1.0, 0.5) | {"time_s": 30.0 + difference})
    assert push_to_goal.compare(rows, "lynch", "loop", max_time=60.0)["verdict"] == "better"
    assert push_to_goal.compare(rows, "lynch", "loop", max_time=60.0, looks=2)["verdict"] == "not decided"
    results = push_to_goal.summarise(rows, {"loop": {"max_time": 60.0}}, looks=2)
    assert results["criterion"]["looks"] == 2 and results["criterion"]["comparison_standard_errors"] == 2.178
    assert "look 2 at the same comparison" in push_to_goal.table(results)


def test_runs_in_several_worlds_pool_their_goals_without_pairing_across_worlds():
    def run(seed, loop_times):
        episodes = [_row(model, "rect1", index, 1.0, 0.5) | {"time_s": time}
                    for index, loop_time in enumerate(loop_times)
                    for model, time in (("lynch", 30.0), ("loop", loop_time))]
        return {"settings": {"seed": seed, "loop": {"max_time": 60.0}}, "episodes": episodes}

    # Goal 0 of world 1 and goal 0 of world 2 are different goals: 4 goals in all, not 2 paired twice.
    pooled = push_to_goal.pool_worlds([run(1, [28.0, 27.0]), run(2, [26.0, 29.0])])
    (comparison,) = pooled["comparisons"]
    assert comparison["goals"] == 4 and pooled["settings"]["worlds"] == [1, 2]
    np.testing.assert_allclose(comparison["time_to_success_difference_s"]["mean"], -2.5)
    assert comparison["verdict"] == "better"
    assert pooled["summary"]["loop/gradient"]["goals"] == 4
    for runs in ([run(1, [28.0])], [run(1, [28.0]), run(1, [27.0])]):
        with pytest.raises(ValueError, match="two or more different worlds"):
            push_to_goal.pool_worlds(runs)
