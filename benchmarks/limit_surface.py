"""Throughput of the exact limit-surface pushing model on CPU, against Lynch's ellipsoid on the same pushes.

Measures pushes per second of ``pushjax.physics.limit_surface.predict`` (forward) and of ``jax.grad`` of the
summed twist with respect to all nine inputs (contact, normal, action, mu, support points, support weights,
patch radius, s, drift force), for ``K`` supports shared by the batch (a uniform disc of radius 5 cm with random
weights, patch radius half the grid spacing), next to ``lynch.predict`` and its gradient (w.r.t. its six
inputs) on the same pushes. Prints a markdown table.

    python benchmarks/limit_surface.py [--batch=100000] [--supports=24,64] [--repeats=5] [--dtype=float32]

Times are the median (and best) over ``--repeats`` calls after a warm-up call, with ``block_until_ready``;
the machine may be shared, so compare the median with the best.
"""

import os
import platform

import jax
import jax.numpy as jnp
import numpy as np
from absl import app, flags

from pushjax.physics import limit_surface, lynch
from timing import seconds_per_call

_BATCH = flags.DEFINE_integer("batch", 100_000, "Pushes per call.")
_SUPPORTS = flags.DEFINE_list("supports", ["24", "64"], "Numbers K of support points.")
_REPEATS = flags.DEFINE_integer("repeats", 5, "Timed calls per measurement.")
_DTYPE = flags.DEFINE_enum("dtype", "float32", ["float32", "float64"], "Floating point type.")
_DRIFT = flags.DEFINE_float("drift", 0.0, "Magnitude of a random drift force (0: none).")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the random pushes.")

RADIUS = 0.05


def disc_supports(count: int, rng) -> tuple[np.ndarray, np.ndarray, float]:
    """``count`` points spread uniformly over a disc (sunflower), random weights, patch radius."""
    index = np.arange(count) + 0.5
    r = RADIUS * np.sqrt(index / count)
    angle = index * np.pi * (3 - np.sqrt(5))
    points = np.stack([r * np.cos(angle), r * np.sin(angle)], -1)
    return points, rng.uniform(0.5, 1.0, count), 0.5 * RADIUS * np.sqrt(np.pi / count)


def random_pushes(batch: int, rng):
    """Pushes at the disc's rim, into it within +-70 deg of the normal and beyond (some pull)."""
    contact_angle = rng.uniform(-np.pi, np.pi, batch)
    contact = RADIUS * np.stack([np.cos(contact_angle), np.sin(contact_angle)], -1)
    normal_angle = contact_angle + np.pi + rng.uniform(-0.3, 0.3, batch)
    normal = np.stack([np.cos(normal_angle), np.sin(normal_angle)], -1)
    action_angle = normal_angle + rng.uniform(-0.6, 0.6, batch) * np.pi
    action = np.stack([np.cos(action_angle), np.sin(action_angle)], -1) * rng.uniform(0.001, 0.01, (batch, 1))
    mu = rng.uniform(0.1, 0.6, batch)
    s = rng.uniform(0, 1, batch)
    return contact, normal, action, mu, s


def main(argv):
    del argv
    dtype = np.dtype(_DTYPE.value)
    jax.config.update("jax_enable_x64", dtype == np.float64)
    batch = _BATCH.value
    rng = np.random.default_rng(_SEED.value)
    contact, normal, action, mu, s = random_pushes(batch, rng)
    drift = _DRIFT.value * rng.uniform(-1, 1, (batch, 2)) / np.sqrt(2)

    def device(*arrays):
        return [jnp.asarray(np.asarray(x, dtype)) for x in arrays]

    rows = []
    mode_note = []
    for count in map(int, _SUPPORTS.value):
        points, weights, rho = disc_supports(count, rng)
        args = device(contact, normal, action, mu, points, weights, rho, s, drift)
        gradient = jax.jit(jax.grad(lambda *a: jnp.sum(limit_surface.predict(*a)), argnums=tuple(range(9))))
        rows.append((f"`limit_surface.predict`, K = {count}", "forward",
                     seconds_per_call(limit_surface.predict, args, _REPEATS.value)))
        rows.append((f"`jax.grad` w.r.t. all 9 inputs, K = {count}", "forward + backward",
                     seconds_per_call(gradient, args, _REPEATS.value)))
        solution = limit_surface.solve(*args)
        mode_note.append(f"K = {count}: {np.mean(solution.sticking):.0%} sticking, {np.mean(solution.slipping):.0%} "
                         f"slipping")
        if len(rows) == 2:
            # Lynch's ellipsoid with the same intercept m_max = sum p_k sqrt(|r_k|^2 + rho^2).
            p = weights / weights.sum()
            l = np.full(batch, p @ np.sqrt(np.sum(points**2, -1) + rho**2))
            lynch_args = device(contact, normal, action, l, mu, s)
            lynch_gradient = jax.jit(jax.grad(lambda *a: jnp.sum(lynch.predict(*a)), argnums=tuple(range(6))))
            lynch_rows = [
                ("`lynch.predict` (ellipsoid)", "forward", seconds_per_call(lynch.predict, lynch_args, _REPEATS.value)),
                ("`jax.grad` of `lynch.predict` w.r.t. all 6 inputs", "forward + backward",
                 seconds_per_call(lynch_gradient, lynch_args, _REPEATS.value)),
            ]
    rows = lynch_rows + rows
    print(f"batch {batch:,} {dtype.name} pushes, drift {_DRIFT.value}; {'; '.join(mode_note)}; "
          f"iterations {limit_surface.ITERATIONS}; jax {jax.__version__} on {jax.devices()[0]}, "
          f"{os.cpu_count()} CPUs ({platform.processor() or platform.machine()}), "
          f"load average {os.getloadavg()[0]:.2f}\n")
    print("| implementation | pass | pushes/s (median) | ms / batch (median, best) | time / Lynch forward |")
    print("|---|---|---:|---:|---:|")
    reference = rows[0][2][0]
    for name, kind, (seconds, best) in rows:
        print(f"| {name} | {kind} | {batch / seconds / 1e6:.2f} M | {seconds * 1e3:.1f}, {best * 1e3:.1f} "
              f"| {seconds / reference:.0f}x |")


if __name__ == "__main__":
    app.run(main)
