"""Receding-horizon control of the pusher's path: plan, execute the first steps, observe, plan again.

Every :func:`replan` (one jit-compiled call per configuration and set of effect names) does three things with the
observed object pose, the pusher's position and the goal:

1. plans from where the pusher is: the planner of :data:`PLANNERS` named by :attr:`ControllerConfig.planner`
   (``"gradient"``: :mod:`pushjax.control.gradient`, ``"sampling"``: :mod:`pushjax.control.sampling`), warm-started
   from the last plan advanced by the executed steps;
2. scores every candidate contact around the outline (:func:`pushjax.control.contact.score_candidates`);
3. decides to reposition when the best candidate beats the plan from here by the factor ``switch_ratio``, or when
   the plan from here is no better than standing still (the pusher has lost the object or cannot move it towards
   the goal from this side) and the candidate is. A reposition returns the detour's waypoints and sets the plan to the candidate's
   straight push, which the next call refines.

Every plan respects the speed limit by construction (:mod:`pushjax.control.path`). The module is a
:class:`pushjax.control.controller.Controller`: :func:`init` and :func:`replan`, whose answer is a
:class:`~pushjax.control.controller.Command`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import NamedTuple

import flax.struct
import jax
import jax.numpy as jnp

from pushjax.control import contact, gradient, sampling
from pushjax.control import cost as cost_lib
from pushjax.control import path as path_lib
from pushjax.control.controller import Command
from pushjax.control.model import PlanningModel, predict

__all__ = ["PLANNERS", "ControllerConfig", "ControllerState", "Planner", "init", "replan"]


class Planner(NamedTuple):
    """A planner of :data:`PLANNERS`.

    Attributes:
      plan: ``(model, pose, goal, start, raw, limit, weights, settings, key) -> (raw, cost)``.
      settings: the :class:`ControllerConfig` field that holds its settings.
    """

    plan: Callable
    settings: str


PLANNERS = {"gradient": Planner(gradient.plan, "gradient"), "sampling": Planner(sampling.plan, "sampling")}
"""The planners by name, the one place a planner is chosen (:attr:`ControllerConfig.planner`)."""


@flax.struct.dataclass
class ControllerConfig:
    """Static settings of the controller (hashable: one compilation per configuration).

    Attributes:
      planner: a name of :data:`PLANNERS`.
      horizon: steps planned ahead.
      period: duration of one step, s.
      speed_limit: the pusher's largest speed, m/s.
      replan_steps: steps executed between two plans (re-planning at ``1 / (replan_steps period)`` Hz).
      weights: the cost's :class:`~pushjax.control.cost.CostWeights`.
      gradient: the gradient planner's :class:`~pushjax.control.gradient.GradientConfig`.
      sampling: the sampling planner's :class:`~pushjax.control.sampling.SamplingConfig`.
      candidates: candidate contacts around the outline.
      directions: push directions scored per candidate.
      push_fractions: lengths of the scored pushes, fractions of the horizon (short ones for fine corrections).
      max_angle: largest angle of a scored direction from the candidate's normal, rad.
      standoff: gap between the pusher and the outline at an approach point, m.
      clearance: gap kept between the pusher and the object's farthest vertex while going around it, m.
      arc_points: waypoints of the detour's arc.
      switch_ratio: a candidate replaces the plan from here when its cost is below this times the plan's.
    """

    planner: str = flax.struct.field(pytree_node=False, default="gradient")
    horizon: int = flax.struct.field(pytree_node=False, default=12)
    period: float = flax.struct.field(pytree_node=False, default=0.1)
    speed_limit: float = flax.struct.field(pytree_node=False, default=0.04)
    replan_steps: int = flax.struct.field(pytree_node=False, default=2)
    weights: cost_lib.CostWeights = flax.struct.field(pytree_node=False, default=cost_lib.CostWeights())
    gradient: gradient.GradientConfig = flax.struct.field(pytree_node=False, default=gradient.GradientConfig())
    sampling: sampling.SamplingConfig = flax.struct.field(pytree_node=False, default=sampling.SamplingConfig())
    candidates: int = flax.struct.field(pytree_node=False, default=32)
    directions: int = flax.struct.field(pytree_node=False, default=5)
    push_fractions: tuple[float, ...] = flax.struct.field(pytree_node=False, default=(0.1, 0.25, 0.5, 1.0))
    max_angle: float = flax.struct.field(pytree_node=False, default=0.6)
    standoff: float = flax.struct.field(pytree_node=False, default=0.003)
    clearance: float = flax.struct.field(pytree_node=False, default=0.01)
    arc_points: int = flax.struct.field(pytree_node=False, default=16)
    switch_ratio: float = flax.struct.field(pytree_node=False, default=0.7)

    def __post_init__(self):
        if self.planner not in PLANNERS:
            raise ValueError(f"planner: expected one of {', '.join(PLANNERS)}, got {self.planner!r}")
        for name in ("horizon", "replan_steps", "candidates", "directions", "arc_points"):
            if not (isinstance(getattr(self, name), int) and getattr(self, name) >= 1):
                raise ValueError(f"{name}: expected a positive integer, got {getattr(self, name)!r}")
        if self.replan_steps > self.horizon:
            raise ValueError(f"replan_steps: expected at most horizon = {self.horizon}, got {self.replan_steps}")
        if not (self.push_fractions and all(0 < f <= 1 for f in self.push_fractions)):
            raise ValueError(f"push_fractions: expected fractions in (0, 1], got {self.push_fractions!r}")
        for name in ("period", "speed_limit", "standoff", "clearance", "switch_ratio"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name}: expected a value > 0, got {getattr(self, name)!r}")

    @property
    def push_lengths(self) -> tuple[int, ...]:
        """The scored pushes' numbers of moving steps."""
        return tuple(sorted({min(self.horizon, max(1, round(f * self.horizon))) for f in self.push_fractions}))

    @property
    def limit(self) -> float:
        """The largest pusher increment per step, m."""
        return self.speed_limit * self.period

    @property
    def planner_config(self):
        """The chosen planner's settings (its :attr:`Planner.settings` field)."""
        return getattr(self, PLANNERS[self.planner].settings)


@flax.struct.dataclass
class ControllerState:
    """What the controller carries from one plan to the next.

    Attributes:
      raw: [H, 2] the last plan (:mod:`pushjax.control.path`), advanced by the steps executed since.
      key: PRNG key of the sampling planner.
    """

    raw: jax.Array
    key: jax.Array


def init(config: ControllerConfig, key, dtype=jnp.float32) -> ControllerState:
    """The state before the first plan: a plan of standing still."""
    return ControllerState(raw=jnp.zeros((config.horizon, 2), dtype), key=key)


@functools.partial(jax.jit, static_argnames=("config",))
def replan(config: ControllerConfig, model: PlanningModel, state: ControllerState, pose, pusher, goal):
    """Plans from the observed `pose` [3] (x m, y m, yaw rad) and the pusher at `pusher` [2] (world, m) towards
    `goal` [3].

    Returns:
      (the :class:`ControllerState` to pass to the next call after executing ``config.replan_steps`` steps, the
      :class:`~pushjax.control.controller.Command`).
    """
    pose, pusher, goal = (jnp.asarray(value, state.raw.dtype) for value in (pose, pusher, goal))
    limit = jnp.asarray(config.limit, state.raw.dtype)
    key, plan_key = jax.random.split(state.key)
    idle_cost, _ = cost_lib.plan_cost(model, pose, goal, pusher, jnp.zeros_like(state.raw), limit, config.weights)
    raw, plan_cost = PLANNERS[config.planner].plan(model, pose, goal, pusher, state.raw, limit, config.weights,
                                                   config.planner_config, plan_key)
    costs, approach, normals, plans = contact.score_candidates(
        model, pose, goal, config.horizon, limit, config.weights, config.candidates, config.directions,
        config.max_angle, config.standoff, config.push_lengths)
    best = jnp.argmin(costs)
    candidate, direction = best // costs.shape[1], best % costs.shape[1]
    candidate_cost = costs[candidate, direction]
    stuck = plan_cost >= idle_cost * (1.0 - 1e-3)
    reposition = (candidate_cost < config.switch_ratio * plan_cost) | (stuck & (candidate_cost < idle_cost))
    waypoints = contact.detour(model.shape, pose, pusher, approach[candidate], normals[candidate], model.radius,
                               config.clearance, config.arc_points)
    raw = jnp.where(reposition, plans[candidate, direction], raw)
    start = jnp.where(reposition, approach[candidate], pusher)
    path = path_lib.pusher_path(start, raw, limit)
    command = Command(reposition=reposition, increments=jnp.diff(path, axis=0), waypoints=waypoints,
                      predicted=predict(model, pose, path).poses,
                      cost=jnp.where(reposition, candidate_cost, plan_cost), idle_cost=idle_cost,
                      candidate_cost=candidate_cost)
    advanced = jnp.where(reposition, raw, path_lib.shifted(raw, config.replan_steps))
    return ControllerState(raw=advanced, key=key), command
