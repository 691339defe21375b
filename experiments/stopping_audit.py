r"""Replays a run's models under the trend stopping rule (`pushjax.paper.stopping_audit`).

  python -m experiments.stopping_audit --run=results/data_efficiency_full --workdir=results/stopping_audit
  python -m experiments.stopping_audit --run=results/data_efficiency_long --workdir=results/data_efficiency_long/continuation

Writes results.json and results.md to --workdir: for every recorded model, whether it was still improving when the
criterion stopped it, and whether the trend rule (`pushjax.train.stopping.RULE`) would have stopped it there; for
the models of fixed budgets (the paper's 75 000 steps), per variant and size, whether the continuation rule
(`pushjax.train.stopping.long_run_continues`) sends its seeds on to twice their steps.
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
    if counts["criterion_met"] or not results["continuations"]:
        print(f"{counts['stopped_while_improving']} of the {counts['criterion_met']} models the criterion stopped "
              f"were still improving; the trend rule would have kept training {counts['rule_would_not_stop']}")
    print(f"wrote {cli.WORKDIR.value}/results.json and results.md")
    for row in results["continuations"]:
        print(f"{row['variant']} at {row['size']} (seeds {', '.join(map(str, row['seeds']))}, "
              f"{max(row['steps'])} steps): " + (f"continues to {row['next_steps']} steps" if row["continues"] else
                                                 "stops (the rule stops every seed)"))


if __name__ == "__main__":
    experiments.run(main)
