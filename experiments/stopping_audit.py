r"""Replays a convergence-criterion run's models under the trend stopping rule (`pushjax.paper.stopping_audit`).

  python -m experiments.stopping_audit --run=results/data_efficiency_full --workdir=results/stopping_audit

Writes results.json and results.md to --workdir: for every recorded model, whether it was still improving when the
criterion stopped it, and whether the trend rule (`pushjax.train.stopping.RULE`) would have stopped it there.
"""

from absl import app, flags

import experiments
from pushjax.paper import cli, full_run, stopping_audit

# --workdir (where results.json and results.md go): pushjax.paper.cli's.
flags.adopt_module_key_flags(cli)
_RUN = flags.DEFINE_string("run", "results/data_efficiency_full", "The run whose models/ records are replayed.")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    if cli.WORKDIR.value is None:
        raise app.UsageError("--workdir is required")
    if not full_run.records(_RUN.value):
        raise app.UsageError(f"--run: no model records in {_RUN.value}/models")
    results = stopping_audit.audit(_RUN.value)
    stopping_audit.write(results, cli.WORKDIR.value)
    counts = results["counts"]
    print(f"{counts['stopped_while_improving']} of the {counts['criterion_met']} models the criterion stopped were "
          f"still improving; the trend rule would have kept training {counts['rule_would_not_stop']}; wrote "
          f"{cli.WORKDIR.value}/results.json and results.md")


if __name__ == "__main__":
    experiments.run(main)
