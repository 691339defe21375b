"""Several processes (one per host) training one sweep: joining them with ``jax.distributed``.

Every process runs the same program (JAX's multi-controller model): after `initialize`, ``jax.devices()``
lists the devices of all processes and ``jax.local_devices()`` this process's. `pushjax.train.sweep` then
splits its model axis over all of them (`pushjax.train.mesh`): each process feeds the batches of the models
on its own devices, the metrics and the trained models are gathered on every process, process 0 writes
``metrics.csv`` and orbax writes each checkpoint once (`pushjax.train.checkpoint`).

Launch (the same command on every host, ``--process_id`` from 0 to N - 1, the address that of process 0)::

  python -m experiments.data_efficiency --mode=unroll --workdir=SHARED \\
      --coordinator_address=HOST0:1234 --num_processes=N --process_id=I
"""

from __future__ import annotations

import jax
from jax.experimental import multihost_utils


def initialize(coordinator_address: str | None = None, num_processes: int = 1, process_id: int = 0) -> None:
    """Joins this process to the `num_processes` processes of one run; call it before any JAX computation.

    With one process it does nothing. With several it calls ``jax.distributed.initialize`` (which waits
    for all processes to join) after selecting gloo as the CPU backend's cross-process collectives
    (``jax_cpu_collectives_implementation``: JAX 0.10's default, set so that a sweep's steps on CPU can
    span processes whatever the default).

    Args:
      coordinator_address: ``host:port`` of process 0, where it serves and the others connect; only with
        several processes.
      num_processes: how many processes run together (>= 1).
      process_id: this process's index in [0, num_processes).

    Raises:
      ValueError: a bad argument, named first in the message (e.g. ``num_processes: ...``).
    """
    if num_processes < 1:
        raise ValueError(f"num_processes: expected at least 1, got {num_processes}")
    if not 0 <= process_id < num_processes:
        raise ValueError(f"process_id: expected an index below num_processes={num_processes}, got {process_id}")
    if num_processes == 1:
        if coordinator_address is not None:
            raise ValueError(f"coordinator_address: only used with num_processes > 1, got {coordinator_address!r}")
        return
    host, _, port = (coordinator_address or "").rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ValueError(f"coordinator_address: expected host:port of process 0, got {coordinator_address!r}")
    jax.config.update("jax_cpu_collectives_implementation", "gloo")
    jax.distributed.initialize(coordinator_address=coordinator_address, num_processes=num_processes,
                               process_id=process_id)


def is_writer() -> bool:
    """Whether this process writes the files the processes share (datasets, logs, results): process 0."""
    return jax.process_index() == 0


def wait_for_all(name: str) -> None:
    """Blocks until every process has reached the point called `name`; with one process it returns at once."""
    if jax.process_count() > 1:
        multihost_utils.sync_global_devices(name)
