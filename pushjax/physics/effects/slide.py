"""The effects after the pusher stops: the object slides on, decelerated by its support friction (``inertia``), which
may depend on the sliding speed (``friction_speed``); their physics: :mod:`pushjax.physics.effects`."""

from __future__ import annotations

import jax.numpy as jnp

from pushjax.friction import MIN_FRICTION_FACTOR, SPEED_FLOOR, SPEED_REFERENCE
from pushjax.physics.effects.types import Effect, zeros
from pushjax.physics.effects.vectors import safe_norm

__all__ = ["FRICTION_SPEED", "INERTIA"]


def _slide_after_contact(twist, state, inputs, inverse_deceleration_at):
    """The twist plus the slide after the pusher stops, decelerated at ``1 / inverse_deceleration_at(speed)``."""
    motion, moving = safe_norm(jnp.stack([safe_norm(twist[..., :2])[0], state.l * twist[..., 2]], -1))
    push, pushed = safe_norm(state.action)
    speed = inputs.push_speed * motion / jnp.where(pushed, push, 1.0)
    inverse_deceleration = inverse_deceleration_at(speed)
    time = inputs.time_after_stop
    # v^2 / (2 a) when the object stops within the window (v / a < t), else v t - a t^2 / 2; written with
    # 1 / a, which is 0 without effect.
    stops = speed * inverse_deceleration < time
    safe_inverse = jnp.where(inverse_deceleration > 0, inverse_deceleration, 1.0)
    slide = jnp.where(stops, 0.5 * speed * speed * inverse_deceleration, speed * time - time * time / (2 * safe_inverse))
    factor = jnp.where(moving & pushed, slide / jnp.where(moving, motion, 1.0), 0.0)
    return twist * (1.0 + factor[..., None])


def _inertia_correct(params, twist, state, inputs):
    return _slide_after_contact(twist, state, inputs, lambda speed: params["inverse_deceleration"])


def _speed_factor(gain, speed):
    """Support friction at ``speed`` [...] (m/s) over that at :data:`SPEED_REFERENCE`."""
    return jnp.maximum(1.0 + gain * jnp.log10(jnp.maximum(speed, SPEED_FLOOR) / SPEED_REFERENCE),
                       MIN_FRICTION_FACTOR)


def _friction_speed_correct(params, twist, state, inputs):
    return _slide_after_contact(twist, state, inputs,
                                lambda speed: params["inverse_deceleration"] / _speed_factor(params["gain"], speed))


def _friction_speed_project(params):
    return {"inverse_deceleration": jnp.maximum(params["inverse_deceleration"], 0.0), "gain": params["gain"]}


def _friction_speed_physical(params):
    return {**_inertia_physical(params), "gain_per_decade": params["gain"]}


def _inertia_project(params):
    return {"inverse_deceleration": jnp.maximum(params["inverse_deceleration"], 0.0)}


def _inertia_physical(params):
    inverse = params["inverse_deceleration"]
    return {"inverse_deceleration_s2_per_m": inverse,
            "decay_length_mm_at_100_mm_s": 1e3 * 0.5 * 0.1 ** 2 * inverse}


INERTIA = Effect(name="inertia", init=zeros(inverse_deceleration=()), typical={"inverse_deceleration": 0.3},
                 correct=_inertia_correct, project=_inertia_project, physical=_inertia_physical)
FRICTION_SPEED = Effect(name="friction_speed", init=zeros(inverse_deceleration=(), gain=()),
                        typical={"inverse_deceleration": 0.3, "gain": 0.3}, correct=_friction_speed_correct,
                        project=_friction_speed_project, physical=_friction_speed_physical)
