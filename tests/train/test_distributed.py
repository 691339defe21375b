"""Several processes training one sweep: 2 processes x 2 forced host devices, joined by ``jax.distributed`` on
loopback, against the single-device sequential sweep; and `distributed.initialize`'s argument checks."""

import json
import os
import socket
import subprocess
import sys
from pathlib import Path

import jax
import numpy as np
import pytest

from pushjax import train
from pushjax.train import distributed
from tests.train.test_mesh import CHILD_XLA_FLAGS, CONFIG, assert_equals_sequential

REPOSITORY = Path(__file__).resolve().parents[2]
SPECS = train.subset_specs(256, [30, 60, 100], [0])
"""K = 3 models on 2 processes x 2 devices: one model per device (the cheapest step to compile), one padding row."""

_PROCESS = """
import dataclasses, json, sys
import numpy as np
from pushjax import train
from pushjax.train import distributed, mesh
from tests.train.test_distributed import CONFIG, SPECS

address, process_id, examples_path, workdir, out = sys.argv[1:]
process_id = int(process_id)
distributed.initialize(address, 2, process_id)  # after importing pushjax, as in the binaries
import jax
assert (jax.process_count(), jax.device_count(), jax.local_device_count()) == (2, 4, 2), jax.devices()
# 3 models padded to 4 on 4 devices: process 0 feeds models 0 and 1, process 1 model 2 and its padding copy.
assert mesh.local_rows(4, mesh.sweep_mesh(len(SPECS))) == range(2 * process_id, 2 * process_id + 2)
examples = dict(np.load(examples_path))
layouts = []

def record_layout(step, metrics):
    # (devices, of which this process's, leading axis, leading axes of this process's shards) of every array
    # placed on several devices
    layouts.extend({(len(a.sharding.device_set), len(a.addressable_shards), a.shape[0],
                     *sorted({s.data.shape[0] for s in a.addressable_shards}))
                    for a in jax.live_arrays() if len(a.sharding.device_set) > 1})

# Half the steps, then a restart that resumes from the checkpoint (a new process costs a new compilation).
half = dataclasses.replace(CONFIG, num_steps=CONFIG.num_steps // 2)
train.sweep(half, examples, SPECS, workdir, mode="unroll", progress=False, step_callback=record_layout)
result = train.sweep(CONFIG, examples, SPECS, workdir, mode="unroll", progress=False)
leaves = jax.tree.leaves(result.state)
distributed.wait_for_all("sweep done")  # returns once both processes got here
np.savez(f"{out}{process_id}.npz", *[np.asarray(leaf) for leaf in leaves])
with open(f"{out}{process_id}.json", "w") as file:
    json.dump({"layouts": sorted(set(layouts)), "state_leaves": len(leaves),
               "loss": result.final_metrics["loss"].tolist(), "writer": distributed.is_writer(),
               "on_own_first_device": all(leaf.devices() == {jax.local_devices()[0]} for leaf in leaves)}, file)
"""


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def test_sweep_on_2_processes_equals_the_sequential_sweep_on_one_device(examples, tmp_path):
    np.savez(tmp_path / "examples.npz", **{name: examples[name] for name in train.model_fields(CONFIG.model)})
    flags = f"{os.environ.get('XLA_FLAGS', '')} --xla_force_host_platform_device_count=2 {CHILD_XLA_FLAGS}".strip()
    address = f"127.0.0.1:{_free_port()}"
    logs = [tmp_path / f"process{index}.log" for index in range(2)]
    children = []
    try:
        for index, log in enumerate(logs):
            with log.open("w") as output:
                children.append(subprocess.Popen(
                    [sys.executable, "-c", _PROCESS, address, str(index), str(tmp_path / "examples.npz"),
                     str(tmp_path / "distributed"), str(tmp_path / "out")],
                    cwd=REPOSITORY, env={**os.environ, "XLA_FLAGS": flags, "JAX_PLATFORMS": "cpu"}, stdout=output,
                    stderr=subprocess.STDOUT,
                ))
        # The children compile while this process trains the reference.
        with jax.default_device(jax.devices("cpu")[0]):  # the children's backend, also on a host with a GPU
            sequential = train.sweep(CONFIG, examples, SPECS, tmp_path / "sequential", mode="sequential",
                                     progress=False)
        for child in children:
            child.wait(timeout=600)
    finally:
        for child in children:
            child.kill()
    for child, log in zip(children, logs):
        assert child.returncode == 0, log.read_text()[-3000:]
    outputs = [json.loads((tmp_path / f"out{index}.json").read_text()) for index in range(2)]
    leaves = []
    for index, output in enumerate(outputs):
        with np.load(tmp_path / f"out{index}.npz") as file:
            leaves.append([file[f"arr_{i}"] for i in range(output["state_leaves"])])

    # Between steps the stacked state and batch of the 3 models, padded to 4, lay on the 4 devices of both
    # processes, one model each, 2 of the devices in each process; nothing else was spread over several devices.
    # The result is on each process's first device, and every process has every model (gathered from both).
    for output in outputs:
        assert [tuple(layout) for layout in output["layouts"]] == [(4, 2, 4, 1)], output["layouts"]
        assert output["on_own_first_device"]
    assert outputs[0]["loss"] == outputs[1]["loss"]
    assert [output["writer"] for output in outputs] == [True, False]
    for got, want in zip(*leaves):
        np.testing.assert_array_equal(got, want)
    # metrics.csv has the sequential sweep's rows once (process 0 wrote it), and the checkpoint resumes here, in one
    # process on one device.
    assert_equals_sequential(examples, tmp_path / "distributed", leaves[0], outputs[0]["loss"], sequential,
                             tmp_path / "sequential")


@pytest.mark.parametrize("arguments, name", [
    ((None, 0, 0), "num_processes"),
    ((None, 2, 2), "process_id"),
    ((None, 1, -1), "process_id"),
    (("127.0.0.1:1234", 1, 0), "coordinator_address"),
    ((None, 2, 0), "coordinator_address"),
    (("127.0.0.1", 2, 0), "coordinator_address"),
    (("127.0.0.1:http", 2, 0), "coordinator_address"),
    ((":1234", 2, 0), "coordinator_address"),
    (("127.0.0.1:70000", 2, 0), "coordinator_address"),
])
def test_initialize_rejects_bad_arguments_naming_them(arguments, name):
    with pytest.raises(ValueError, match=f"^{name}: "):
        distributed.initialize(*arguments)


def test_initialize_with_one_process_does_nothing():
    distributed.initialize()
    assert jax.process_count() == 1
    assert distributed.is_writer()
    distributed.wait_for_all("nothing to wait for")
