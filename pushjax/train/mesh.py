"""The sweep's model axis over a device mesh: K models on D devices, K/D per device in one jitted step.

`pushjax.train.sweep_trainer` stacks the K models of a sweep along a leading model axis. On more than
one device it pads that axis to a multiple of D (`pad`, repeating the last model), places the stacked
state and each step's stacked batch with their model axis split over a 1-D mesh (`sweep_mesh`,
`shard`: a `jax.sharding.NamedSharding` with the axis `MODEL_AXIS`), and maps its vmapped or unrolled
step over the devices' shards (`map_models`: every device steps its K/D models, no communication).
What it logs, checkpoints and returns is unpadded and on one device again (`unshard`), as in a
single-device run, so checkpoints restore on any number of devices.

Several processes (`pushjax.train.distributed`): the mesh spans the devices of all of them, each process
holds a contiguous block of the model axis (`local_rows`) and feeds only those models' batches (`shard`
of process-local rows), and `unshard` gathers the models from all processes onto each one's first device.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np
from jax.experimental import multihost_utils
from jax.sharding import Mesh, NamedSharding, PartitionSpec

MODEL_AXIS = "models"
"""The mesh axis the models are split over."""


def model_mesh(devices: Sequence[jax.Device] | None = None) -> Mesh:
    """A 1-D mesh with the axis `MODEL_AXIS` over `devices` (default: those of all processes, ``jax.devices()``).

    The devices are ordered by process, so that each process's shards form one block of the model axis.
    """
    devices = jax.devices() if devices is None else devices
    return Mesh(np.asarray(sorted(devices, key=lambda device: (device.process_index, device.id))), (MODEL_AXIS,))


def sweep_mesh(count: int) -> Mesh | None:
    """The mesh `count` models are split over: None on one device.

    One process: its first `count` devices (no device without a model). Several processes: all their devices,
    so that every process takes part in each step.
    """
    devices = jax.devices() if jax.process_count() > 1 else jax.devices()[:count]
    return model_mesh(devices) if len(devices) > 1 else None


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


def _sharding(mesh: Mesh) -> NamedSharding:
    return NamedSharding(mesh, PartitionSpec(MODEL_AXIS))


def local_rows(count: int, mesh: Mesh) -> range:
    """The rows of a [count, ...] array sharded over `mesh` (`shard`) that this process's devices hold.

    All `count` with one process; with several, process p's block (count / D rows per device of p).
    """
    rows = [index[0].indices(count)[:2] for index in _sharding(mesh).addressable_devices_indices_map((count,)).values()]
    return range(min(start for start, _ in rows), max(stop for _, stop in rows))


def shard(tree: Any, count: int, mesh: Mesh) -> Any:
    """Leaves [count, ...] (count a multiple of the D devices) placed with the model axis split over `mesh`.

    Each device holds a [count/D, ...] shard of every leaf: ``NamedSharding(mesh, PartitionSpec(MODEL_AXIS))``.
    A leaf holds either all `count` rows (the same on every process) or only this process's,
    `local_rows(count, mesh)`; each process places the rows of its own devices.
    """
    sharding = _sharding(mesh)
    return jax.tree.map(
        lambda leaf: jax.make_array_from_process_local_data(sharding, leaf, (count, *leaf.shape[1:])), tree)


def unshard(tree: Any, count: int, mesh: Mesh) -> Any:
    """The first `count` models of a sharded pytree on this process's first device: leaves [K, ...] -> [count, ...].

    Inverse of `shard` after `pad`; the result is laid out as a single-device sweep's. With several processes
    the shards are gathered from all of them first (every process must call it, as any step).
    """
    if jax.process_count() > 1:
        tree = multihost_utils.process_allgather(tree, tiled=True)
    device = mesh.local_devices[0]
    return jax.tree.map(lambda leaf: jax.device_put(leaf, device)[:count], tree)


def map_models(step: Callable, mesh: Mesh) -> Callable:
    """`step` over [K/D, ...] shards as a function of [K, ...] arrays sharded over `mesh` (`shard`).

    Every positional argument's and output's leaves are split along their leading model axis; each
    device runs `step` on its own K/D models (``jax.shard_map``). Jit the result.
    """
    return jax.shard_map(step, mesh=mesh, in_specs=PartitionSpec(MODEL_AXIS), out_specs=PartitionSpec(MODEL_AXIS))
