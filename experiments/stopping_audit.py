r"""Replays a convergence-criterion run's models under the trend stopping rule (`pushjax.paper.stopping_audit`).

  python -m experiments.stopping_audit --workdir=results/data_efficiency_full --out_dir=results/stopping_audit

Writes results.json and results.md to --out_dir: for every recorded model, whether it was still improving when the
criterion stopped it, and whether the trend rule (`pushjax.train.stopping.RULE`) would have stopped it there.
"""

from absl import app, flags

import experiments
from pushjax.paper import full_run, stopping_audit

_WORKDIR = flags.DEFINE_string("workdir", "results/data_efficiency_full", "The run whose models/ records are replayed.")
_OUT_DIR = flags.DEFINE_string("out_dir", "results/stopping_audit", "Where results.json and results.md go.")
experiments.require_writable_folder("out_dir")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    if not full_run.records(_WORKDIR.value):
        raise app.UsageError(f"--workdir: no model records in {_WORKDIR.value}/models")
    results = stopping_audit.audit(_WORKDIR.value)
    stopping_audit.write(results, _OUT_DIR.value)
    counts = results["counts"]
    print(f"{counts['stopped_while_improving']} of the {counts['criterion_met']} models the criterion stopped were "
          f"still improving; the trend rule would have kept training {counts['rule_would_not_stop']}; wrote "
          f"{_OUT_DIR.value}/results.json and results.md")


if __name__ == "__main__":
    experiments.run(main)
