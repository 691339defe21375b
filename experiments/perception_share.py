r"""The perception's share of hybrid's error: each recorded hybrid against Lynch on the true state, paired by sequence.

  python -m experiments.perception_share --data_dir=work/data --workdir=results/perception_share \
      --runs=criterion:results/data_efficiency_full,long:results/data_efficiency_long [--train_size=190080] \
      [--scale=cpu_full]

Reads the ``data_efficiency`` test split (built when missing is not done here: build it with experiments.build_dataset
or the run), the hybrid records of each run at --train_size, and writes results.json and results.md to --workdir
(`pushjax.paper.perception_share`).
"""

from absl import app, flags

import experiments
from pushjax.paper import cli, full_run, perception_share, runner

# --workdir (where results.json and results.md go), --data_dir, --scale: pushjax.paper.cli's.
flags.adopt_module_key_flags(cli)
_RUNS = flags.DEFINE_list("runs", ["criterion:results/data_efficiency_full"],
                          "label:workdir of each run whose hybrids are read.")
_TRAIN_SIZE = flags.DEFINE_integer("train_size", full_run.FULL, "The training size whose hybrids are read.",
                                   lower_bound=1)


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    if cli.WORKDIR.value is None:
        raise app.UsageError("--workdir is required")
    scale = cli.SCALE.value if flags.FLAGS["scale"].present else full_run.SCALE
    runs = {}
    for item in _RUNS.value:
        label, _, workdir = item.partition(":")
        if not label or not workdir:
            raise app.UsageError(f"--runs: expected label:workdir, got {item!r}")
        if not full_run.records(workdir):
            raise app.UsageError(f"--runs: no model records in {workdir}/models")
        runs[label] = workdir
    try:
        results = perception_share.run(cli.DATA_DIR.value, runs, cli.WORKDIR.value, scale, _TRAIN_SIZE.value)
    except (runner.DatasetUnavailableError, ValueError) as error:
        raise app.UsageError(f"--data_dir: {error}") from None
    print(f"wrote {cli.WORKDIR.value}/results.json and results.md ({len(results['rows'])} rows)")


if __name__ == "__main__":
    experiments.run(main)
