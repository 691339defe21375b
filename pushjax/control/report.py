"""The push-to-goal report: per episode rows, summaries per model and planner (and per object) with Wilson
intervals, ``results.json``, a markdown table and a figure of trajectories.

Units in the report: mm and degrees for errors, m for the pusher's path, s for times.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pushjax import outputs, planar, stats
from pushjax.control import goals
from pushjax.geometry.objects import PUSHER_RADIUS, get_object

__all__ = ["compare", "episode_row", "figure", "summarise", "table", "write"]


def episode_row(task: goals.Goal, result, stride: int) -> dict:
    """The JSON row of one episode (a :class:`pushjax.control.closed_loop.EpisodeResult`): errors, success, path,
    times, and the trajectory every `stride` control periods (and the last)."""
    keep = np.unique(np.append(np.arange(0, len(result.poses), stride), len(result.poses) - 1))
    return {
        "start": list(task.start), "goal": list(task.goal), "final_pose": result.final_pose.tolist(),
        "position_error_mm": 1e3 * result.position_error, "yaw_error_deg": math.degrees(result.yaw_error),
        "success": goals.succeeded(result.position_error, result.yaw_error), "path_length_m": result.path_length,
        "time_s": result.time, "wall_s": result.wall_time, "plans": result.plans, "repositions": result.repositions,
        "stop": result.stop,
        **({"readings": len(result.readings), "skipped_readings": result.skipped_readings} if len(result.readings)
           else {}),
        "trajectory": {"poses": result.poses[keep].tolist(), "pusher": result.pusher[keep].tolist()},
    }


def _summary(rows: Sequence[dict]) -> dict:
    successes = sum(row["success"] for row in rows)
    low, high = goals.wilson_interval(successes, len(rows))
    position = np.array([row["position_error_mm"] for row in rows])
    yaw = np.abs([row["yaw_error_deg"] for row in rows])
    return {
        "goals": len(rows), "successes": successes, "success_rate": successes / len(rows),
        "wilson_95": [low, high], "position_error_mm_median": float(np.median(position)),
        "position_error_mm_mean": float(np.mean(position)), "yaw_error_deg_median": float(np.median(yaw)),
        "yaw_error_deg_mean": float(np.mean(yaw)),
        "path_length_m_mean": float(np.mean([row["path_length_m"] for row in rows])),
        "time_s_mean": float(np.mean([row["time_s"] for row in rows])),
        "wall_s_mean": float(np.mean([row["wall_s"] for row in rows])),
        "stops": {stop: sum(row["stop"] == stop for row in rows) for stop in sorted({row["stop"] for row in rows})},
    }


def compare(rows: Sequence[dict], baseline: str, model: str, max_time: float, looks: int = 1) -> dict:
    """`model` against `baseline` on the goals both were given (paired by planner, world, object and goal; a goal's
    differences averaged over its planners, so that the goals are the unit of resampling), decided on the time to
    success by :func:`pushjax.stats.decide` at the `looks`-th look at the comparison.

    Returns:
      ``{"model", "baseline", "goals", "time_to_success_difference_s": {"mean", "standard_error"},
      "position_error_difference_mm": {"mean", "standard_error"}, "only_model_succeeded",
      "only_baseline_succeeded", "verdict"}``; differences are `model` minus `baseline`, a failed goal's time to
      success is `max_time` (s), and the verdict is "better", "worse" or "not decided".
    """
    def by_goal(name):
        return {(row["planner"], row.get("world", 0), row["object"], row["index"]): row for row in rows
                if row["model"] == name}

    ours, theirs = by_goal(model), by_goal(baseline)
    keys = sorted(set(ours) & set(theirs))

    def time_to_success(row):
        return row["time_s"] if row["success"] else max_time

    tasks = sorted({key[1:] for key in keys})  # the goals; a goal's planners are averaged, not counted apart

    def paired(value):
        difference = np.array([np.mean([value(ours[key]) - value(theirs[key]) for key in keys if key[1:] == task])
                               for task in tasks])
        error = float(np.std(difference, ddof=1) / math.sqrt(len(tasks))) if len(tasks) > 1 else math.inf
        return {"mean": float(np.mean(difference)) if tasks else math.nan, "standard_error": error}

    time = paired(time_to_success)
    verdict = {stats.HOLDS: "better", stats.FAILS: "worse", stats.UNDECIDED: "not decided"}[
        stats.decide(time["mean"], time["standard_error"], looks)]
    return {"model": model, "baseline": baseline, "goals": len(tasks), "time_to_success_difference_s": time,
            "position_error_difference_mm": paired(lambda row: row["position_error_mm"]),
            "only_model_succeeded": sum(ours[key]["success"] and not theirs[key]["success"] for key in keys),
            "only_baseline_succeeded": sum(theirs[key]["success"] and not ours[key]["success"] for key in keys),
            "verdict": verdict}


def summarise(rows: Sequence[dict], settings: dict, looks: int = 1) -> dict:
    """``{"criterion", "settings", "summary": {model/planner: ...}, "per_object": {model/planner: {object: ...}},
    "comparisons": [every other model against the first, :func:`compare` at the `looks`-th look], "episodes":
    rows}``; the criterion records the look when it is not the first."""
    groups: dict[str, list[dict]] = {}
    for row in rows:
        groups.setdefault(f"{row['model']}/{row['planner']}", []).append(row)
    per_object = {}
    for name, members in groups.items():
        objects = sorted({row["object"] for row in members})
        per_object[name] = {obj: _summary([row for row in members if row["object"] == obj]) for obj in objects}
    models = list(dict.fromkeys(row["model"] for row in rows))
    comparisons = [compare(rows, models[0], model, settings["loop"]["max_time"], looks) for model in models[1:]]
    criterion = {"position_mm": 1e3 * goals.SUCCESS_POSITION, "yaw_deg": goals.SUCCESS_YAW_DEG,
                 "comparison_standard_errors": stats.decision_bound(looks), **({"looks": looks} if looks > 1 else {})}
    return {"criterion": criterion,
            "settings": settings, "summary": {name: _summary(members) for name, members in groups.items()},
            "per_object": per_object, "comparisons": comparisons, "episodes": list(rows)}


def pool_worlds(runs: Sequence[dict]) -> dict:
    """The results of push-to-goal runs in several worlds (each run's ``settings["seed"]``: its goals and testbed
    draws) as one :func:`summarise`: every goal of every world paired across the models, the goals of all worlds the
    unit of the comparisons; ``settings`` holds each run's under ``"runs"``.

    Raises:
      ValueError: fewer than two runs, two runs of one world, or runs of different models or time limits.
    """
    worlds = [run["settings"]["seed"] for run in runs]
    if len(runs) < 2 or len(set(worlds)) != len(worlds):
        raise ValueError(f"runs: expected runs of two or more different worlds (seeds), got seeds {worlds}")
    models = [list(dict.fromkeys(row["model"] for row in run["episodes"])) for run in runs]
    limits = {run["settings"]["loop"]["max_time"] for run in runs}
    if any(names != models[0] for names in models) or len(limits) != 1:
        raise ValueError(f"runs: expected the same models and time limit in every run, got {models} and {limits}")
    rows = [{**row, "world": world} for run, world in zip(runs, worlds) for row in run["episodes"]]
    return summarise(rows, {"worlds": worlds, "loop": runs[0]["settings"]["loop"],
                            "runs": [run["settings"] for run in runs]})


def _line(label: str, entry: dict) -> str:
    low, high = entry["wilson_95"]
    return (f"| {label} | {entry['successes']}/{entry['goals']} | {100 * entry['success_rate']:.0f} % "
            f"[{100 * low:.0f}, {100 * high:.0f}] | {entry['position_error_mm_median']:.1f} | "
            f"{entry['yaw_error_deg_median']:.1f} | {entry['path_length_m_mean']:.2f} | {entry['time_s_mean']:.1f} | "
            f"{entry['wall_s_mean']:.1f} |")


def table(results: dict) -> str:
    """Markdown: one row per model/planner, then one per model/planner and object."""
    criterion = results["criterion"]
    header = ("| {} | successes | success rate [Wilson 95 %] | median position error (mm) | median orientation error "
              "(deg) | mean pusher path (m) | mean time (s) | mean wall time (s) |\n|---|---:|---:|---:|---:|---:|---:|---:|")
    lines = [f"Success: final position error < {criterion['position_mm']:g} mm and orientation error < "
             f"{criterion['yaw_deg']:g} deg.", ""]
    position = results["settings"].get("position")
    if position:
        noise = ", ".join(f"{1e3 * value:.2f}" for value in position["std_m"])
        gate = f", readings beyond a squared innovation of {position['gate']:g} skipped" if "gate" in position else ""
        lines += [f"State sources: {', '.join(results['settings']['states'])}; perception: {position['description']}, "
                  f"a reading every {position['every_periods']} control period(s), noise std {noise} mm (x, y){gate}.",
                  ""]
    lines += [header.format("model / planner")]
    lines += [_line(name, entry) for name, entry in results["summary"].items()]
    if results.get("comparisons"):
        lines += ["", (f"Comparisons (paired over goals; better: the mean difference of the time to success, a failure "
                       f"counting as the time limit, below zero by more than {criterion['comparison_standard_errors']:g} "
                       "standard errors" + (f", look {criterion['looks']} at the same comparison" if "looks" in criterion
                                            else "") + "):"), "",
                  "| model − baseline | goals | time to success (s) | final position error (mm) | only model succeeded "
                  "| only baseline succeeded | verdict |", "|---|---:|---:|---:|---:|---:|---|"]
        for entry in results["comparisons"]:
            time, position = entry["time_to_success_difference_s"], entry["position_error_difference_mm"]
            lines.append(f"| {entry['model']} − {entry['baseline']} | {entry['goals']} | {time['mean']:+.1f} ± "
                         f"{time['standard_error']:.1f} | {position['mean']:+.1f} ± {position['standard_error']:.1f} | "
                         f"{entry['only_model_succeeded']} | {entry['only_baseline_succeeded']} | {entry['verdict']} |")
    lines += ["", header.format("model / planner, object")]
    lines += [_line(f"{name}, {obj}", entry) for name, objects in results["per_object"].items()
              for obj, entry in objects.items()]
    return "\n".join(lines) + "\n"


def figure(results: dict, path: Path, count: int = 4) -> None:
    """A few episodes: the object's outline over time (light to dark), the goal (dashed), the pusher's path."""
    episodes = results["episodes"][:count]
    axes = plt.subplots(1, len(episodes), figsize=(3.4 * len(episodes), 3.4), squeeze=False)[1][0]
    drawing = axes[0].figure
    for axis, row in zip(axes, episodes):
        outline = get_object(row["object"]).outline
        poses = np.asarray(row["trajectory"]["poses"])
        for shade, pose in zip(np.linspace(0.2, 1.0, len(poses)), poses):
            points = pose[1:3] + planar.rotate(outline, pose[3])
            axis.fill(*points.T, color=plt.cm.Blues(shade), alpha=0.35, linewidth=0.5, edgecolor="k")
        goal = np.asarray(row["goal"])
        goal_points = goal[:2] + planar.rotate(outline, goal[2])
        axis.plot(*np.vstack([goal_points, goal_points[:1]]).T, "r--", linewidth=1.2, label="goal")
        pusher = np.asarray(row["trajectory"]["pusher"])
        axis.plot(pusher[:, 1], pusher[:, 2], "-", color="0.3", linewidth=0.8, label="pusher")
        axis.plot(*pusher[-1, 1:3], "o", color="0.3", markersize=2 * 1e3 * PUSHER_RADIUS / 3)
        axis.set_aspect("equal")
        axis.set_title(f"{row['object']} #{row['index']} ({row['model']}/{row['planner']})\n"
                       f"{row['position_error_mm']:.1f} mm, {row['yaw_error_deg']:.1f} deg", fontsize=8)
        axis.tick_params(labelsize=7)
    axes[0].legend(fontsize=7, loc="best")
    drawing.tight_layout()
    drawing.savefig(path, dpi=100)
    plt.close(drawing)


def write(results: dict, workdir: str | Path) -> list[Path]:
    """Writes ``results.json``, ``results.md`` and ``trajectories.png`` to `workdir`; returns their paths."""
    return outputs.write_results(workdir, results, table(results), "trajectories.png", figure)
