"""What a closed-loop episode asks of a controller: :class:`Controller`, whose :meth:`~Controller.replan` answers a
:class:`Command`.

The receding-horizon controller :mod:`pushjax.control.mpc` is one (the module itself: its ``init`` and ``replan``);
the episode runner (``pushjax.studies.episode.run_episode``) takes any other with the same two functions. The
controller's settings (``config``) are its own, with the four the runner also reads: ``period`` (s, a multiple of
the testbed's 4 ms clock), ``speed_limit`` (m/s), ``replan_steps`` (control periods executed between two plans) and
``clearance`` (m, the gap of the pusher's waiting circle around the object,
:func:`pushjax.control.contact.clearance_radius`).
"""

from __future__ import annotations

from typing import Any, Protocol

import flax.struct
import jax

__all__ = ["Command", "Controller"]


@flax.struct.dataclass
class Command:
    """One :meth:`Controller.replan`'s answer: where the pusher goes next, and the costs behind it.

    Attributes:
      reposition: [] bool, go around the object to ``waypoints[-1]`` before pushing on.
      increments: [H, 2] the plan's pusher increments, world, m (from the approach point after a reposition).
      waypoints: [W, 2] the detour, world, m (meaningful when ``reposition``).
      predicted: [H + 1, 3] the object poses the plan predicts.
      cost: [] the plan's cost.
      idle_cost: [] the cost of standing still.
      candidate_cost: [] the best candidate's cost.
    """

    reposition: jax.Array
    increments: jax.Array
    waypoints: jax.Array
    predicted: jax.Array
    cost: jax.Array
    idle_cost: jax.Array
    candidate_cost: jax.Array


class Controller(Protocol):
    """A controller of the closed loop (:mod:`pushjax.control.mpc` is one)."""

    def init(self, config: Any, key: jax.Array) -> Any:
        """The controller's state before the first plan, from its settings `config` and a PRNG `key`."""

    def replan(self, config: Any, model: Any, state: Any, pose: jax.Array, pusher: jax.Array,
               goal: jax.Array) -> tuple[Any, Command]:
        """(the state for the next call, after ``config.replan_steps`` executed steps; the :class:`Command`) planned
        with `model` (a :class:`pushjax.control.model.PlanningModel`) from the observed `pose` [3] (x m, y m, yaw rad)
        and the pusher at `pusher` [2] (world, m) towards `goal` [3]."""
