r"""Build a push dataset (TFDS, array_record) for one experiment of the paper at one scale.

  python -m experiments.build_dataset --experiment=data_efficiency --scale=smoke --data_dir=DIR \
      [--seed=0] [--workers=N] [--raw_dir=DIR]

Experiments: data_efficiency, new_pushes, velocities, objects, viewpoint, repeated (``all`` builds each);
scales: smoke, cpu (default), paper; see ``pushjax.data.configs``. The push sequences are simulated into a raw
MIT-layout cache (``<data_dir>/push_effects_raw/seed<seed>``), examples are made on all cores and written to
``<data_dir>/push_effects/<experiment>_<scale>[_seed<seed>]/1.0.0``. ``--raw_dir`` reads the sequences from a
folder of your own instead (e.g. real MIT files), read-only: it must hold every planned file, else the build
stops, counting the missing files and naming the first; nothing is ever written into it. Re-running skips
finished datasets and cached sequences; the same flags give the same bytes. Read the result with

  tfds.data_source("push_effects/<experiment>_<scale>", data_dir=DIR)   # after `import pushjax.data.builder`
  pushjax.data.load("<experiment>", "<scale>", data_dir=DIR)
"""

import os

from absl import app, flags

import experiments
from pushjax.data import configs
from pushjax.data.builder import IncompleteRawDirError, build

_EXPERIMENT = flags.DEFINE_enum("experiment", "data_efficiency", [*configs.EXPERIMENTS, "all"], "Experiment.")
_SCALE = flags.DEFINE_enum("scale", configs.DEFAULT_SCALE, list(configs.SCALES), "Scale.")
_DATA_DIR = flags.DEFINE_string("data_dir", None, "TFDS data directory.", required=True)
_SEED = flags.DEFINE_integer("seed", 0, "Dataset seed.", lower_bound=0)
_WORKERS = flags.DEFINE_integer("workers", None, "Worker processes (default: all cores).", lower_bound=1)
_RAW_DIR = flags.DEFINE_string(
    "raw_dir", None, "Read-only MIT-layout folder holding every planned sequence file (e.g. real MIT files); "
    "the build stops if any is missing. Default: pushjax's own cache under --data_dir, simulated as needed.")
experiments.require_writable_folder("data_dir")
flags.register_validator("raw_dir", lambda folder: folder is None or os.path.isdir(folder),
                         "expected an existing folder of MIT-layout push files")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    names = configs.EXPERIMENTS if _EXPERIMENT.value == "all" else (_EXPERIMENT.value,)
    for experiment in names:
        try:
            builder = build(experiment, _SCALE.value, data_dir=_DATA_DIR.value, seed=_SEED.value,
                            workers=_WORKERS.value, raw_dir=_RAW_DIR.value)
        except IncompleteRawDirError as error:
            raise app.UsageError(f"--{error}") from None
        sizes = ", ".join(f"{name} {split.num_examples}" for name, split in builder.info.splits.items())
        print(f"{builder.builder_config.name}: {sizes} examples in {os.fspath(builder.data_dir)}")


if __name__ == "__main__":
    experiments.run(main)
