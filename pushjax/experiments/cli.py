"""Command-line flags shared by the experiment binaries under ``experiments/``, and their ``main``.

Importing this module defines the flags (absl's global ``FLAGS``); ``experiments/train.py`` shares the common ones.
Each binary is ``main(argv) -> cli.main(<name>, argv)``; `SETUPS` holds what it trains and evaluates
(``visualize`` runs `pushjax.experiments.visualize.run`).
"""

from __future__ import annotations

import dataclasses
import warnings

from absl import app, flags, logging

from pushjax.data import configs as data_configs
from pushjax.experiments import figures, runner, tables, visualize
from pushjax.models import VARIANTS
from pushjax.train import train as train_lib

SCALE = flags.DEFINE_enum("scale", data_configs.DEFAULT_SCALE, data_configs.SCALES, "Dataset and training scale.")
WORKDIR = flags.DEFINE_string("workdir", None, "Output folder: checkpoints, results.json, results.md, figures.")
SIZES = flags.DEFINE_list("sizes", [], "Training-set sizes (default: the experiment's; larger ones are clipped).")
SEEDS = flags.DEFINE_list("seeds", ["0"], "Subset and initialisation seeds.")
NUM_STEPS = flags.DEFINE_integer("num_steps", None, "Override the scale's number of training steps.")
DATA_DIR = flags.DEFINE_string("data_dir", None, "TFDS data directory, must exist (default: TFDS's).")
BUILD = flags.DEFINE_bool("build", True, "Build the dataset when it is missing.")
WORKERS = flags.DEFINE_integer("workers", None, "Dataset build processes (default: the builder's).")
MODE = flags.DEFINE_enum("mode", None, train_lib.SWEEP_MODES, "Sweep batching (default: sequential on CPU, else vmap).")
VARIANTS_FLAG = flags.DEFINE_list("variants", [], "Models to train and baselines (default: the experiment's).")


@dataclasses.dataclass(frozen=True)
class Setup:
    """What one binary runs (arguments of `runner.run`); `models` mixes variants and baselines."""

    experiment: str
    models: tuple[str, ...]
    train_splits: tuple[str, ...] = ("train",)
    test_splits: tuple[str, ...] = ("test",)
    sizes: tuple[int, ...] = ()
    l_scales: tuple[float, ...] = (1.0,)
    l_scaled_models: tuple[str, ...] | None = None


_VELOCITY_TESTS = tuple(f"test_{v:g}" for v in data_configs.TEST_VELOCITIES)
SETUPS = {
    "data_efficiency": Setup("data_efficiency", (*VARIANTS, "zero", "physics"), sizes=(2_500, 190_000)),
    "new_pushes": Setup("new_pushes", ("neural", "neural_dyn", "hybrid", "simple", "error", "zero", "physics"),
                        sizes=(2_500, 190_000)),
    "velocities": Setup("velocities", ("neural", "hybrid", "error", "zero", "physics"),
                        tuple(data_configs.VELOCITY_TRAIN_SETS), _VELOCITY_TESTS),
    "objects": Setup("objects", ("neural", "hybrid", "error", "zero", "physics"),
                     tuple(data_configs.OBJECT_TRAIN_SETS), tuple(data_configs.OBJECT_TEST_SETS)),
    "error_variants": Setup("data_efficiency", ("hybrid", "error", "error_grad", "error_norm", "zero", "physics"),
                            sizes=(2_500, 190_000), l_scales=(1.0, 1.5, 3.0),
                            l_scaled_models=("physics", "hybrid", "error")),
    "viewpoint": Setup("viewpoint", ("hybrid", "zero", "physics")),
}


def common_arguments() -> dict:
    """The parsed common flags as `runner.run` keyword arguments; bad values raise ``app.UsageError``."""
    if WORKDIR.value is None:
        raise app.UsageError("--workdir is required")
    if NUM_STEPS.value is not None and NUM_STEPS.value < 1:
        raise app.UsageError(f"--num_steps: expected a positive integer, got {NUM_STEPS.value}")
    try:
        sizes = runner.parse_sizes(SIZES.value)
        seeds = runner.parse_seeds(SEEDS.value)
        runner.check_data_dir(DATA_DIR.value)
    except ValueError as error:
        raise app.UsageError(str(error)) from error
    return dict(scale=SCALE.value, workdir=WORKDIR.value, sizes=sizes, seeds=seeds, num_steps=NUM_STEPS.value,
                data_dir=DATA_DIR.value, build=BUILD.value, workers=WORKERS.value, mode=MODE.value)


def run_setup(name: str, **arguments) -> dict:
    """`runner.run` of ``SETUPS[name]`` (``models`` and ``sizes`` in `arguments` replace the setup's)."""
    setup = SETUPS[name]
    models = tuple(arguments.pop("models", None) or setup.models)
    runner.parse_models(models)
    sizes = tuple(arguments.pop("sizes", None) or setup.sizes)
    return runner.run(
        name, setup.experiment, variants=[m for m in models if m in VARIANTS],
        baselines=[m for m in models if m not in VARIANTS], train_splits=setup.train_splits,
        test_splits=setup.test_splits, sizes=sizes, l_scales=setup.l_scales,
        l_scaled_models=setup.l_scaled_models, **arguments,
    )


def main(name: str, argv) -> dict:
    """Runs experiment `name` with the parsed flags; writes results.json, results.md and the figures."""
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    arguments = common_arguments()
    try:
        models = runner.parse_models(VARIANTS_FLAG.value, runner.MODELS) if VARIANTS_FLAG.value else None
    except ValueError as error:
        raise app.UsageError(str(error)) from error
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if name == "visualize":
            results = visualize.run(variants=models or visualize.DEFAULT_VARIANTS, **arguments)
        else:
            results = run_setup(name, models=models, **arguments)
    for message in dict.fromkeys(str(warning.message) for warning in caught):
        logging.warning("%s", message)
    table = tables.write(results, arguments["workdir"])
    if name != "visualize":
        figures.plot(results, arguments["workdir"])
    print(table.read_text())
    return results
