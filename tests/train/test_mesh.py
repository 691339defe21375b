"""The sweep's model axis over a device mesh: padding and sharding, and a sweep of 6 models on 4 forced
host devices against the single-device sequential sweep."""

import csv
import dataclasses
import json
import os
import subprocess
import sys
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from pushjax import train
from pushjax.train import mesh
from tests.tiny_configs import TINY_SMOKE

REPOSITORY = Path(__file__).resolve().parents[2]
CONFIG = dataclasses.replace(TINY_SMOKE.with_variant("hybrid", "top_down"), num_steps=8, checkpoint_every=4,
                             log_every=2)
SPECS = train.subset_specs(256, [30, 60, 100], [0, 1])
"""K = 6 models, not a multiple of 4 devices."""
CHILD_XLA_FLAGS = "--xla_backend_optimization_level=0"
"""Added to the XLA flags of the forced-device children (here and in test_distributed.py): their programs run 8 steps,
so compiling them without LLVM's optimisations saves a quarter of each child's CPU time (the 4-device child: 32 -> 25
s), and they agree with the sequential sweep as closely (the worst parameter 1.6 % of `assert_equals_sequential`'s
tolerance, against 3 % with the optimisations). The sharding is decided before LLVM runs, so the layouts are the same."""

_SHARDED_RUN = """
import dataclasses, json, sys
import jax, numpy as np
from pushjax import train
from tests.train.test_mesh import CONFIG, SPECS

examples_path, workdir, out = sys.argv[1:]
assert jax.device_count() == 4, jax.devices()
examples = dict(np.load(examples_path))
layouts = []

def leading(array):
    return array.shape[0] if array.ndim else None

def record_layout(step, metrics):
    # (devices, leading axis, leading axes of the shards) of every array placed on several devices
    layouts.extend({(len(a.sharding.device_set), leading(a), *sorted({leading(s.data) for s in a.addressable_shards}))
                    for a in jax.live_arrays() if len(a.sharding.device_set) > 1})

# Half the steps, then a restart that resumes from the checkpoint on the same 4 devices.
half = dataclasses.replace(CONFIG, num_steps=CONFIG.num_steps // 2)
train.sweep(half, examples, SPECS, workdir, mode="vmap", progress=False, step_callback=record_layout)
result = train.sweep(CONFIG, examples, SPECS, workdir, mode="vmap", progress=False)
leaves = jax.tree.leaves(result.state)
np.savez(out + ".npz", *[np.asarray(leaf) for leaf in leaves])
with open(out + ".json", "w") as file:
    json.dump({"layouts": sorted(set(layouts)), "state_leaves": len(leaves),
               "result_devices": sorted({len(leaf.sharding.device_set) for leaf in leaves}),
               "loss": result.final_metrics["loss"].tolist()}, file)
"""


def test_pad_shard_and_unshard_round_trip():
    device_mesh = mesh.model_mesh()
    assert device_mesh.axis_names == (mesh.MODEL_AXIS,) and device_mesh.size == jax.device_count()
    assert mesh.padded_count(6, mesh.model_mesh(jax.devices()[:1])) == 6
    tree = {"host": np.arange(12).reshape(6, 2), "device": jnp.arange(6.0)}
    padded = mesh.pad(tree, 8)
    assert isinstance(padded["host"], np.ndarray) and isinstance(padded["device"], jax.Array)
    np.testing.assert_array_equal(padded["host"], np.concatenate([tree["host"], [[10, 11], [10, 11]]]))
    np.testing.assert_array_equal(padded["device"], [0, 1, 2, 3, 4, 5, 5, 5])
    assert mesh.pad(tree, 6)["host"] is tree["host"]
    assert mesh.local_rows(8, device_mesh) == range(8)  # one process holds every row
    restored = mesh.unshard(mesh.shard(padded, 8, device_mesh), 6, device_mesh)
    jax.tree.map(np.testing.assert_array_equal, restored, jax.tree.map(np.asarray, tree))


def _rows(path):
    with path.open() as file:
        return list(csv.DictReader(file))


def assert_equals_sequential(examples, workdir, leaves, loss, sequential, sequential_workdir):
    """A sharded sweep of `CONFIG` against the single-device `sequential` sweep of the same models, to float tolerance.

    Also checks that the sharded sweep's checkpoint resumes in this process, on one device, to the same state.

    Args:
      examples: the training split both sweeps trained on.
      workdir: the sharded sweep's work directory (checkpoints, ``metrics.csv``).
      leaves: its final state, ``jax.tree.leaves``, as NumPy arrays.
      loss: [K] its last step's losses.
      sequential: the `SweepResult` of the sequential sweep.
      sequential_workdir: the sequential sweep's work directory.
    """
    specs, reference = sequential.specs, jax.tree.map(np.asarray, sequential.state)
    state = jax.tree.unflatten(jax.tree.structure(reference), leaves)
    assert [(a.shape, a.dtype) for a in leaves] == [(a.shape, a.dtype) for a in jax.tree.leaves(reference)]
    np.testing.assert_array_equal(state.step, [CONFIG.num_steps] * len(specs))
    # Each device runs a vmapped or unrolled step of its models (vmapped: grouped convolutions), whose float
    # summation order differs from one model's step; Adam turns rounding differences of near-zero gradients into
    # differences of up to a step (learning rate 1e-3), hence rtol 1e-3 and atol 1e-4 on the parameters and
    # batch statistics, as for the vmapped against the sequential sweep in test_sweep_trainer. (Adam's
    # moments, raw gradient scale, are left out: their rounding differences are not bounded by a step.)
    jax.tree.map(lambda got, want: np.testing.assert_allclose(got, want, rtol=1e-3, atol=1e-4),
                 (state.params, state.batch_stats), (reference.params, reference.batch_stats))
    np.testing.assert_allclose(loss, sequential.final_metrics["loss"], rtol=1e-3)
    # The models differ (the padding repeats the last one), so the comparison is not trivially true.
    kernel = jax.tree.leaves(sequential.state.params)[0]
    assert all(not np.allclose(kernel[k], kernel[k + 1]) for k in range(len(specs) - 1))

    # metrics.csv: the same rows (no padded model), the resumed half appended, values to the same tolerance.
    rows, want_rows = _rows(Path(workdir) / "metrics.csv"), _rows(Path(sequential_workdir) / "metrics.csv")
    assert [(r["step"], r["model"], r["name"]) for r in rows] == [(r["step"], r["model"], r["name"]) for r in want_rows]
    np.testing.assert_allclose([float(r["loss"]) for r in rows], [float(r["loss"]) for r in want_rows], rtol=1e-3)

    # The checkpoint holds the K models only: it resumes on this one device to the same state.
    restored = train.sweep(CONFIG, examples, specs, workdir, mode="vmap", progress=False)
    for got, want in zip(jax.tree.leaves(restored.state), leaves):
        np.testing.assert_array_equal(np.asarray(got), want)
    np.testing.assert_array_equal(restored.steps_trained, [CONFIG.num_steps] * len(specs))


def test_sweep_on_4_devices_equals_the_sequential_sweep_on_one(examples, tmp_path):
    np.savez(tmp_path / "examples.npz", **{name: examples[name] for name in train.model_fields(CONFIG.model)})
    flags = f"{os.environ.get('XLA_FLAGS', '')} --xla_force_host_platform_device_count=4 {CHILD_XLA_FLAGS}".strip()
    log = tmp_path / "child.log"
    with log.open("w") as output:
        # The child compiles while this process trains the reference (compilation is mostly serial).
        child = subprocess.Popen(
            [sys.executable, "-c", _SHARDED_RUN, str(tmp_path / "examples.npz"), str(tmp_path / "sharded"),
             str(tmp_path / "out")],
            cwd=REPOSITORY, env={**os.environ, "XLA_FLAGS": flags, "JAX_PLATFORMS": "cpu"}, stdout=output,
            stderr=subprocess.STDOUT,
        )
        try:
            with jax.default_device(jax.devices("cpu")[0]):  # the child's backend, also on a host with a GPU
                sequential = train.sweep(CONFIG, examples, SPECS, tmp_path / "sequential", mode="sequential",
                                         progress=False)
        finally:
            child.wait(timeout=600)
    assert child.returncode == 0, log.read_text()[-3000:]
    sharded = json.loads((tmp_path / "out.json").read_text())
    with np.load(tmp_path / "out.npz") as file:
        sharded_leaves = [file[f"arr_{i}"] for i in range(sharded["state_leaves"])]

    # Between steps the stacked state (and batch) of the 6 models, padded to 8, lay on 4 devices, 2 models
    # each; nothing else was spread over several devices. The result is back on one device.
    assert [tuple(layout) for layout in sharded["layouts"]] == [(4, 8, 2)], sharded["layouts"]
    assert sharded["result_devices"] == [1]

    assert_equals_sequential(examples, tmp_path / "sharded", sharded_leaves, sharded["loss"], sequential,
                             tmp_path / "sequential")
