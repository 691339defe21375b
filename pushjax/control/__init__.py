"""Pushing an object to a goal pose by model-predictive control through the differentiable rollout.

``model`` (the object and the pushing model planned with, ``PlanningModel``), ``path`` (the plan's parametrisation
and the speed limit), ``cost`` (goal error and effort), the planners ``gradient`` (``jax.grad`` through the rollout,
optax) and ``sampling`` (the cross-entropy method, vmapped), ``contact`` (candidate contacts around the outline and the
detour to one), ``controller`` (the interface a closed loop asks of a controller: ``Controller``, answering a
``Command``), ``mpc`` (the receding-horizon controller, one ``Controller``), ``goals`` (goals drawn per object and the
success criterion). The algorithms only, no MuJoCo: the controller closed on the testbed and the push-to-goal
experiment are studies (``pushjax.studies.episode``, ``pushjax.studies.push_to_goal``).
"""

from pushjax.control import contact, controller, cost, goals, gradient, model, mpc, path, sampling
from pushjax.control.controller import Command, Controller
from pushjax.control.model import PlanningModel, make_model
from pushjax.control.mpc import ControllerConfig, ControllerState, init, replan

__all__ = ["Command", "Controller", "ControllerConfig", "ControllerState", "PlanningModel", "contact", "controller",
           "cost", "goals", "gradient", "init", "make_model", "model", "mpc", "path", "replan", "sampling"]
