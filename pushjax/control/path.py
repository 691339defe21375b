"""The pusher path a planner optimises, with the pusher's speed limit built in.

A plan is ``raw`` [H, 2], unconstrained; step ``k`` moves the pusher by ``limit * raw_k / sqrt(1 + |raw_k|^2)``
(world, m), so no step exceeds ``limit = speed_limit * period`` whatever the planner does, and the map is smooth
(``jax.grad`` and sampling see the same parametrisation). :func:`raw_for` inverts it.
"""

from __future__ import annotations

import jax.numpy as jnp

__all__ = ["increments", "pusher_path", "raw_for", "shifted"]


def increments(raw, limit):
    """[H, 2] pusher increments (m) of the plan `raw` [H, 2]; every norm is below `limit` [] (m per step)."""
    return limit * raw / jnp.sqrt(1.0 + jnp.sum(raw * raw, axis=-1, keepdims=True))


def pusher_path(start, raw, limit):
    """[H + 1, 2] pusher positions (world, m) of the plan `raw` from `start` [2]."""
    steps = increments(raw, limit)
    return jnp.concatenate([start[None], start + jnp.cumsum(steps, axis=0)])


def raw_for(step, limit):
    """[..., 2] raw plan entries whose increments are `step` [..., 2] (m; norms clipped to 0.95 `limit`)."""
    norm = jnp.sqrt(jnp.sum(step * step, axis=-1, keepdims=True))
    fraction = jnp.minimum(norm / limit, 0.95)
    scale = jnp.where(norm > 0, fraction / jnp.sqrt(1.0 - fraction ** 2) / jnp.where(norm > 0, norm, 1.0), 0.0)
    return step * scale


def shifted(raw, steps: int):
    """The plan `raw` [H, 2] advanced by `steps` executed steps (receding horizon): the rest moved to the front,
    the last step repeated at the end."""
    return jnp.concatenate([raw[steps:], jnp.repeat(raw[-1:], steps, axis=0)])
