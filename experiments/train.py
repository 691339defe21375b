r"""Train models of Kloss et al. on a push dataset and evaluate them on its test split.

  python -m experiments.train --variant=hybrid --experiment=data_efficiency --scale=smoke --workdir=DIR \
      [--sizes=100,500] [--seeds=0,1,2] [--mix_error_variants] [--num_steps=N] [--data_dir=DIR] \
      [--train_split=train] [--test_split=test] [--nobuild] [--mode=vmap|unroll|sequential]

One sweep trains a model per (training-set size, seed) — each on its own random subset of the training
split — with one vmapped jit-compiled step (`pushjax.train.sweep`). Without ``--sizes`` every model sees
the whole split. ``--mix_error_variants`` (with an error variant) trains error, error_grad and
error_norm side by side for every subset. The view follows the experiment (``viewpoint``: free camera,
point clouds; otherwise top-down depth), the glimpse size the dataset config.

The work directory gets ``checkpoints/`` (an interrupted run resumes where it stopped), ``metrics.csv``
(training metrics, mm / degrees) and ``results.json`` (test metrics per model, `pushjax.train.evaluate`).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from absl import app, flags

from pushjax import data
from pushjax.experiments import cli, runner
from pushjax.models import ERROR_OPTIONS, VARIANTS
from pushjax.train import train

# --scale, --workdir, --sizes, --seeds, --num_steps, --data_dir, --build, --mode: see pushjax.experiments.cli.
flags.adopt_module_key_flags(cli)
_VARIANT = flags.DEFINE_enum("variant", "hybrid", VARIANTS, "Model variant.")
_EXPERIMENT = flags.DEFINE_string("experiment", "data_efficiency", "Dataset experiment (pushjax.data.EXPERIMENTS).")
_MIX = flags.DEFINE_bool("mix_error_variants", False, "Train error, error_grad and error_norm together.")
_TRAIN_SPLIT = flags.DEFINE_string("train_split", "train", "Training split.")
_TEST_SPLIT = flags.DEFINE_string("test_split", "test", "Evaluation split.")


def train_experiment(
    variant: str, experiment: str, scale: str, workdir: str | Path, *, sizes: Sequence[int] = (),
    seeds: Sequence[int] = (0,), mix_error_variants: bool = False, num_steps: int | None = None,
    data_dir: str | Path | None = None, train_split: str = "train", test_split: str = "test",
    build: bool = False, progress: bool = True, mode: str | None = None,
) -> list[dict]:
    """Trains the sweep described in the module docstring; returns the per-model test results."""
    if mix_error_variants and variant not in ERROR_OPTIONS:
        raise ValueError(f"mix_error_variants: needs an error variant, got variant {variant!r}")
    splits = runner.load_splits(experiment, scale, data_dir, build=build, progress=progress)
    for split in (train_split, test_split):
        if split not in splits:
            raise ValueError(f"split: {split!r} is not a split of {experiment}; choose from {sorted(splits)}")
    config = runner.make_train_config(scale, variant, data.get_config(experiment, scale), num_steps)
    fields = runner.example_fields(config)
    results = runner.train_and_evaluate(
        config, train.examples_from_source(splits[train_split], fields),
        {test_split: train.examples_from_source(splits[test_split], fields)}, workdir,
        sizes=runner.parse_sizes(sizes), seeds=runner.parse_seeds(seeds),
        variants=tuple(ERROR_OPTIONS) if mix_error_variants else (None,), mode=mode, progress=progress,
        train_split=train_split,
    )
    (Path(workdir) / "results.json").write_text(json.dumps(results, indent=2))
    return results


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    arguments = cli.common_arguments()
    results = train_experiment(
        _VARIANT.value, _EXPERIMENT.value, arguments["scale"], arguments["workdir"], sizes=arguments["sizes"],
        seeds=arguments["seeds"], mix_error_variants=_MIX.value, num_steps=arguments["num_steps"],
        data_dir=arguments["data_dir"], train_split=_TRAIN_SPLIT.value, test_split=_TEST_SPLIT.value,
        build=arguments["build"], mode=arguments["mode"],
    )
    for row in results:
        print(
            f"{row['name']:>28}: trans {row['trans_percent']:.1f} ± {row['trans_percent_se']:.1f} %, "
            f"rot {row['rot_percent']:.1f} ± {row['rot_percent_se']:.1f} %, "
            f"pos {row.get('pos_mm', float('nan')):.2f} mm"
        )


if __name__ == "__main__":
    app.run(main)
