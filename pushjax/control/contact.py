"""Where to push: candidate contacts around the outline, scored in one ``jax.vmap``, and the way there.

The candidates are ``count`` points spread evenly by arc length over the outline, each with its inward normal
(:func:`candidates`). :func:`score_candidates` predicts, for every candidate and every direction within
``max_angle`` of its normal, a straight push at the largest increment from the approach point (the pusher
``standoff`` off the outline along the normal) and costs it; the cheapest tells the controller which side to push
next. :func:`detour` is the pusher's way to that approach point without touching the object: straight away from
the centre of mass to a clearance circle, along the shorter arc of that circle, and in along the candidate's
normal. For a convex outline neither straight leg brings the pusher closer to the object (the distance to a
convex set is convex along a line, and both legs run away from a point of the set); the arc's polygon keeps its
chords on or outside the circle.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from pushjax.control import cost as cost_lib
from pushjax.control import path as path_lib
from pushjax.control.model import PlanningModel
from pushjax.geometry import outline_jax

__all__ = ["approach_points", "candidates", "clearance_radius", "detour", "rotate", "score_candidates"]


def rotate(vector, yaw):
    """[..., 2] vectors turned counter-clockwise by `yaw` (rad)."""
    cos, sin = jnp.cos(yaw), jnp.sin(yaw)
    return jnp.stack([cos * vector[..., 0] - sin * vector[..., 1], sin * vector[..., 0] + cos * vector[..., 1]],
                     axis=-1)


def candidates(shape: outline_jax.Outline, count: int):
    """([count, 2] points on the outline, [count, 2] unit inward normals), object frame, m, evenly spread by arc
    length (the first half a spacing after the first vertex)."""
    lengths = jnp.sqrt(jnp.sum(shape.edge * shape.edge, axis=-1))
    ends = jnp.cumsum(lengths)
    along = (jnp.arange(count, dtype=lengths.dtype) + 0.5) / count * ends[-1]
    index = jnp.minimum(jnp.searchsorted(ends, along, side="right"), len(lengths) - 1)
    fraction = (along - (ends[index] - lengths[index])) / lengths[index]
    points = shape.start[index] + fraction[:, None] * shape.edge[index]
    return points, -shape.outward[index]


def approach_points(shape: outline_jax.Outline, pose, points, normals, distance):
    """([K, 2] pusher centres `distance` (m) off the outline points along their normals, [K, 2] the normals), world,
    for the object at `pose` [3]; `points`, `normals` [K, 2] in the object frame."""
    world_normals = rotate(normals, pose[2])
    return pose[:2] + rotate(points, pose[2]) - distance * world_normals, world_normals


def score_candidates(model: PlanningModel, pose, goal, horizon: int, limit, weights: cost_lib.CostWeights, count: int,
                     directions: int, max_angle: float, standoff: float, lengths: tuple[int, ...]):
    """Costs of straight pushes from every candidate's approach point.

    Args:
      model: the :class:`~pushjax.control.model.PlanningModel`.
      pose: [3] object pose (x m, y m, yaw rad).
      goal: [3] goal pose.
      horizon: steps of each push.
      limit: [] largest pusher increment per step, m (each push moves at 0.95 of it).
      weights: the cost's :class:`~pushjax.control.cost.CostWeights`.
      count: candidate contacts.
      directions: push directions per candidate, evenly within ``max_angle`` (rad) of the normal (1: the normal).
      max_angle: rad.
      standoff: gap between the pusher and the outline at the approach point, m.
      lengths: the pushes' numbers of moving steps (each at most ``horizon``; the pusher stands still after).

    Returns:
      (costs [count, directions * len(lengths)], approach points [count, 2] and inward normals [count, 2] world,
      raw plans [count, directions * len(lengths), horizon, 2]).
    """
    points, normals = candidates(model.shape, count)
    approach, world_normals = approach_points(model.shape, pose, points, normals, model.radius + standoff)
    angles = jnp.linspace(-max_angle, max_angle, directions) if directions > 1 else jnp.zeros(1)
    turned = rotate(world_normals[:, None, :], angles[None, :])
    raw = path_lib.raw_for(0.95 * limit * turned, limit)
    moving = jnp.arange(horizon)[None, :] < jnp.asarray(lengths)[:, None]
    plans = (raw[:, :, None, None, :] * moving[None, None, :, :, None]).reshape(count, -1, horizon, 2)

    def cost_of(start, plan):
        return cost_lib.plan_cost(model, pose, goal, start, plan, limit, weights)[0]

    costs = jax.vmap(jax.vmap(cost_of, in_axes=(None, 0)))(approach, plans)
    return costs, approach, world_normals, plans


def clearance_radius(shape: outline_jax.Outline, radius, clearance):
    """[] radius (m) of the circle about the centre of mass on which the pusher travels around the object: the
    farthest outline vertex plus the pusher radius plus `clearance`."""
    reach = jnp.max(jnp.sqrt(jnp.sum((shape.start - shape.centroid) ** 2, axis=-1)))
    return reach + radius + clearance


def detour(shape: outline_jax.Outline, pose, pusher, target, normal, radius, clearance, arc_points: int):
    """[arc_points + 4, 2] waypoints (world, m) of the pusher from `pusher` [2] to the approach point `target` [2]
    of a contact with world inward `normal` [2], around the object at `pose` [3] (see the module docstring)."""
    com = pose[:2] + rotate(shape.centroid, pose[2])
    circle = clearance_radius(shape, radius, clearance)
    away = pusher - com
    distance = jnp.sqrt(jnp.sum(away * away))
    direction = jnp.where(distance > 1e-9, away / jnp.where(distance > 1e-9, distance, 1.0),
                          jnp.array([1.0, 0.0], pusher.dtype))
    leave = com + jnp.maximum(distance, circle) * direction
    offset = target - com
    along = jnp.dot(offset, normal)
    back = along + jnp.sqrt(jnp.maximum(along ** 2 - jnp.dot(offset, offset) + circle ** 2, 0.0))
    enter = target - jnp.maximum(back, 0.0) * normal
    first = jnp.arctan2(direction[1], direction[0])
    turn = cost_lib.wrap(jnp.arctan2(enter[1] - com[1], enter[0] - com[0]) - first)
    angles = first + turn * jnp.arange(1, arc_points + 1) / (arc_points + 1)
    # Vertices beyond the circle by the chords' sagitta, so that the chords stay outside it.
    polygon_radius = jnp.maximum(distance, circle) / jnp.cos(turn / (2 * (arc_points + 1)))
    arc = com + polygon_radius * jnp.stack([jnp.cos(angles), jnp.sin(angles)], axis=-1)
    return jnp.concatenate([pusher[None], leave[None], arc, enter[None], target[None]])
