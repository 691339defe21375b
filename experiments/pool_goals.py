r"""Push-to-goal runs in several worlds as one comparison: every goal of every world paired across the models.

  python -m experiments.pool_goals --runs=DIR1,DIR2,DIR3 --workdir=OUT

Each DIR is the ``--workdir`` of an ``experiments.push_to_goal`` run in its own world (``--seed``: its goals and
testbed draws) with the same models and time limit; writes ``results.json``, ``results.md`` and ``trajectories.png``
to OUT (``pushjax.studies.push_to_goal.pool_worlds``: the goals of all worlds the unit of the comparisons, decided by
the project's rule). The runs' folders are only read.
"""

import json
from pathlib import Path

from absl import app, flags

import experiments
from pushjax.studies import push_to_goal

_RUNS = flags.DEFINE_list("runs", None, "Work folders of push_to_goal runs, one per world.", required=True)
_WORKDIR = flags.DEFINE_string("workdir", None, "Folder for the pooled results.json, results.md and figure.",
                               required=True)
experiments.require_writable_folder("workdir")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    runs = []
    for folder in _RUNS.value:
        path = Path(folder) / "results.json"
        try:
            runs.append(json.loads(path.read_text()))
        except (OSError, ValueError) as error:
            raise app.UsageError(f"--runs: {path}: expected a push_to_goal results.json ({error})") from None
    try:
        pooled = push_to_goal.pool_worlds(runs)
    except (KeyError, ValueError) as error:
        raise app.UsageError(f"--runs: {error}") from None
    paths = push_to_goal.write(pooled, _WORKDIR.value)
    print(paths[1].read_text())
    print(f"wrote {', '.join(str(path) for path in paths)}")


if __name__ == "__main__":
    experiments.run(main)
