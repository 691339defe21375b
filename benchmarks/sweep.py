"""Sweep trainer: K models in one sweep against K separate runs.

Trains K = len(sizes) * len(seeds) models (a random training subset per size and seed) of one variant
on the smoke ``data_efficiency`` dataset (built under ``--data_dir`` on first use): as K one-model
runs one after another, and as one sweep with ``pushjax.train.sweep`` in each mode (``vmap``,
``unroll``: one jitted step for all K models; ``sequential``: the single-model step per model). Prints the wall time of each (compilation included, as a user sees it) and the
steady-state time per step of all K models (compilation excluded: the time from the end of step 10 on).

    python benchmarks/sweep.py [--variant=hybrid] [--scale=smoke] [--sizes=100,300] [--seeds=0,1]
        [--num_steps=200] [--data_dir=/tmp/pushjax_bench_data]
"""

import dataclasses
import os
import platform
import tempfile

import jax
from absl import app, flags

from pushjax import train
from pushjax.data import testing
from pushjax.models import VARIANTS
from pushjax.data import configs as data_configs
from pushjax.train.configs import get_config
from sweep_timing import timed_sweep

_VARIANT = flags.DEFINE_enum("variant", "hybrid", VARIANTS, "Model variant.")
_SCALE = flags.DEFINE_enum("scale", "smoke", data_configs.SCALES, "Model and optimiser config scale.")
_SIZES = flags.DEFINE_list("sizes", ["100", "300"], "Training-set sizes.")
_SEEDS = flags.DEFINE_list("seeds", ["0", "1"], "Subset seeds per size.")
_NUM_STEPS = flags.DEFINE_integer("num_steps", 200, "Steps per model.", lower_bound=20)
_DATA_DIR = flags.DEFINE_string(
    "data_dir", os.path.join(tempfile.gettempdir(), "pushjax_bench_data"), "Where the smoke dataset is built."
)


def _timed(config, examples, specs, mode):
    """`timed_sweep` of one sweep in `mode`, or for "separate" the sums over K one-model sweeps."""
    if mode != "separate":
        return timed_sweep(config, examples, specs, mode)
    times = [timed_sweep(config, examples, [spec], "unroll") for spec in specs]
    return sum(total for total, _ in times), sum(steady for _, steady in times)


def main(argv):
    del argv
    splits = testing.smoke_dataset(_DATA_DIR.value)
    config = get_config(data_configs.get_config("data_efficiency", _SCALE.value)).with_variant(_VARIANT.value)
    config = dataclasses.replace(config, num_steps=_NUM_STEPS.value)
    fields = train.model_fields(config.model)
    examples = train.examples_from_source(splits["train"], fields)
    specs = train.subset_specs(
        len(examples["motion"]), [int(s) for s in _SIZES.value], [int(s) for s in _SEEDS.value]
    )
    # Baseline: K separate one-model runs, as `experiments.train` does for a single model; the step
    # is compiled once and reused (a separate process per run would compile K times).
    timings = {mode: _timed(config, examples, specs, mode) for mode in ("separate", *train.SWEEP_MODES)}
    separate_total, separate_step = timings["separate"]
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, jax {jax.__version__}, "
          f"{jax.devices()[0].platform}; variant {_VARIANT.value}, scale {_SCALE.value}, K = {len(specs)} models, "
          f"{config.num_steps} steps, batch {config.batch_size}, images {examples['depth'].shape[1:3]}")
    print("| mode | total s (incl. compile) | ms per step of all K models (steady) | speed-up total / steady "
          "over separate runs |")
    print("|---|---|---|---|")
    for mode, (total, step) in timings.items():
        print(f"| {mode} | {total:.1f} | {1000 * step:.1f} | "
              f"{separate_total / total:.2f}x / {separate_step / step:.2f}x |")


if __name__ == "__main__":
    app.run(main)
