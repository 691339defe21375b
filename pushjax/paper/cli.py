"""Command-line flags shared by the experiment binaries under ``experiments/``, and their ``main``.

Importing this module defines the flags (absl's global ``FLAGS``); ``experiments/train.py`` shares them.
`spec_from_flags` is the one place where flags become an `ExperimentSpec`; each binary is
``main(argv) -> cli.main(<name>, argv)``, which runs the spec (`run_spec`: `pushjax.paper.runner.run`), writes its
tables and figures and ends with one line saying what it wrote where. A bad flag is an ``app.UsageError`` naming
the flag, raised before any dataset is built or model trained. ``--config.<field>=<value>`` replaces any field of the
training config (`pushjax.train.configs.OVERRIDABLE_FIELDS`, e.g. ``--config.learning_rate=3e-4``,
``--config.model.head_features=64,32``); the overrides are recorded in ``results.json``'s ``config``.
"""

from __future__ import annotations

import warnings
from absl import app, flags, logging

from pushjax.data import configs as data_configs
from pushjax.paper import figures, paths, reference, runner, spec as spec_lib, tables, visualize
from pushjax.sim import testbed
from pushjax.train import SWEEP_MODES, distributed, sweep_trainer
from pushjax.train import configs as train_configs

SCALE = flags.DEFINE_enum("scale", data_configs.DEFAULT_SCALE, data_configs.SCALES, "Dataset and training scale.")
WORKDIR = flags.DEFINE_string("workdir", None, "Output folder: checkpoints, results.json, results.md, figures.")
SIZES = flags.DEFINE_list("sizes", [], "Training-set sizes (default: the experiment's; larger ones are clipped).")
SEEDS = flags.DEFINE_list("seeds", ["0"], "Subset and initialisation seeds.")
NUM_STEPS = flags.DEFINE_integer("num_steps", None, "Override the scale's number of training steps.")
DATA_DIR = flags.DEFINE_string("data_dir", None, "TFDS data directory, must exist (default: TFDS's).")
BUILD = flags.DEFINE_bool("build", True, "Build the dataset when it is missing.")
WORKERS = flags.DEFINE_integer("workers", None, "Dataset build processes (default: the builder's).")
MODE = flags.DEFINE_enum("mode", None, SWEEP_MODES, "Sweep batching (default: sequential on CPU, else vmap).")
VARIANTS_FLAG = flags.DEFINE_list("variants", [], "Models to train and baselines (default: the experiment's).")
TESTBED = flags.DEFINE_enum("testbed", testbed.DEFAULT_PROFILE, list(testbed.PROFILES), testbed.FLAG_HELP)
MIN_TEST_SEQUENCES = flags.DEFINE_integer(
    "min_test_sequences", 0, "Evaluate on the test splits grown to at least this many push sequences, a test-only "
    "dataset that shares no sequence with the training and validation splits (0: the experiment's own test splits).")
COORDINATOR_ADDRESS = flags.DEFINE_string(
    "coordinator_address", None, "Several processes (hosts): host:port of process 0, which coordinates them.")
NUM_PROCESSES = flags.DEFINE_integer("num_processes", 1, "Processes (one per host) that train together.")
PROCESS_ID = flags.DEFINE_integer("process_id", 0, "This process's index in [0, --num_processes).")
CONFIG_OVERRIDES = {
    path: flags.DEFINE_string(
        f"config.{path}", None, f"Replace the training config's {path} ("
        f"{field_type.__name__ if field_type in (int, float, str) else 'comma-separated integers > 0'}; default: the "
        "scale's).")
    for path, field_type in train_configs.OVERRIDABLE_FIELDS.items()
}
"""``--config.<field>=<value>`` (Flax / big_vision style): any training-config field, recorded in results.json."""


def spec_from_flags(setup: spec_lib.Setup) -> spec_lib.ExperimentSpec:
    """The `ExperimentSpec` of `setup` with the parsed flags; a bad flag raises ``app.UsageError``.

    With ``--num_processes`` > 1 it first joins the processes (`pushjax.train.distributed.initialize`), before
    anything touches JAX.
    """
    if WORKDIR.value is None:
        raise app.UsageError("--workdir: expected a value (the flag is required)")
    try:
        paths.check_writable_folder(WORKDIR.value)
    except ValueError as error:
        raise app.UsageError(f"--workdir={WORKDIR.value}: {error}") from error
    try:
        distributed.initialize(COORDINATOR_ADDRESS.value, NUM_PROCESSES.value, PROCESS_ID.value)
        spec = spec_lib.make_spec(
            setup, SCALE.value, models=VARIANTS_FLAG.value, sizes=SIZES.value, seeds=SEEDS.value,
            num_steps=NUM_STEPS.value, data_dir=DATA_DIR.value, build=BUILD.value, workers=WORKERS.value,
            mode=MODE.value, testbed=TESTBED.value, min_test_sequences=MIN_TEST_SEQUENCES.value,
            config_overrides={path: flag.value for path, flag in CONFIG_OVERRIDES.items() if flag.value is not None},
        )
    except ValueError as error:
        raise app.UsageError(f"--{error}") from error
    if spec.mode == "sequential" and NUM_PROCESSES.value > 1:
        raise app.UsageError(f"--mode: sequential trains on one device; with --num_processes={NUM_PROCESSES.value} "
                             "pass --mode=vmap or --mode=unroll")
    return spec


def run_spec(spec: spec_lib.ExperimentSpec) -> runner.RunOutcome:
    """`runner.run` of `spec` in ``--workdir``, its warnings (e.g. clipped sizes) logged once each.

    A dataset the flags do not let the run build (`runner.DatasetUnavailableError`, which names the flag) and a work
    directory holding other models' checkpoints (`pushjax.train.sweep_trainer.WorkdirConflictError`) are
    ``app.UsageError``s.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            outcome = runner.run(spec, WORKDIR.value)
        except (runner.DatasetUnavailableError, sweep_trainer.WorkdirConflictError) as error:
            raise app.UsageError(f"--{error}") from error
    for message in dict.fromkeys(str(warning.message) for warning in caught):
        logging.warning("%s", message)
    return outcome


def main(name: str, argv) -> dict:
    """Runs experiment `name` (`spec_lib.SETUPS`) with the parsed flags; writes results, tables and figures."""
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    try:  # read before training, so that a bad file stops the run at once and not after hours
        reference.tables()
    except ValueError as error:
        raise app.UsageError(str(error)) from error
    outcome = run_spec(spec_from_flags(spec_lib.SETUPS[name]))
    if not distributed.is_writer():  # process 0 of several writes and prints
        return outcome.results
    table = tables.write(outcome.results, WORKDIR.value)
    if name == "visualize":
        pngs = [visualize.plot_outcome(outcome, WORKDIR.value)]
    else:
        pngs = figures.plot(outcome.results, WORKDIR.value)
    print(table.read_text())
    print(f"wrote results.json, {table.name} and {len(pngs)} figure{'s' * (len(pngs) != 1)} "
          f"({', '.join(png.name for png in pngs)}) to {WORKDIR.value}")
    return outcome.results
