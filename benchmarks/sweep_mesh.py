"""Sweep trainer on several devices: time per step of K models, the model axis split over 1, 2 and 4 devices.

Trains K = len(sizes) * len(seeds) models of one variant on the smoke ``data_efficiency`` dataset (built
under ``--data_dir`` on first use) with ``pushjax.train.sweep`` in the ``vmap`` and ``unroll`` modes, which
split the model axis over all visible devices (`pushjax.train.mesh`), once per device count D in a child
process that sees D CPU devices (``XLA_FLAGS=--xla_force_host_platform_device_count=D``,
``JAX_PLATFORMS=cpu``); ``sequential``, which uses one device, runs with D = 1 as the reference. Prints
the wall time of each run (compilation included) and the steady-state time per step of all K models
(compilation excluded: the time from the end of step 10 on).

    python benchmarks/sweep_mesh.py [--device_counts=1,2,4] [--modes=vmap,unroll,sequential]
        [--variant=hybrid] [--scale=smoke] [--sizes=100,200,300,400] [--seeds=0,1] [--num_steps=40]
        [--data_dir=/tmp/pushjax_bench_data]
"""

import dataclasses
import json
import os
import platform
import subprocess
import sys
import tempfile

import jax
from absl import app, flags

from pushjax import train
from pushjax.data import configs as data_configs
from pushjax.data import testing
from pushjax.models import VARIANTS
from pushjax.train.configs import get_config
from sweep_timing import timed_sweep

_DEVICE_COUNTS = flags.DEFINE_list("device_counts", ["1", "2", "4"], "Numbers of CPU devices D to time.")
_MODES = flags.DEFINE_list("modes", ["vmap", "unroll", "sequential"], "Sweep modes (sequential only at D = 1).")
_VARIANT = flags.DEFINE_enum("variant", "hybrid", VARIANTS, "Model variant.")
_SCALE = flags.DEFINE_enum("scale", "smoke", data_configs.SCALES, "Model and optimiser config scale.")
_SIZES = flags.DEFINE_list("sizes", ["100", "200", "300", "400"], "Training-set sizes.")
_SEEDS = flags.DEFINE_list("seeds", ["0", "1"], "Subset seeds per size.")
_NUM_STEPS = flags.DEFINE_integer("num_steps", 40, "Steps per model.", lower_bound=20)
_DATA_DIR = flags.DEFINE_string(
    "data_dir", os.path.join(tempfile.gettempdir(), "pushjax_bench_data"), "Where the smoke dataset is built."
)
_DEVICES = flags.DEFINE_integer("devices", 0, "Internal: run as the child process that sees this many devices.")


def _child(devices):
    """Times each mode on this process's `devices` CPU devices; prints {mode: [total s, s per step]} as JSON."""
    if jax.device_count() != devices:
        raise RuntimeError(f"expected {devices} devices, got {jax.devices()}")
    config = get_config(data_configs.get_config("data_efficiency", _SCALE.value)).with_variant(_VARIANT.value)
    config = dataclasses.replace(config, num_steps=_NUM_STEPS.value)
    examples = train.examples_from_source(testing.smoke_dataset(_DATA_DIR.value)["train"],
                                          train.model_fields(config.model))
    specs = train.subset_specs(
        len(examples["motion"]), [int(s) for s in _SIZES.value], [int(s) for s in _SEEDS.value]
    )
    modes = [mode for mode in _MODES.value if mode != "sequential" or devices == 1]
    print(json.dumps({mode: timed_sweep(config, examples, specs, mode) for mode in modes}))


def main(argv):
    del argv
    if _DEVICES.value:
        _child(_DEVICES.value)
        return
    testing.smoke_dataset(_DATA_DIR.value)  # built once, before the children load it
    timings = {}
    for devices in map(int, _DEVICE_COUNTS.value):
        flags_env = f"{os.environ.get('XLA_FLAGS', '')} --xla_force_host_platform_device_count={devices}".strip()
        completed = subprocess.run(
            [sys.executable, __file__, f"--devices={devices}", *(a for a in sys.argv[1:] if a.startswith("--"))],
            env={**os.environ, "XLA_FLAGS": flags_env, "JAX_PLATFORMS": "cpu"}, capture_output=True, text=True,
            check=False,
        )
        if completed.returncode:
            sys.exit(completed.stderr[-3000:])
        timings[devices] = json.loads(completed.stdout.strip().splitlines()[-1])
    count = len(_SIZES.value) * len(_SEEDS.value)
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, jax {jax.__version__}; variant "
          f"{_VARIANT.value}, scale {_SCALE.value}, K = {count} models, {_NUM_STEPS.value} steps")
    print("| mode | devices D | models per device | total s (incl. compile) | ms per step of all K models (steady) |")
    print("|---|---:|---:|---:|---:|")
    for devices, modes in timings.items():
        for mode, (total, step) in modes.items():
            per_device = count if mode == "sequential" else -(-count // min(count, devices))
            print(f"| {mode} | {devices} | {per_device} | {total:.1f} | {1000 * step:.1f} |")


if __name__ == "__main__":
    app.run(main)
