r"""Build a push dataset (TFDS, array_record) for one experiment of the paper at one scale.

  python -m experiments.build_dataset --experiment=data_efficiency --scale=smoke --data_dir=DIR \
      [--seed=0] [--workers=N] [--raw_dir=DIR]

Experiments: data_efficiency, new_pushes, velocities, objects, viewpoint, repeated (``all`` builds each);
scales: smoke, cpu (default), paper; see ``pushjax.data.configs``. The push sequences are simulated into a raw
MIT-layout cache (``<data_dir>/push_effects_raw/seed<seed>`` unless ``--raw_dir``), examples are made on all
cores and written to ``<data_dir>/push_effects/<experiment>_<scale>[_seed<seed>]/1.0.0``. Re-running skips
finished datasets and cached sequences; the same flags give the same bytes. Read the result with

  tfds.data_source("push_effects/<experiment>_<scale>", data_dir=DIR)   # after `import pushjax.data.builder`
  pushjax.data.load("<experiment>", "<scale>", data_dir=DIR)
"""

import os

from absl import app, flags

from pushjax.data import configs

_EXPERIMENT = flags.DEFINE_enum("experiment", "data_efficiency", [*configs.EXPERIMENTS, "all"], "Experiment.")
_SCALE = flags.DEFINE_enum("scale", configs.DEFAULT_SCALE, list(configs.SCALES), "Scale.")
_DATA_DIR = flags.DEFINE_string("data_dir", None, "TFDS data directory.", required=True)
_SEED = flags.DEFINE_integer("seed", 0, "Dataset seed.", lower_bound=0)
_WORKERS = flags.DEFINE_integer("workers", None, "Worker processes (default: all cores).", lower_bound=1)
_RAW_DIR = flags.DEFINE_string("raw_dir", None, "Raw sequence cache (default: under --data_dir).")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    from pushjax.data.builder import build

    experiments = configs.EXPERIMENTS if _EXPERIMENT.value == "all" else (_EXPERIMENT.value,)
    for experiment in experiments:
        builder = build(experiment, _SCALE.value, data_dir=_DATA_DIR.value, seed=_SEED.value,
                        workers=_WORKERS.value, raw_dir=_RAW_DIR.value)
        sizes = ", ".join(f"{name} {split.num_examples}" for name, split in builder.info.splits.items())
        print(f"{builder.builder_config.name}: {sizes} examples in {os.fspath(builder.data_dir)}")


if __name__ == "__main__":
    app.run(main)
