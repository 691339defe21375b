"""Timing one sweep of the sweep trainer, shared by the sweep benchmarks (``sweep.py``, ``sweep_mesh.py``)."""

import time

import jax

from pushjax import train

STEADY_FROM = 10
"""The step after which a sweep counts as compiled and warm."""


def timed_sweep(config, examples, specs, mode):
    """(total seconds, seconds per step of all `specs`' models after step `STEADY_FROM`) of one `train.sweep`."""
    marks = {}

    def mark(step, metrics):
        if step in (STEADY_FROM, config.num_steps):
            jax.block_until_ready(metrics)
            marks[step] = time.perf_counter()

    start = time.perf_counter()
    result = train.sweep(config, examples, specs, mode=mode, progress=False, step_callback=mark)
    jax.block_until_ready(result.state)
    total = time.perf_counter() - start
    return total, (marks[config.num_steps] - marks[STEADY_FROM]) / (config.num_steps - STEADY_FROM)
