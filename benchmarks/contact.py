"""Throughput of the contact annotation ``pushjax.geometry.annotate`` on CPU (NumPy, float64).

Annotates random pushes against each of the 11 MIT Push objects (butter included) and prints a
markdown table per object plus the total. Random pushes: the object at a random pose, the pusher
starting 0-15 cm from the object's frame in a random direction, pushing roughly towards it (+-45
degrees) over 0-10 cm; about two thirds of them touch the object.

    python benchmarks/contact.py [--per_object=10000] [--repeats=3] [--seed=0]

Times are the median over ``--repeats`` calls per object (no warm-up is needed: nothing compiles).
"""

import os
import platform
import time

import numpy as np
from absl import app, flags

from pushjax.geometry import OBJECT_NAMES, annotate, get_object

_PER_OBJECT = flags.DEFINE_integer("per_object", 10_000, "Pushes annotated per object and call.")
_REPEATS = flags.DEFINE_integer("repeats", 3, "Timed calls per object.")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the random pushes.")


def random_pushes(count: int, seed: int):
    """[count, 3] object poses, [count, 2] pusher starts and [count, 2] actions, m and rad."""
    rng = np.random.default_rng(seed)
    pose = np.concatenate([rng.uniform(-0.2, 0.2, (count, 2)), rng.uniform(-np.pi, np.pi, (count, 1))], axis=-1)
    bearing = rng.uniform(-np.pi, np.pi, count)
    start = pose[:, :2] + rng.uniform(0.0, 0.15, (count, 1)) * np.stack([np.cos(bearing), np.sin(bearing)], axis=-1)
    heading = bearing + np.pi + rng.uniform(-np.pi / 4, np.pi / 4, count)
    action = rng.uniform(0.0, 0.1, (count, 1)) * np.stack([np.cos(heading), np.sin(heading)], axis=-1)
    return pose, start, action


def main(argv):
    del argv
    count = _PER_OBJECT.value
    rows = []
    for index, name in enumerate(OBJECT_NAMES):
        obj = get_object(name)
        pushes = random_pushes(count, _SEED.value + index)
        annotate(obj, *(p[:1] for p in pushes))  # builds the object's cached geometry
        times = []
        for _ in range(_REPEATS.value):
            start = time.perf_counter()
            annotation = annotate(obj, *pushes)
            times.append(time.perf_counter() - start)
        rows.append((name, float(np.median(times)), float(np.mean(annotation.touches))))

    print(
        f"{count:,} pushes per object; numpy {np.__version__}, {os.cpu_count()} CPUs "
        f"({platform.processor() or platform.machine()}), load average {os.getloadavg()[0]:.2f}\n"
    )
    print("| object | pushes | touching | s | pushes/s |")
    print("|---|---:|---:|---:|---:|")
    for name, seconds, touching in rows:
        print(f"| {name} | {count:,} | {touching:.0%} | {seconds:.3f} | {count / seconds / 1e3:.0f} k |")
    total = sum(seconds for _, seconds, _ in rows)
    total_count = count * len(rows)
    print(f"| **total** | {total_count:,} | | {total:.3f} | {total_count / total / 1e3:.0f} k |")


if __name__ == "__main__":
    app.run(main)
