"""Training throughput of the ``data_efficiency_full`` run (issue 30): model-steps per second per variant.

One model of each variant of the run (and neural / hybrid at the paper's widths) with the ``cpu_full`` training config
(64 x 64 depth, 20 x 20 px glimpses, batch 32, the single-model step the trainer jits in ``sequential`` mode) on the examples
of ``--data_dir``'s ``data_efficiency`` dataset at ``--scale`` (the smoke dataset has the same image and glimpse
size as ``cpu_full``). Per variant: the steady-state seconds per step (after `--warmup` steps), split into the input
handling (drawing the batch's indices and gathering its arrays, `pushjax.train.batching`) and the jitted step; and
the evaluation speed (examples per second of `pushjax.train.evaluate.predict`). With ``--at_once=N``, a second table:
N models of each variant (seeds 0..N-1) trained one after the other and then at the same time in N threads, as
``experiments.data_efficiency_full --models_at_once=N`` trains them, in model-steps per second, and whether the
threads' parameters equal the sequential ones.

    python benchmarks/full_throughput.py [--data_dir=/tmp/pushjax_bench_data] [--scale=smoke] [--steps=200] [--at_once=2]
"""

import dataclasses
import os
import tempfile
import threading
import time

import jax
import numpy as np
from absl import app, flags

from pushjax import train
from pushjax.data import configs as data_configs, load, testing
from pushjax.models import ModelConfig, PushModel
from pushjax.train import evaluate
from pushjax.train.batching import ModelSpec, batch_indices, gather, model_fields
from pushjax.train.train_state import create_train_state, make_train_step

_DATA_DIR = flags.DEFINE_string("data_dir", os.path.join(tempfile.gettempdir(), "pushjax_bench_data"),
                                "TFDS data directory (the smoke dataset is built there when --scale=smoke).")
_SCALE = flags.DEFINE_string("scale", "smoke", "Scale of the data_efficiency dataset read.")
_STEPS = flags.DEFINE_integer("steps", 200, "Timed steps per variant.", lower_bound=10)
_WARMUP = flags.DEFINE_integer("warmup", 20, "Steps before timing (compilation).", lower_bound=1)
_AT_ONCE = flags.DEFINE_integer("at_once", 1, "Also time this many models trained at once in threads (1: not).",
                                lower_bound=1)
_VARIANTS = flags.DEFINE_list("variants", ["neural", "hybrid", "error", "simple", "neural_dyn", "neural_wide",
                                           "hybrid_wide"], "Variants (``_wide``: the paper's widths).")


def main(argv):
    del argv
    if _SCALE.value == "smoke":
        testing.smoke_dataset(_DATA_DIR.value)
    splits = load("data_efficiency", _SCALE.value, data_dir=_DATA_DIR.value)
    base = train.get_config(data_configs.get_config("data_efficiency", "cpu_full"))
    print(f"jax {jax.__version__}, {jax.default_backend()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    print("| variant | parameters | input ms/step | jitted step ms | model-steps/s | input share | eval examples/s |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name in _VARIANTS.value:
        variant, wide = name.removesuffix("_wide"), name.endswith("_wide")
        config = base.with_variant(variant)
        if wide:
            config = dataclasses.replace(config, model=dataclasses.replace(
                ModelConfig(), variant=variant, view=config.model.view, glimpse_size=config.model.glimpse_size))
        fields = model_fields(config.model)
        examples = train.examples_from_source(splits["train"], (*fields, *train.EVALUATION_FIELDS))
        spec = ModelSpec("bench", np.arange(len(examples["motion"])), seed=0)
        model = PushModel(config.model)
        optimizer = train.make_optimizer(1e-3, adjustable=True)
        state = create_train_state(model, optimizer, gather(examples, batch_indices(spec, 0, 32), fields), 0)
        step_fn = jax.jit(make_train_step(model, optimizer, config.weight_decay))
        for step in range(_WARMUP.value):
            state, _ = step_fn(state, gather(examples, batch_indices(spec, step, 32), fields))
        jax.block_until_ready(state.params)
        clock = time.perf_counter()
        batches = [gather(examples, batch_indices(spec, step, 32), fields)
                   for step in range(_WARMUP.value, _WARMUP.value + _STEPS.value)]
        input_s = (time.perf_counter() - clock) / _STEPS.value
        clock = time.perf_counter()
        for batch in batches:
            state, _ = step_fn(state, batch)
        jax.block_until_ready(state.params)
        step_s = (time.perf_counter() - clock) / _STEPS.value
        evaluate.predict(model, state, examples, config.eval_batch_size)  # compile
        clock = time.perf_counter()
        evaluate.predict(model, state, examples, config.eval_batch_size)
        eval_rate = len(examples["motion"]) / (time.perf_counter() - clock)
        parameters = sum(np.size(leaf) for leaf in jax.tree.leaves(state.params))
        print(f"| {name} | {parameters:,} | {input_s * 1e3:.2f} | {step_s * 1e3:.1f} | "
              f"{1.0 / (input_s + step_s):.1f} | {input_s / (input_s + step_s):.1%} | {eval_rate:.0f} |", flush=True)

    if _AT_ONCE.value > 1:
        _time_models_at_once(splits, base, _AT_ONCE.value)


def _time_models_at_once(splits, base, count: int) -> None:
    print(f"\n| variant | one at a time, model-steps/s | {count} at once, model-steps/s | speed-up | same parameters |")
    print("|---|---:|---:|---:|---|")
    for name in _VARIANTS.value:
        if name.endswith("_wide"):
            continue
        config = base.with_variant(name)
        fields = model_fields(config.model)
        examples = train.examples_from_source(splits["train"], fields)
        model = PushModel(config.model)
        optimizer = train.make_optimizer(1e-3, adjustable=True)
        step_fn = jax.jit(make_train_step(model, optimizer, config.weight_decay))

        def train_model(seed, steps, out):
            spec = ModelSpec("bench", np.arange(len(examples["motion"])), seed=seed)
            state = create_train_state(model, optimizer, gather(examples, batch_indices(spec, 0, 32), fields), seed)
            for step in range(steps):
                state, _ = step_fn(state, gather(examples, batch_indices(spec, step, 32), fields))
            out[seed] = jax.device_get(state.params)

        train_model(count, _WARMUP.value, {})  # compilation
        sequential, threaded = {}, {}
        clock = time.perf_counter()
        for seed in range(count):
            train_model(seed, _STEPS.value, sequential)
        one_rate = count * _STEPS.value / (time.perf_counter() - clock)
        threads = [threading.Thread(target=train_model, args=(seed, _STEPS.value, threaded)) for seed in range(count)]
        clock = time.perf_counter()
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        many_rate = count * _STEPS.value / (time.perf_counter() - clock)
        same = all(np.array_equal(a, b) for seed in range(count)
                   for a, b in zip(jax.tree.leaves(sequential[seed]), jax.tree.leaves(threaded[seed])))
        print(f"| {name} | {one_rate:.1f} | {many_rate:.1f} | {many_rate / one_rate:.2f}x | {same} |", flush=True)


if __name__ == "__main__":
    app.run(main)
