"""Planar vector helpers of the effects, finite gradients everywhere."""

from __future__ import annotations

import jax
import jax.numpy as jnp

__all__ = ["dot", "rotate", "safe_norm", "safe_sqrt"]


def rotate(vector: jax.Array, yaw: jax.Array) -> jax.Array:
    """[..., 2] vectors turned counter-clockwise by ``yaw`` [...] rad."""
    cos, sin = jnp.cos(yaw), jnp.sin(yaw)
    return jnp.stack([cos * vector[..., 0] - sin * vector[..., 1],
                      sin * vector[..., 0] + cos * vector[..., 1]], axis=-1)


def dot(a: jax.Array, b: jax.Array) -> jax.Array:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def safe_norm(vector: jax.Array) -> tuple[jax.Array, jax.Array]:
    """(|v|, |v| > 0) with a finite gradient at v = 0."""
    squared = dot(vector, vector)
    positive = squared > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, squared, 1.0)), 0.0), positive


def safe_sqrt(value: jax.Array) -> jax.Array:
    positive = value > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, value, 1.0)), 0.0)

