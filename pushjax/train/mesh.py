"""The sweep's model axis over a device mesh: K models on D devices, K/D per device in one jitted step.

`pushjax.train.sweep_trainer` stacks the K models of a sweep along a leading model axis. On more than
one device it pads that axis to a multiple of D (`pad`, repeating the last model), places the stacked
state and each step's stacked batch with their model axis split over a 1-D mesh (`model_mesh`,
`shard`: a `jax.sharding.NamedSharding` with the axis `MODEL_AXIS`), and maps its vmapped or unrolled
step over the devices' shards (`map_models`: every device steps its K/D models, no communication).
What it logs, checkpoints and returns is unpadded and on one device again (`unshard`), as in a
single-device run, so checkpoints restore on any number of devices.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec

MODEL_AXIS = "models"
"""The mesh axis the models are split over."""


def model_mesh(devices: Sequence[jax.Device] | None = None) -> Mesh:
    """A 1-D mesh with the axis `MODEL_AXIS` over `devices` (default: all visible, ``jax.devices()``)."""
    return Mesh(np.asarray(jax.devices() if devices is None else devices), (MODEL_AXIS,))


def padded_count(count: int, mesh: Mesh) -> int:
    """`count` models rounded up to a multiple of the mesh's D devices (so each holds as many)."""
    return -(-count // mesh.size) * mesh.size


def pad(tree: Any, count: int) -> Any:
    """Leaves [K, ...] -> [count, ...] (count >= K): the last model repeated count - K times.

    NumPy leaves stay NumPy arrays (padded on the host), JAX arrays stay JAX arrays.
    """
    def pad_leaf(leaf):
        extra = count - leaf.shape[0]
        if extra == 0:
            return leaf
        xp = np if isinstance(leaf, np.ndarray) else jnp
        return xp.concatenate([leaf, xp.repeat(leaf[-1:], extra, axis=0)])

    return jax.tree.map(pad_leaf, tree)


def shard(tree: Any, mesh: Mesh) -> Any:
    """Leaves [K, ...] (K a multiple of the D devices) placed with the model axis split over `mesh`.

    Each device holds a [K/D, ...] shard of every leaf: ``NamedSharding(mesh, PartitionSpec(MODEL_AXIS))``.
    """
    return jax.device_put(tree, NamedSharding(mesh, PartitionSpec(MODEL_AXIS)))


def unshard(tree: Any, count: int, mesh: Mesh) -> Any:
    """The first `count` models of a sharded pytree on the mesh's first device: leaves [K, ...] -> [count, ...].

    Inverse of `shard` after `pad`; the result is laid out as a single-device sweep's.
    """
    device = mesh.devices.flat[0]
    return jax.tree.map(lambda leaf: jax.device_put(leaf, device)[:count], tree)


def map_models(step: Callable, mesh: Mesh) -> Callable:
    """`step` over [K/D, ...] shards as a function of [K, ...] arrays sharded over `mesh` (`shard`).

    Every positional argument's and output's leaves are split along their leading model axis; each
    device runs `step` on its own K/D models (``jax.shard_map``). Jit the result.
    """
    return jax.shard_map(step, mesh=mesh, in_specs=PartitionSpec(MODEL_AXIS), out_specs=PartitionSpec(MODEL_AXIS))
