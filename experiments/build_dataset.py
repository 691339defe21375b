r"""Build a push dataset (TFDS, array_record) for one experiment of the paper at one scale.

  python -m experiments.build_dataset --experiment=data_efficiency --scale=smoke --data_dir=DIR \
      [--testbed=realistic|ideal] [--seed=0] [--workers=N] [--raw_dir=DIR] [--min_test_sequences=N]
  python -m experiments.build_dataset ... --beam_runner=DirectRunner [--beam_options="--direct_num_workers=2"]

Experiments: data_efficiency, new_pushes, velocities, objects, viewpoint, repeated (``all`` builds each);
scales: smoke, cpu (default), paper; see ``pushjax.data.configs``. The push sequences are simulated with the
``--testbed`` profile (``pushjax.sim.testbed``: ``realistic`` by default, ``ideal`` the clean reference) into a raw
MIT-layout cache (``<data_dir>/push_effects_raw/<testbed>/seed<seed>``), examples are made on all cores and written
to ``<data_dir>/push_effects/<experiment>_<scale>[_ideal][_test<N>][_seed<seed>]/3.0.0``. ``--raw_dir`` reads the sequences
from a folder of your own instead (e.g. real MIT files), read-only: it must hold every planned file, else the build
stops, counting the missing files and naming the first; nothing is ever written into it. ``--beam_runner``
simulates, renders and writes with Apache Beam on that runner instead (``pip install 'pushjax[beam]'``), passing it
``--beam_options`` as its pipeline options; the records are those of the process pool. Re-running skips finished
datasets (the log says which it reused, with version and folder) and cached sequences; the same flags give the same
bytes. Read the result with

  tfds.data_source("push_effects/<experiment>_<scale>", data_dir=DIR)   # after `import pushjax.data.builder`
  pushjax.data.load("<experiment>", "<scale>", data_dir=DIR)              # testbed="ideal": the ideal profile's
"""

import contextlib
import io
import os
import shlex

import tensorflow_datasets as tfds
from absl import app, flags

import experiments
from pushjax.data import configs
from pushjax.data.builder import IncompleteRawDirError, build
from pushjax.mit.files import PushFileError

_EXPERIMENT = flags.DEFINE_enum("experiment", "data_efficiency", [*configs.EXPERIMENTS, "all"], "Experiment.")
_SCALE = flags.DEFINE_enum("scale", configs.DEFAULT_SCALE, list(configs.SCALES), "Scale.")
_DATA_DIR = flags.DEFINE_string("data_dir", None, "TFDS data directory.", required=True)
_SEED = flags.DEFINE_integer("seed", 0, "Dataset seed.", lower_bound=0)
_TESTBED = experiments.define_testbed_flag()
_MIN_TEST_SEQUENCES = flags.DEFINE_integer(
    "min_test_sequences", 0, "Build the experiment's test splits grown to at least this many push sequences, a "
    "test-only dataset <experiment>_<scale>_test<N> (0: the experiment's dataset).", lower_bound=0)
_WORKERS = flags.DEFINE_integer("workers", None, "Worker processes (default: all cores).", lower_bound=1)
_RAW_DIR = flags.DEFINE_string(
    "raw_dir", None, "Read-only MIT-layout folder holding every planned sequence file (e.g. real MIT files); "
    "the build stops if any is missing. Default: pushjax's own cache under --data_dir, simulated as needed.")
_BEAM_RUNNER = flags.DEFINE_string(
    "beam_runner", None, "Build with Apache Beam on this runner (e.g. DirectRunner, DataflowRunner, FlinkRunner, "
    "SparkRunner, or a runner class's dotted path; needs `pip install 'pushjax[beam]'`). Default: a process pool "
    "on this machine (--workers).")
_BEAM_OPTIONS = flags.DEFINE_string(
    "beam_options", None, "The runner's pipeline options as on a Beam command line, e.g. "
    "'--direct_num_workers=2 --direct_running_mode=multi_processing' (with --beam_runner).")
experiments.require_writable_folder("data_dir")
flags.register_validator("raw_dir", lambda folder: folder is None or os.path.isdir(folder),
                         "expected an existing folder of MIT-layout push files")


def _apache_beam():
    """The ``apache_beam`` module; a flag error when it is not installed."""
    try:
        return tfds.core.lazy_imports.apache_beam
    except ImportError:
        raise flags.ValidationError("needs apache-beam: pip install 'pushjax[beam]'") from None


def _check_beam_runner(name: str | None) -> bool:
    if name is None:
        return True
    known = _apache_beam().options.pipeline_options.StandardOptions.KNOWN_RUNNER_NAMES
    lowered = {runner.lower() for runner in known}
    if "." not in name and name.lower() not in lowered and f"{name.lower()}runner" not in lowered:
        raise flags.ValidationError(f"expected one of {', '.join(known)} or a runner class's dotted path")
    return True


def _pipeline_options(text: str | None):
    """Beam's ``PipelineOptions`` of a command line of pipeline options (``"--a=1 --b=2"``; None: the defaults).

    Raises:
      flags.ValidationError: one line naming a malformed, unknown or badly valued option.
    """
    try:
        arguments = shlex.split(text or "")
    except ValueError as error:
        raise flags.ValidationError(f"not a command line: {error}") from None
    options = _apache_beam().options.pipeline_options.PipelineOptions(arguments)
    errors = io.StringIO()
    try:
        with contextlib.redirect_stderr(errors):  # Beam's parser prints its usage before a bad value's error
            known = options.get_all_options()
    except SystemExit:
        raise flags.ValidationError(errors.getvalue().strip().splitlines()[-1].split("error: ", 1)[-1]) from None
    unknown = [argument for argument in arguments if not argument.startswith("--")] + [
        f"--{name}" for name in sorted(set(options.get_all_options(retain_unknown_options=True)) - set(known))]
    if unknown:
        raise flags.ValidationError(f"unknown pipeline options: {', '.join(unknown)}")
    return options


def _check_beam_options(text: str | None) -> bool:
    if text is not None:
        _pipeline_options(text)
    return True


flags.register_validator("beam_runner", _check_beam_runner)
flags.register_validator("beam_options", _check_beam_options)
flags.register_multi_flags_validator(
    ["beam_options", "beam_runner"],
    lambda values: values["beam_options"] is None or values["beam_runner"] is not None,
    "--beam_options: needs --beam_runner")
flags.register_multi_flags_validator(
    ["workers", "beam_runner"], lambda values: values["workers"] is None or values["beam_runner"] is None,
    "--workers: sets the process pool, which --beam_runner replaces (give the runner its workers in --beam_options)")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    names = configs.EXPERIMENTS if _EXPERIMENT.value == "all" else (_EXPERIMENT.value,)
    if _EXPERIMENT.value == "all" and _MIN_TEST_SEQUENCES.value:
        names = tuple(name for name in names if name != "repeated")  # one push, nothing to grow
    beam_options = None if _BEAM_OPTIONS.value is None else _pipeline_options(_BEAM_OPTIONS.value)
    for experiment in names:
        try:
            builder = build(experiment, _SCALE.value, data_dir=_DATA_DIR.value, seed=_SEED.value,
                            testbed=_TESTBED.value, workers=_WORKERS.value, raw_dir=_RAW_DIR.value,
                            beam_runner=_BEAM_RUNNER.value, beam_options=beam_options,
                            min_test_sequences=_MIN_TEST_SEQUENCES.value)
        except PushFileError:
            raise  # names the file (`experiments.run` prints it as a usage error)
        except (IncompleteRawDirError, ValueError) as error:
            raise app.UsageError(f"--{error}") from None
        sizes = ", ".join(f"{name} {split.num_examples}" for name, split in builder.info.splits.items())
        print(f"{builder.builder_config.name}: {sizes} examples in {os.fspath(builder.data_dir)}")


if __name__ == "__main__":
    experiments.run(main)
