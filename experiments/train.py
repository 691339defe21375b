r"""Train models of Kloss et al. on a push dataset and evaluate them on its test split.

  python -m experiments.train --variant=hybrid --experiment=data_efficiency --scale=smoke --workdir=DIR \
      [--sizes=100,500] [--seeds=0,1,2] [--mix_error_variants] [--num_steps=N] [--data_dir=DIR] \
      [--train_split=train] [--test_split=test] [--build] [--mode=vmap|unroll|sequential]

One sweep trains a model per (training-set size, seed) — each on its own random subset of the training
split — with one vmapped jit-compiled step (`pushjax.train.sweep`). Without ``--sizes`` every model sees
the whole split. ``--mix_error_variants`` (with an error variant) trains error, error_grad and
error_norm side by side for every subset. The view follows the experiment (``viewpoint``: free camera,
point clouds; otherwise top-down depth), the glimpse size the dataset config.

The work directory gets ``checkpoints/`` (an interrupted run resumes where it stopped), ``metrics.csv``
(training metrics, mm / degrees) and ``results.json`` (test metrics per model, `pushjax.train.evaluate`).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from pathlib import Path

import jax
from absl import app, flags

from pushjax import data
from pushjax.models import ERROR_OPTIONS, VARIANTS
from pushjax.train import evaluate, train
from pushjax.train.configs import SCALES, get_config

_VARIANT = flags.DEFINE_enum("variant", "hybrid", VARIANTS, "Model variant.")
_EXPERIMENT = flags.DEFINE_string("experiment", "data_efficiency", "Dataset experiment (pushjax.data.EXPERIMENTS).")
_SCALE = flags.DEFINE_enum("scale", "smoke", SCALES, "Dataset and training scale.")
_WORKDIR = flags.DEFINE_string("workdir", None, "Checkpoints, metrics.csv and results.json.", required=True)
_SIZES = flags.DEFINE_list("sizes", [], "Training-set sizes (default: the whole training split).")
_SEEDS = flags.DEFINE_list("seeds", ["0"], "Subset and initialisation seeds.")
_MIX = flags.DEFINE_bool("mix_error_variants", False, "Train error, error_grad and error_norm together.")
_NUM_STEPS = flags.DEFINE_integer("num_steps", None, "Override the config's number of steps.", lower_bound=1)
_DATA_DIR = flags.DEFINE_string("data_dir", None, "TFDS data directory (default: TFDS's).")
_TRAIN_SPLIT = flags.DEFINE_string("train_split", "train", "Training split.")
_TEST_SPLIT = flags.DEFINE_string("test_split", "test", "Evaluation split.")
_BUILD = flags.DEFINE_bool("build", False, "Build the dataset first when it is missing.")
_MODE = flags.DEFINE_enum(
    "mode", None, train.SWEEP_MODES, "How the sweep batches its models (default: unroll on CPU, else vmap)."
)


def train_experiment(
    variant: str, experiment: str, scale: str, workdir: str | Path, *, sizes: Sequence[int] = (),
    seeds: Sequence[int] = (0,), mix_error_variants: bool = False, num_steps: int | None = None,
    data_dir: str | Path | None = None, train_split: str = "train", test_split: str = "test",
    build: bool = False, progress: bool = True, mode: str | None = None,
) -> list[dict]:
    """Trains the sweep described in the module docstring; returns the per-model test results."""
    if mix_error_variants and variant not in ERROR_OPTIONS:
        raise ValueError(f"mix_error_variants: needs an error variant, got variant {variant!r}")
    dataset_config = data.get_config(experiment, scale)
    if build:
        data.build(experiment, scale, data_dir=data_dir, progress=progress)
    splits = data.load(experiment, scale, data_dir=data_dir)
    for split in (train_split, test_split):
        if split not in splits:
            raise ValueError(f"split: {split!r} is not a split of {experiment}; choose from {sorted(splits)}")
    config = get_config(scale).with_variant(variant, dataset_config.camera)
    config = dataclasses.replace(
        config,
        model=dataclasses.replace(config.model, glimpse_size=dataset_config.glimpse_size),
        num_steps=num_steps or config.num_steps,
    )
    fields = (*train.model_fields(config.model), *train.EVALUATION_FIELDS)
    train_examples = train.examples_from_source(splits[train_split], fields)
    test_examples = train.examples_from_source(splits[test_split], fields)
    count = len(train_examples["motion"])
    variants = tuple(ERROR_OPTIONS) if mix_error_variants else (None,)
    specs = train.subset_specs(count, [int(s) for s in sizes] or [count], [int(s) for s in seeds], variants)
    if mode is None:
        mode = "unroll" if jax.default_backend() == "cpu" else "vmap"
    result = train.sweep(config, train_examples, specs, workdir, mode=mode, progress=progress)
    results = [
        {"name": spec.name, "variant": spec.variant or variant, "train_size": len(spec.train_indices),
         "seed": spec.seed, **metrics}
        for spec, metrics in zip(specs, evaluate.evaluate_sweep(result, test_examples, config.eval_batch_size))
    ]
    (Path(workdir) / "results.json").write_text(json.dumps(results, indent=2))
    return results


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    results = train_experiment(
        _VARIANT.value, _EXPERIMENT.value, _SCALE.value, _WORKDIR.value, sizes=_SIZES.value,
        seeds=_SEEDS.value, mix_error_variants=_MIX.value, num_steps=_NUM_STEPS.value,
        data_dir=_DATA_DIR.value, train_split=_TRAIN_SPLIT.value, test_split=_TEST_SPLIT.value,
        build=_BUILD.value, mode=_MODE.value,
    )
    for row in results:
        print(
            f"{row['name']:>28}: trans {row['trans_percent']:.1f} ± {row['trans_percent_se']:.1f} %, "
            f"rot {row['rot_percent']:.1f} ± {row['rot_percent_se']:.1f} %, "
            f"pos {row.get('pos_mm', float('nan')):.2f} mm"
        )


if __name__ == "__main__":
    app.run(main)
