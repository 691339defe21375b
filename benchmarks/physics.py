"""Throughput of the differentiable Lynch pushing model on CPU, against vectorised NumPy.

Measures pushes per second of ``pushjax.physics.lynch.predict`` (forward) and of its gradient with
respect to all six inputs (``jax.grad`` of the summed twist w.r.t. contact, normal, action, l, mu,
s) on one batch, and the forward pass of two vectorised NumPy implementations on the same batch:
the independent test reference (``tests/physics/numpy_lynch.py``: normalised normal, arctan/cos/sin,
both motion-cone boundaries, arctan2 angle tests) and a NumPy port of the closed form the JAX code
uses (the fastest NumPy formulation we have). Prints a markdown table.

    python benchmarks/physics.py [--batch=1000000] [--repeats=20] [--dtype=float32]

Times are the median (and best) over ``--repeats`` calls after a warm-up call, with
``block_until_ready``; the machine may be shared, so compare the median with the best.
XLA flags are the defaults unless set through the ``XLA_FLAGS`` environment variable.
"""

import importlib.util
import os
import pathlib
import platform

import jax
import jax.numpy as jnp
import numpy as np
from absl import app, flags

from pushjax.physics import lynch
from timing import seconds_per_call

_BATCH = flags.DEFINE_integer("batch", 1_000_000, "Pushes per call.")
_REPEATS = flags.DEFINE_integer("repeats", 20, "Timed calls per JAX measurement.")
_NUMPY_REPEATS = flags.DEFINE_integer("numpy_repeats", 5, "Timed calls per NumPy measurement.")
_DTYPE = flags.DEFINE_enum("dtype", "float32", ["float32", "float64"], "Floating point type.")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the random pushes.")

_REFERENCE_PATH = (
    pathlib.Path(__file__).resolve().parents[1] / "tests" / "physics" / "numpy_lynch.py"
)


def _load_numpy_reference():
    spec = importlib.util.spec_from_file_location("numpy_lynch", _REFERENCE_PATH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def numpy_closed_form(contact, normal, action, l, mu, s):
    """The algorithm of ``lynch.predict`` in vectorised NumPy: [N, 3] twists."""
    cx, cy = contact[:, 0], contact[:, 1]
    nx, ny = normal[:, 0], normal[:, 1]
    ux, uy = action[:, 0], action[:, 1]
    l2 = l * l
    c_dot_u = cx * ux + cy * uy
    force_x, force_y = l2 * ux + c_dot_u * cx, l2 * uy + c_dot_u * cy
    n_cross_force = nx * force_y - ny * force_x
    u_dot_n = ux * nx + uy * ny
    pushing = u_dot_n > 0
    sticking = pushing & (np.abs(n_cross_force) <= mu * (nx * force_x + ny * force_y))
    side_mu = np.where(n_cross_force > 0, mu, -mu)
    c_cross_n = cx * ny - cy * nx
    torque = c_cross_n + side_mu * (cx * nx + cy * ny)
    boundary_velocity_dot_n = l2 * (nx * nx + ny * ny) + torque * c_cross_n
    slipping = pushing & ~sticking & (boundary_velocity_dot_n > 0)
    numerator = s * np.where(sticking, 1, np.where(slipping, u_dot_n, 0))
    denominator = np.where(
        sticking, l2 + cx * cx + cy * cy, np.where(slipping, boundary_velocity_dot_n, 1)
    )
    scale = numerator / denominator
    return np.stack(
        [
            scale * np.where(sticking, force_x, l2 * (nx - side_mu * ny)),
            scale * np.where(sticking, force_y, l2 * (ny + side_mu * nx)),
            scale * np.where(sticking, cx * uy - cy * ux, torque),
        ],
        axis=-1,
    )


def random_pushes(batch: int, dtype, seed: int):
    """Pushes on MIT-Push-sized objects (m): ~18 % sticking, ~65 % slipping, ~17 % pulling."""
    rng = np.random.default_rng(seed)
    l = rng.uniform(0.03, 0.045, batch)
    contact = rng.uniform(-0.07, 0.07, (batch, 2))
    normal_angle = rng.uniform(-np.pi, np.pi, batch)
    normal = np.stack([np.cos(normal_angle), np.sin(normal_angle)], axis=-1)
    action_angle = normal_angle + rng.uniform(-0.6, 0.6, batch) * np.pi
    action = np.stack([np.cos(action_angle), np.sin(action_angle)], -1) * rng.uniform(
        0.001, 0.01, (batch, 1)
    )
    mu = rng.uniform(0.1, 0.6, batch)
    s = rng.uniform(0, 1, batch)
    return [x.astype(dtype) for x in (contact, normal, action, l, mu, s)]


def main(argv):
    del argv
    dtype = np.dtype(_DTYPE.value)
    jax.config.update("jax_enable_x64", dtype == np.float64)
    batch = _BATCH.value
    pushes = random_pushes(batch, dtype, _SEED.value)
    device_pushes = [jnp.asarray(x) for x in pushes]
    numpy_reference = _load_numpy_reference()

    gradient = jax.jit(
        jax.grad(lambda *args: jnp.sum(lynch.predict(*args)), argnums=tuple(range(6)))
    )
    rows = [
        (
            "JAX `predict`",
            "forward",
            seconds_per_call(lynch.predict, device_pushes, _REPEATS.value),
        ),
        (
            "JAX `grad` w.r.t. all 6 inputs",
            "forward + backward",
            seconds_per_call(gradient, device_pushes, _REPEATS.value),
        ),
        (
            "NumPy reference (tests/physics/numpy_lynch.py)",
            "forward",
            seconds_per_call(numpy_reference.predict, pushes, _NUMPY_REPEATS.value),
        ),
        (
            "NumPy, same closed form as JAX",
            "forward",
            seconds_per_call(numpy_closed_form, pushes, _NUMPY_REPEATS.value),
        ),
    ]
    forward_seconds = rows[0][2][0]
    print(
        f"batch {batch:,} {dtype.name} pushes; jax {jax.__version__} on {jax.devices()[0]}, "
        f"{os.cpu_count()} CPUs ({platform.processor() or platform.machine()}), "
        f"load average {os.getloadavg()[0]:.2f}, XLA_FLAGS={os.environ.get('XLA_FLAGS', '')!r}\n"
    )
    print(
        "| implementation | pass | pushes/s (median) | ms / batch (median, best) "
        "| time / JAX forward |"
    )
    print("|---|---|---:|---:|---:|")
    for name, kind, (seconds, best) in rows:
        print(
            f"| {name} | {kind} | {batch / seconds / 1e6:.1f} M | {seconds * 1e3:.2f}, "
            f"{best * 1e3:.2f} | {seconds / forward_seconds:.1f}x |"
        )


if __name__ == "__main__":
    app.run(main)
