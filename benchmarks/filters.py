"""Throughput of the filters (``pushjax.filter``) on CPU, vmapped over a batch of pushes.

``--pushes`` synthetic pushes of rect1 (5 cm in ``--steps`` steps into random sides at random angles, simulated by
the analytical rollout with random mu, measured with the realistic testbed's motion-capture noise and 1 % dropped
samples), filtered at once by the EKF, the UKF and the particle filter (``--particles``). Prints a markdown table of
the median (best) time over ``--repeats`` calls after the compiling first call.

    python benchmarks/filters.py [--pushes=256] [--steps=50] [--particles=256] [--repeats=3]
"""

import platform

import jax
import numpy as np
from absl import app, flags

from pushjax.filter import ekf, metrics, models, particle, ukf
from pushjax.geometry.objects import get_object
from timing import time_calls

_PUSHES = flags.DEFINE_integer("pushes", 256, "Pushes per batch.")
_STEPS = flags.DEFINE_integer("steps", 50, "Steps per push.")
_PARTICLES = flags.DEFINE_integer("particles", 256, "Particles of the particle filter.")
_REPEATS = flags.DEFINE_integer("repeats", 3, "Timed calls per filter.")


def main(argv):
    del argv
    rng = np.random.default_rng(0)
    obj = get_object("rect1")
    count, steps = _PUSHES.value, _STEPS.value
    paths = np.empty((count, steps + 1, 2))
    for k in range(count):
        point, normal = obj.side_point(int(rng.integers(4)), float(rng.uniform(0.1, 0.9)))
        angle = rng.uniform(-0.7, 0.7)
        direction = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]) @ normal
        start = point - direction * (0.00476 / (direction @ normal) + 5e-4)
        paths[k] = start + np.linspace(0.0, 1.0, steps + 1)[:, None] * 0.05 * direction
    system = models.make_system(obj, mu=0.3)
    truth_state = np.zeros((count, 5))
    truth_state[:, 3] = rng.normal(0.0, 0.3, count)
    truth = np.asarray(metrics.simulate(system, truth_state, paths))
    measurements = metrics.measure(truth, (2e-4, 2e-4, 3e-3), 0.01, seed=0)
    mean = np.concatenate([measurements[:, 0], np.zeros((count, 2))], axis=-1)
    cov = np.broadcast_to(np.diag([2e-4, 2e-4, 3e-3, 0.5, 0.3]) ** 2, (count, 5, 5))
    keys = jax.random.split(jax.random.key(0), count)
    print(f"{platform.machine()}, {jax.devices()[0].platform}, jax {jax.__version__}; {count} pushes x {steps} steps "
          f"of rect1, float32, median (best) of {_REPEATS.value}\n")
    print("| filter | first call (s) | time (s) | pushes/s | filter steps/s |")
    print("|---|---:|---:|---:|---:|")
    for name, function in [
            ("EKF", lambda: ekf.filter_pushes(system, mean, cov, paths, measurements)),
            ("UKF", lambda: ukf.filter_pushes(system, mean, cov, paths, measurements)),
            (f"particle ({_PARTICLES.value})",
             lambda: particle.filter_pushes(system, keys, mean, cov, paths, measurements, count=_PARTICLES.value))]:
        first, median, best = time_calls(function, _REPEATS.value)
        print(f"| {name} | {first:.1f} | {median:.3f} ({best:.3f}) | {count / median:,.0f} | "
              f"{count * steps / median:,.0f} |")


if __name__ == "__main__":
    app.run(main)
