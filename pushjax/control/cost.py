"""What a plan costs: the distance of the predicted object poses from the goal, and the pusher's effort.

    cost = e(pose_T) + running_weight mean_t e(pose_t) + effort_weight mean_t |u_t|^2 / limit^2
    e(pose) = |position - goal position|^2 / position_scale^2 + wrap(yaw - goal yaw)^2 / yaw_scale^2

(``u_t`` the pusher increments). The errors are dimensionless: ``position_scale`` (m) and ``yaw_scale`` (rad)
say how much of one equals one unit of the other.
"""

from __future__ import annotations

import flax.struct
import jax.numpy as jnp

from pushjax.control import path as path_lib
from pushjax.control.model import PlanningModel, predict

__all__ = ["CostWeights", "plan_cost", "pose_error", "trajectory_cost", "wrap"]


@flax.struct.dataclass
class CostWeights:
    """Weights of :func:`trajectory_cost` (static: hashable, part of a controller's configuration).

    Attributes:
      position_scale: position error counted as one unit, m.
      yaw_scale: orientation error counted as one unit, rad.
      running_weight: weight of the mean error along the horizon against the terminal error.
      effort_weight: weight of the mean squared increment (over the squared largest increment).
    """

    position_scale: float = flax.struct.field(pytree_node=False, default=0.01)
    yaw_scale: float = flax.struct.field(pytree_node=False, default=0.1)
    running_weight: float = flax.struct.field(pytree_node=False, default=0.5)
    effort_weight: float = flax.struct.field(pytree_node=False, default=0.05)


def wrap(angle):
    """Angles wrapped to (-pi, pi], rad."""
    return jnp.arctan2(jnp.sin(angle), jnp.cos(angle))


def pose_error(pose, goal):
    """([...] position error m, [...] wrapped orientation error rad) of poses [..., 3] from the goal [3]."""
    difference = pose[..., :2] - goal[:2]
    return jnp.sqrt(jnp.sum(difference * difference, axis=-1)), wrap(pose[..., 2] - goal[2])


def _squared_error(poses, goal, weights: CostWeights):
    difference = poses[..., :2] - goal[:2]
    yaw = wrap(poses[..., 2] - goal[2])
    return jnp.sum(difference * difference, axis=-1) / weights.position_scale ** 2 + (yaw / weights.yaw_scale) ** 2


def trajectory_cost(poses, steps, goal, limit, weights: CostWeights):
    """(cost [], metrics) of predicted poses [H + 1, 3] under pusher increments `steps` [H, 2] (m).

    Args:
      poses: predicted object poses (x m, y m, yaw rad), the first the current one.
      steps: the pusher increments, m.
      goal: [3] goal pose.
      limit: [] largest increment, m.
      weights: the :class:`CostWeights`.

    Returns:
      (cost, {"terminal", "running", "effort"}: its dimensionless parts before weighting).
    """
    errors = _squared_error(poses, goal, weights)
    terminal, running = errors[-1], jnp.mean(errors[1:])
    effort = jnp.mean(jnp.sum(steps * steps, axis=-1)) / limit ** 2
    cost = terminal + weights.running_weight * running + weights.effort_weight * effort
    return cost, {"terminal": terminal, "running": running, "effort": effort}


def plan_cost(model: PlanningModel, pose, goal, start, raw, limit, weights: CostWeights):
    """(cost [], metrics) of the plan `raw` [H, 2] (:mod:`pushjax.control.path`) from the pusher at `start` [2]
    (world, m) and the object at `pose` [3], predicted by `model`."""
    path = path_lib.pusher_path(start, raw, limit)
    poses = predict(model, pose, path).poses
    return trajectory_cost(poses, jnp.diff(path, axis=0), goal, limit, weights)
