"""Wall time of jitted calls, shared by the benchmark scripts (run as ``python benchmarks/<name>.py``)."""

import time

import jax
import numpy as np


def time_calls(function, repeats: int) -> tuple[float, float, float]:
    """(first, median, best) wall time in s of ``function()``: the first call (compilation included), then the median
    and the best of ``repeats`` further calls, each waited for with ``jax.block_until_ready``."""
    start = time.perf_counter()
    jax.block_until_ready(function())
    first = time.perf_counter() - start
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        jax.block_until_ready(function())
        times.append(time.perf_counter() - start)
    return first, float(np.median(times)), float(np.min(times))


def seconds_per_call(function, args, repeats: int) -> tuple[float, float]:
    """(median, best) wall time of ``function(*args)`` after one warm-up call."""
    return time_calls(lambda: function(*args), repeats)[1:]
