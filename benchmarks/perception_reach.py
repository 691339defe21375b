"""How far from its training pushes a trained model's perception still finds the object, and what that does to the
controller that takes its state from it.

1. **A grid of true poses**: each object at yaw 0 and 1 rad, its centre of mass on a square grid around the origin
   (where every training push of the ``data_efficiency`` dataset starts), the pusher 15 cm behind it; the scene is
   rendered as the model's dataset renders it and the perception locates the centre of mass
   (:meth:`pushjax.sensing.perception.PerceptionSensor.locate`). The error by ring (the larger of |x| and |y|, m): the
   median and the largest distance, mm.
2. **The goals of a push-to-goal run** (``--episodes``: its ``results.json``, e.g. ``results/push_to_goal_perception``)
   split by how far the goal is from the origin (``--near``): the successes per state source within and beyond.

    python benchmarks/perception_reach.py --workdir results/perception_reach

Writes ``results.json`` and ``results.md`` to ``--workdir``: about 10 s on 2 cores for the default grid (2 objects x
2 yaws x 81 poses).
"""

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from pushjax import outputs, planar
from pushjax.geometry.objects import get_object
from pushjax.sensing import perception

PUSHER_BEHIND = 0.15
"""Distance of the pusher behind the object's centre of mass along the object's -x axis, m."""


def grid_errors(sensor: perception.PerceptionSensor, objects: list[str], yaws: list[float],
                steps: np.ndarray) -> list[dict]:
    """The location error of every grid pose: [{object, yaw, x, y, ring, error_mm}] (x, y, ring in m)."""
    rows = []
    for obj in objects:
        centroid = get_object(obj).centroid
        for yaw in yaws:
            com = np.array([(x, y) for x in steps for y in steps])
            rotation = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
            poses = np.column_stack([com - centroid @ rotation.T, np.full(len(com), yaw)])
            pushers = com - PUSHER_BEHIND * rotation[:, 0]
            truth = planar.centre_of_mass(centroid, poses)
            found = sensor.locate(obj, poses, pushers)
            errors = np.linalg.norm(found - truth, axis=-1) * 1e3
            rows += [{"object": obj, "yaw": yaw, "x": float(x), "y": float(y),
                      "ring": float(max(abs(x), abs(y))), "error_mm": float(error)}
                     for (x, y), error in zip(com, errors)]
    return rows


def by_ring(rows: list[dict]) -> list[dict]:
    """Per object and ring: the poses, the median and the largest error (mm)."""
    groups = defaultdict(list)
    for row in rows:
        groups[(row["object"], round(row["ring"], 6))].append(row["error_mm"])
    return [{"object": obj, "ring_m": ring, "poses": len(errors), "median_mm": float(np.median(errors)),
             "max_mm": float(np.max(errors))} for (obj, ring), errors in sorted(groups.items())]


def goals_by_distance(episodes: list[dict], near: float) -> list[dict]:
    """Successes per state source for goals within `near` (m) of the origin and beyond (every planner counted)."""
    counts = defaultdict(lambda: [0, 0])
    for episode in episodes:
        where = "near" if np.hypot(*episode["goal"][:2]) <= near else "far"
        count = counts[(episode["state"], where)]
        count[0] += bool(episode["success"])
        count[1] += 1
    return [{"state": state, "goals": where, "successes": hits, "episodes": total}
            for (state, where), (hits, total) in sorted(counts.items())]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workdir", type=Path, required=True, help="where results.json and results.md go")
    parser.add_argument("--model", default="results/track_perception/model", help="the trained model's folder")
    parser.add_argument("--scale", default="cpu_full", help="scale of the data_efficiency dataset it was trained on")
    parser.add_argument("--objects", default="rect2,tri2")
    parser.add_argument("--yaws", default="0,1", help="object yaws, rad")
    parser.add_argument("--extent", type=float, default=0.2, help="the grid's half width, m")
    parser.add_argument("--step", type=float, default=0.05, help="the grid's spacing, m")
    parser.add_argument("--episodes", type=Path, default=Path("results/push_to_goal_perception/results.json"),
                        help="a push-to-goal run's results.json whose goals are split by distance")
    parser.add_argument("--near", type=float, default=0.1, help="goals within this distance of the origin, m")
    args = parser.parse_args()
    try:
        sensor = perception.load_data_efficiency(args.model, args.scale)
    except ValueError as error:
        sys.exit(f"perception_reach.py: --model: {' '.join(str(error).split())}")
    if not args.episodes.is_file():
        sys.exit(f"perception_reach.py: --episodes: no file {args.episodes} (a push-to-goal run's results.json)")
    steps = np.round(np.arange(-args.extent, args.extent + args.step / 2, args.step), 6)
    grid = grid_errors(sensor, args.objects.split(","), [float(yaw) for yaw in args.yaws.split(",")], steps)
    rings = by_ring(grid)
    goals = goals_by_distance(json.loads(args.episodes.read_text())["episodes"], args.near)
    lines = [f"Perception of `{args.model}` ({sensor.description}); pusher {PUSHER_BEHIND * 100:g} cm behind, yaws "
             f"{args.yaws} rad.", "", "| object | ring (max of abs x, y), cm | poses | median error, mm | largest, mm |",
             "|---|---:|---:|---:|---:|"]
    lines += [f"| {row['object']} | {row['ring_m'] * 100:g} | {row['poses']} | {row['median_mm']:.1f} | "
              f"{row['max_mm']:.1f} |" for row in rings]
    lines += ["", f"Goals of `{args.episodes}` within {args.near * 100:g} cm of the origin (near) and beyond (far), "
              "successes per state source, both planners:", "", "| state | goals | successes | episodes |",
              "|---|---|---:|---:|"]
    lines += [f"| {row['state']} | {row['goals']} | {row['successes']} | {row['episodes']} |" for row in goals]
    table = "\n".join(lines) + "\n"
    outputs.write_report(args.workdir, {"model": args.model, "scale": args.scale, "pusher_behind_m": PUSHER_BEHIND,
                                        "grid": grid, "rings": rings, "episodes": str(args.episodes),
                                        "near_m": args.near, "goals": goals}, table)
    print(table)


if __name__ == "__main__":
    main()
