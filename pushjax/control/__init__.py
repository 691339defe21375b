"""Pushing an object to a goal pose by model-predictive control through the differentiable rollout.

``model`` (the object and the pushing model planned with), ``path`` (the plan's parametrisation and the speed
limit), ``cost`` (goal error and effort), the planners ``gradient`` (``jax.grad`` through the rollout, optax) and
``sampling`` (the cross-entropy method, vmapped), ``contact`` (candidate contacts around the outline and the detour
to one), ``mpc`` (the receding-horizon controller). ``closed_loop`` (not imported here: it needs MuJoCo) runs the
controller on the testbed, ``goals`` draws goals and judges success, ``report`` writes the experiment's results.
"""

from pushjax.control import contact, cost, gradient, model, mpc, path, sampling
from pushjax.control.model import PushModel, make_model
from pushjax.control.mpc import ControllerConfig, ControllerState, init, replan

__all__ = ["ControllerConfig", "ControllerState", "PushModel", "contact", "cost", "gradient", "init",
           "make_model", "model", "mpc", "path", "replan", "sampling"]
