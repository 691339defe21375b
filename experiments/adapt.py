r"""Learn while pushing: the controller closes the loop on the pushes it makes, against plain Lynch and the oracle.

  python -m experiments.adapt --workdir=work/adapt [--scale=smoke|cpu] [--effect=tilt|com_offset|pusher_friction|
      friction_variability] [--worlds=3] [--blocks=4] [--per_block=6] [--first_block=6] [--max_time=30]
      [--seed=0] [--report_only]

A testbed table with an effect the controller's model does not declare (its magnitude drawn per world seed), and a
sequence of goals pushed four ways on the same goals: ``adaptive`` (the loop, ``pushjax.loop.close_loop``, runs on all
the controller's own recorded pushes after the first ``--first_block`` episodes and every ``--per_block`` after them,
and the next block plans with the model it selected), ``plain`` (Lynch throughout), ``oracle`` (the true effect and
magnitude) and ``filtered`` (Lynch whose pusher friction follows the EKF's within each episode); see
:mod:`pushjax.studies.adapt`. Writes ``results.json`` (rows per arm and block: success, time to goal, path length; what
the loop selected after each block; the comparison rules' verdicts), ``results.md`` and
``time_to_goal.png`` to ``--workdir``, the push files, the loop's reports and the finished episodes below it; a run
over the same ``--workdir`` reads back what an earlier (interrupted) run finished instead of simulating it again.
``--report_only`` writes ``results.md`` and the figure again from ``--workdir``'s ``results.json`` (a published run's
tables after a change of the report), simulating nothing.
"""

import json
import math
from pathlib import Path

from absl import app, flags

import experiments
from pushjax.studies import adapt, worlds

_WORKDIR = flags.DEFINE_string("workdir", None, "Folder for results.json, results.md, the figure, the pushes and the "
                               "loop's reports.", required=True)
_SCALE = flags.DEFINE_enum("scale", "cpu", list(adapt.SCALES), "Effects, worlds, blocks and settings (smoke: a test).")
_EFFECT = flags.DEFINE_string("effect", None, f"The world's undeclared effect, one of {','.join(worlds.EFFECTS)} "
                              "(default: the scale's).")
_WORLDS = flags.DEFINE_integer("worlds", None, "World seeds per effect (default: the scale's).")
_BLOCKS = flags.DEFINE_integer("blocks", None, "Blocks of episodes per world (default: the scale's).")
_PER_BLOCK = flags.DEFINE_integer("per_block", None, "Episodes per block; the loop runs after each block (default: "
                                  "the scale's).")
_FIRST_BLOCK = flags.DEFINE_integer("first_block", None, "Episodes in the first block, after which the loop first "
                                    "runs (default: the scale's; the loop needs 12).")
_MAX_TIME = flags.DEFINE_float("max_time", None, "Simulated seconds per goal (default: the scale's).")
_SEED = flags.DEFINE_integer("seed", None, "The first world seed (default: the scale's, 0).")
_REPORT_ONLY = flags.DEFINE_bool("report_only", False, "Write results.md and the figure again from --workdir's "
                                 "results.json; simulate nothing.")
experiments.require_writable_folder("workdir")


@flags.validator("effect", f"expected one of {','.join(worlds.EFFECTS)}")
def _check_effect(value):
    return value is None or value in worlds.EFFECTS


for _name in ("worlds", "blocks", "per_block", "first_block"):
    flags.register_validator(_name, lambda value: value is None or value >= 1, "expected a whole number >= 1")
flags.register_validator("seed", lambda value: value is None or value >= 0, "expected a whole number >= 0")
flags.register_validator("max_time", lambda value: value is None or (math.isfinite(value) and value >= 1),
                         "expected a finite number of seconds >= 1")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    try:
        config = adapt.make_config(_SCALE.value, effects=None if _EFFECT.value is None else (_EFFECT.value,),
                                   worlds=_WORLDS.value, blocks=_BLOCKS.value, per_block=_PER_BLOCK.value,
                                   first_block=_FIRST_BLOCK.value, max_time=_MAX_TIME.value, seed=_SEED.value)
    except ValueError as error:
        raise app.UsageError(f"--{' '.join(str(error).split())}") from None
    if _REPORT_ONLY.value:
        recorded = Path(_WORKDIR.value) / "results.json"
        if not recorded.is_file():
            raise app.UsageError(f"--report_only: no results.json in --workdir {_WORKDIR.value}")
        results = json.loads(recorded.read_text())
    else:
        results = adapt.run(config, _WORKDIR.value)
    paths = adapt.write(results, _WORKDIR.value, tables_only=_REPORT_ONLY.value)
    print(next(path for path in paths if path.suffix == ".md").read_text())
    print(f"wrote {', '.join(str(path) for path in paths)}")


if __name__ == "__main__":
    experiments.run(main)
