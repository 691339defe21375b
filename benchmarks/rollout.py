"""Throughput of the JAX rollout (``pushjax.physics.rollout.rollout``) on CPU, against a vectorised NumPy loop.

A batch of ``--pushes`` straight pushes of 5 cm in ``--steps`` steps per object (random side, point along it,
angle within ±40° of the side's normal, mu in [0.1, 1]), ``jax.vmap`` over the batch under ``jax.jit``:
rollouts per second of the forward pass, and of ``jax.grad`` of the summed final poses with respect to the
pusher paths, l and mu. The NumPy baseline runs the same steps vectorised over the batch (the NumPy contact
annotation ``pushjax.geometry.contact.annotate`` and the NumPy reference model of the tests), float64, on
``--numpy_pushes`` pushes. Prints a markdown table.

    python benchmarks/rollout.py [--pushes=1000] [--steps=100] [--objects=rect1,ellip2,butter] [--repeats=5]
        [--searches=full,local]

``--searches`` compares the contact searches in one sitting on the same pushes: ``full`` is the former rollout
(every outline feature every step, the outline unpadded: a program per vertex count), ``local`` the current one
(the window around the tracked feature, the outline padded to 256 vertices: one program for every object). The
jitted functions take the outline as an argument, so a search's first call on a later object shows whether it
compiled again.

Times are the median (and best) over ``--repeats`` calls after a warm-up (compiling) call, with
``block_until_ready``; the compile time of the first call is given separately.
"""

import importlib.util
import pathlib
import platform
import time

import jax
import jax.numpy as jnp
import numpy as np
from absl import app, flags

from pushjax import planar
from pushjax.geometry import contact as contact_lib
from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, get_object, limit_surface_ratio
from pushjax.physics import rollout
from timing import time_calls

_PUSHES = flags.DEFINE_integer("pushes", 1000, "Pushes per batch.")
_STEPS = flags.DEFINE_integer("steps", 100, "Steps per push.")
_OBJECTS = flags.DEFINE_list("objects", ["rect1", "ellip2", "butter"], "Objects to measure.")
_REPEATS = flags.DEFINE_integer("repeats", 5, "Timed calls per measurement.")
_NUMPY_PUSHES = flags.DEFINE_integer("numpy_pushes", 1000, "Pushes of the NumPy baseline's batch.")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the random pushes.")
_SEARCHES = flags.DEFINE_list("searches", ["full", "local"],
                              "Contact searches: full (unpadded outline, every feature) and/or local (padded, tracked).")

_REFERENCE_PATH = pathlib.Path(__file__).resolve().parents[1] / "tests" / "physics" / "numpy_lynch.py"


def _load_numpy_reference():
    spec = importlib.util.spec_from_file_location("numpy_lynch", _REFERENCE_PATH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def random_pushes(obj, count, steps, seed):
    """([count, steps + 1, 2] pusher paths, [count] mu), pushes of 5 cm into random sides of `obj` at yaw 0."""
    rng = np.random.default_rng(seed)
    paths = np.empty((count, steps + 1, 2))
    for k in range(count):
        point, normal = obj.side_point(int(rng.integers(len(obj.sides))), float(rng.uniform(0.1, 0.9)))
        direction = planar.rotation_matrix(rng.uniform(-0.7, 0.7)) @ normal
        start = point - direction * (PUSHER_RADIUS / (direction @ normal) + 1e-3)
        paths[k] = start + np.linspace(0.0, 1.0, steps + 1)[:, None] * 0.05 * direction
    return paths, rng.uniform(0.1, 1.0, count)


def numpy_rollouts(obj, paths, l, mu, reference):
    """[N, 3] final poses of the NumPy loop, vectorised over the pushes."""
    pose = np.zeros((len(paths), 3))
    for k in range(paths.shape[1] - 1):
        state = contact_lib.annotate(obj, pose, paths[:, k], paths[:, k + 1] - paths[:, k])
        motion = reference.predict(state.contact_rel_com, state.normal, state.action_from_contact, l, mu)
        com_offset = planar.rotate(np.broadcast_to(obj.centroid, (len(pose), 2)), pose[:, 2])
        com = pose[:, :2] + com_offset + motion[:, :2]
        pose = np.concatenate([com - planar.rotate(com_offset, motion[:, 2]), (pose[:, 2] + motion[:, 2])[:, None]],
                              axis=-1)
    return pose


def main(argv):
    del argv
    reference = _load_numpy_reference()
    count, steps = _PUSHES.value, _STEPS.value
    print(f"{platform.processor() or platform.machine()}, {jax.devices()[0].platform}, jax {jax.__version__}; "
          f"{count} pushes x {steps} steps, float32, median (best) of {_REPEATS.value}\n")
    print("| object | search | pass | first call (s) | time (s) | rollouts/s | steps/s |")
    print("|---|---|---|---:|---:|---:|---:|")
    functions = {search: _functions(search) for search in _SEARCHES.value}
    for name in _OBJECTS.value:
        _measure(name, count, steps, reference, functions)


def _functions(search):
    """(forward, gradient) of a batch of rollouts with `search`, jitted once, the outline an argument."""

    def final(shape, path, pose, l, mu):
        return rollout.rollout(shape, pose, path, l, mu, search=search).poses[-1]

    forward = jax.jit(jax.vmap(final, in_axes=(None, 0, 0, 0, 0)))
    gradient = jax.jit(jax.vmap(jax.grad(lambda *args: jnp.sum(final(*args)), argnums=(1, 3, 4)),
                                in_axes=(None, 0, 0, 0, 0)))
    return forward, gradient


def _measure(name, count, steps, reference, functions):
    """Prints the rows of one object."""
    obj = get_object(name)
    paths, mus = random_pushes(obj, count, steps, _SEED.value)
    l = jnp.full(count, limit_surface_ratio(obj), jnp.float32)
    paths_j, mus_j = jnp.asarray(paths, jnp.float32), jnp.asarray(mus, jnp.float32)
    poses0 = jnp.zeros((count, 3))
    for search, (forward, gradient) in functions.items():
        shape = outline_jax.outline(obj, pad_to=None if search == "full" else outline_jax.PADDED_VERTICES)
        label = f"{search} ({int(shape.count)} of {shape.start.shape[0]} vertices)"
        for pass_, function in [("forward", forward), ("grad w.r.t. path, l, mu", gradient)]:
            first, median, best = time_calls(lambda function=function: function(shape, paths_j, poses0, l, mus_j),
                                             _REPEATS.value)
            print(f"| {name} | {label} | {pass_} | {first:.1f} | {median:.3f} ({best:.3f}) | {count / median:,.0f} "
                  f"({count / best:,.0f}) | {count * steps / median:,.0f} |", flush=True)
    numpy_count = min(_NUMPY_PUSHES.value, count)
    if numpy_count == 0:
        return
    start = time.perf_counter()
    numpy_rollouts(obj, paths[:numpy_count], limit_surface_ratio(obj), mus[:numpy_count], reference)
    elapsed = time.perf_counter() - start
    print(f"| {name} | NumPy loop, float64 ({numpy_count} pushes) | | | {elapsed:.3f} | {numpy_count / elapsed:,.0f} "
          f"| {numpy_count * steps / elapsed:,.0f} |", flush=True)


if __name__ == "__main__":
    app.run(main)
