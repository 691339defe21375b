r"""Prediction over time: zero, physics (one long step and chained 0.5 s steps), hybrid, error and neural rolled out
along whole test pushes, their error at 0.5, 1, 2, 4 s and at the push's end (issue 31).

  python -m experiments.rollouts [--scale=smoke|cpu|paper] [--seeds=0,1,2] [--test_splits=test_20,test_50]
      --workdir=DIR

Trains the models on the velocities dataset's 20 mm/s training split (the shared runner: resumable, with the
one-step rows of every experiment), rolls them out on the whole pushes of the test velocities
(`pushjax.paper.rollouts`) and writes results.json, results.md and rollouts.png to the work directory (all flags:
--help).
"""

from absl import app, flags

import experiments
from pushjax.paper import cli, rollouts

flags.adopt_module_key_flags(cli)
_TEST_SPLITS = flags.DEFINE_list("test_splits", [], "Test velocities to roll out on, e.g. test_20,test_50 "
                                 "(default: every test split of the velocities dataset).")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {argv[1:]}")
    try:
        setup = rollouts.setup(_TEST_SPLITS.value)
    except ValueError as error:
        raise app.UsageError(f"--{error}") from error
    spec = cli.spec_from_flags(setup)
    try:
        rollouts.check_models(spec)
    except ValueError as error:
        raise app.UsageError(f"--{error}") from error
    paths = rollouts.write(rollouts.evaluate(cli.run_spec(spec)), cli.WORKDIR.value)
    print(paths[1].read_text())
    print(f"wrote {', '.join(str(path) for path in paths)}")


if __name__ == "__main__":
    experiments.run(main)
