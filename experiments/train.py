r"""Train one model variant of Kloss et al. on a push dataset and evaluate it on one split.

  python -m experiments.train --variant=hybrid --experiment=data_efficiency --scale=smoke --workdir=DIR \
      [--sizes=100,500] [--seeds=0,1,2] [--mix_error_variants] [--num_steps=N] [--data_dir=DIR] \
      [--train_split=train] [--test_split=test] [--nobuild] [--mode=vmap|unroll|sequential] \
      [--config.learning_rate=3e-4 --config.model.head_features=64,32 ...]

One sweep trains a model per (training-set size, seed), each on its own random subset of the training split.
Without ``--sizes`` every model sees the whole split. ``--mix_error_variants`` (with an error variant) trains
error, error_grad and error_norm side by side for every subset. The view follows the experiment
(``viewpoint``: free camera, point clouds; otherwise top-down depth), the glimpse size the dataset config.

The run goes through the same orchestrator as the experiment binaries (`pushjax.paper.runner.run`): the work
directory gets ``<train_split>/l1/<variants>/`` (checkpoints with the model configuration, so an interrupted run
resumes and `pushjax.train.predictor.load_model` loads a model; ``metrics.csv``, ``curves.csv`` and TensorBoard event
files under ``tensorboard/``) and ``results.json`` in the schema documented there. ``--config.<field>`` replaces any
field of the training config (`pushjax.paper.cli`), recorded in ``results.json``'s ``config``.
"""

from __future__ import annotations

from absl import app, flags

import experiments
from pushjax.data import configs as data_configs
from pushjax.models import ERROR_OPTIONS, VARIANTS
from pushjax.paper import cli
from pushjax.paper.spec import Setup

# --scale, --workdir, --sizes, --seeds, --num_steps, --data_dir, --build, --workers, --mode: see pushjax.paper.cli
# (its --variants, when given, replaces --variant).
flags.adopt_module_key_flags(cli)
_VARIANT = flags.DEFINE_enum("variant", "hybrid", VARIANTS, "Model variant.")
_EXPERIMENT = flags.DEFINE_enum("experiment", "data_efficiency", data_configs.EXPERIMENTS, "Dataset experiment.")
_MIX = flags.DEFINE_bool("mix_error_variants", False, "Train error, error_grad and error_norm together.")
_TRAIN_SPLIT = flags.DEFINE_string("train_split", "train", "Training split.")
_TEST_SPLIT = flags.DEFINE_string("test_split", "test", "Evaluation split.")


def setup(variant: str, experiment: str, mix_error_variants: bool = False, train_split: str = "train",
          test_split: str = "test") -> Setup:
    """The `Setup` of one variant (or the three error variants) trained on one split and tested on another."""
    if mix_error_variants and variant not in ERROR_OPTIONS:
        raise ValueError(f"mix_error_variants: needs an error variant, got variant {variant!r}")
    return Setup("train", experiment, tuple(ERROR_OPTIONS) if mix_error_variants else (variant,),
                 train_splits=(train_split,), test_splits=(test_split,))


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    try:
        experiment_setup = setup(_VARIANT.value, _EXPERIMENT.value, _MIX.value, _TRAIN_SPLIT.value, _TEST_SPLIT.value)
    except ValueError as error:
        raise app.UsageError(f"--{error}") from error
    outcome = cli.run_spec(cli.spec_from_flags(experiment_setup))
    for row in outcome.results["rows"]:
        print(
            f"{row['model']:>10} size={row['train_size']} seed={row['seed']} ({row['steps']} steps): "
            f"trans {row['trans_percent']:.1f} ± {row['trans_percent_se']:.1f} %, "
            f"rot {row['rot_percent']:.1f} ± {row['rot_percent_se']:.1f} %, pos {row.get('pos_mm') or float('nan'):.2f} mm"
        )
    print(f"wrote results.json and {len(outcome.sweeps)} sweep folder{'s' * (len(outcome.sweeps) != 1)} "
          f"(checkpoints, metrics.csv) to {cli.WORKDIR.value}")


if __name__ == "__main__":
    experiments.run(main)
