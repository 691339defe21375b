r"""Close the loop on measured pushes: residual → the missing effect → refit → test-split error before and after.

  python -m experiments.close_loop --data_dir=DIR --workdir=OUT [--horizon=0.5] [--seed=0] \
      [--heldout_fraction=0.25] [--min_gain=0.05] [--min_strength=0.1] [--steps=300] [--effects=a,b,...]

DIR holds pushes in the raw MIT layout (``<surface>/<object>/motion_surface=...h5``: real MIT files or the
testbed's, ``python -m experiments.record_pushes``); only the streams and the file-name fields are used.
Writes ``OUT/report.json``, ``OUT/details.json``, ``OUT/model.json`` (the selected model, which
``experiments.push_to_goal --models=loop --loop_model=OUT/model.json`` plans with), ``OUT/report.md`` and
``OUT/figures/*.png``; see
:mod:`pushjax.loop`. Effects are chosen on fit and select push sequences and measured on a test split of
``--heldout_fraction`` of them. With too few push sequences to select on it stops with one line naming how
many it found and how many it needs.
"""

import dataclasses
import sys

from absl import app, flags

import experiments
from pushjax.loop import LoopConfig, close_loop
from pushjax.loop.fit import FitConfig
from pushjax.physics.effects import EFFECT_NAMES

_DATA_DIR = flags.DEFINE_string("data_dir", None, "Root of the pushes (raw MIT layout).", required=True)
_WORKDIR = flags.DEFINE_string("workdir", None, "Output directory.", required=True)
_HORIZON = flags.DEFINE_float("horizon", 0.5, "Prediction window in s.", lower_bound=0.0)
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the split, bootstraps and error term.", lower_bound=0)
_HELDOUT = flags.DEFINE_float("heldout_fraction", LoopConfig.test_fraction,
                              "Share of push sequences in the untouched test split.")
_MIN_GAIN = flags.DEFINE_float("min_gain", LoopConfig.min_gain,
                               "Share of the select-split error above the noise floor that an effect must remove, on "
                               "top of being beyond noise.")
_MIN_STRENGTH = flags.DEFINE_float("min_strength", LoopConfig.min_strength,
                                   "Share of the error a variable's correction must remove to count as structure.")
_STEPS = flags.DEFINE_integer("steps", FitConfig.steps, "Adam steps per effect fit.", lower_bound=1)
_EFFECTS = flags.DEFINE_list("effects", list(EFFECT_NAMES), "Candidate library effects (default: all).")
experiments.require_writable_folder("workdir")
_FLAG_OF_FIELD = {"test_fraction": "heldout_fraction", "fit": "steps"}
"""The flag of a ``LoopConfig`` field whose name differs from it."""


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    try:
        settings = LoopConfig(horizon=_HORIZON.value, test_fraction=_HELDOUT.value, min_gain=_MIN_GAIN.value,
                              min_strength=_MIN_STRENGTH.value, effects=tuple(_EFFECTS.value),
                              fit=dataclasses.replace(FitConfig(), steps=_STEPS.value))
    except ValueError as error:
        raise experiments.config_error(error, _FLAG_OF_FIELD) from None
    try:
        result = close_loop(_DATA_DIR.value, _WORKDIR.value, settings, seed=_SEED.value)
    except ValueError as error:
        message = str(error)
        if message.startswith("data_dir"):
            message = "--" + message
        raise app.UsageError(message) from None
    report = result.report.as_dict()
    if not all(round_.converged for round_ in result.details.rounds):
        print(f"warning: the fits had not converged at --steps={_STEPS.value}: selection stopped early "
              f"(report.md, \"Forward selection\"); rerun with more --steps", file=sys.stderr)
    print(summary(report, _WORKDIR.value))


def summary(report: dict, workdir: str) -> str:
    """A few lines of ``report.json`` (its content as :meth:`pushjax.loop.report.LoopReport.as_dict` gives it)."""

    def errors(scores: dict) -> str:
        return f"{scores['trans_percent']:.1f} / {scores['rot_percent']:.1f}"

    remaining = [entry["variable"] for entry in report["remaining"]["variables"]]
    return "\n".join([
        f"pushes: {', '.join(f'{role} {count}' for role, count in report['n_pushes'].items())}; selected: "
        f"{', '.join(report['selected']) or 'nothing (plain Lynch)'}",
        f"test error, % of zero (translation / rotation): plain Lynch {errors(report['baseline'])}, selected "
        f"{errors(report['after'])}, with the learned error term {errors(report['fallback'])}; noise floor "
        f"{errors(report['noise_floor'])}",
        f"explained: {'yes' if report['explained'] else 'no'} ({errors(report['remaining']['above_floor'])} points "
        f"above the floor){'; the residual still depends on ' + ', '.join(remaining) if remaining else ''}",
        f"wrote report.json, details.json, model.json, report.md and figures/ to {workdir}",
    ])


if __name__ == "__main__":
    experiments.run(main)
