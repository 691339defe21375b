"""Have the loop's first-round fits converged? Each single effect's selection score after its fit and after one more.

Splits the windows of the pushes under ``--data_dir`` as `experiments.close_loop` does (seed ``--seed``, the pusher
friction from the force sensor), fits every library effect alone on each fold as the first round of forward selection
does (`pushjax.loop.select`) with ``--steps`` Adam steps, continues every fit by ``--warm_steps``, and prints each
effect's out-of-fold selection score (translation + rotation, % of zero) before and after the continuation, best
first. The first round's current model is the plain one, which has nothing to fit, so the selection's convergence
check (from the second round on) does not see these fits; an effect whose score still falls by more than
`pushjax.loop.select.CONVERGENCE_TOLERANCE` has not converged, and if it ranks below another only before the
continuation, the first round picked by the number of steps.

    python benchmarks/close_loop_first_round.py --data_dir=PUSHES [--steps=300] [--warm_steps=100] [--stride=0.5]

PUSHES: e.g. ``tests/loop``'s case ``pressure``, recorded as in benchmarks/close_loop_fit_steps.py's docstring.
"""

from pathlib import Path

from absl import app, flags

from pushjax.loop import LoopConfig, select
from pushjax.loop.fit import FitConfig, fit_effects
from pushjax.loop.pipeline import measured_split
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes

_DATA_DIR = flags.DEFINE_string("data_dir", None, "Root of the push files (MIT layout).", required=True)
_STEPS = flags.DEFINE_integer("steps", FitConfig.steps, "Adam steps of the first fit.", lower_bound=1)
_WARM_STEPS = flags.DEFINE_integer("warm_steps", FitConfig.warm_steps, "Adam steps of the continuation.",
                                   lower_bound=1)
_STRIDE = flags.DEFINE_float("stride", None, "Seconds between window starts (default: experiments.close_loop's; "
                             "tests/loop's STRIDE is 0.5).", lower_bound=0.0)
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the split (as experiments.close_loop's --seed).", lower_bound=0)


def main(argv):
    del argv
    if not Path(_DATA_DIR.value).is_dir():
        raise app.UsageError(f"--data_dir={_DATA_DIR.value}: not a directory")
    pushes = iter_pushes(_DATA_DIR.value)
    if not pushes.paths:
        raise app.UsageError(f"--data_dir={_DATA_DIR.value}: no push files (motion_surface=...h5) below it")
    examples, _ = build_examples(pushes, stride=_STRIDE.value)
    split, _, effects = measured_split(examples, LoopConfig(), _SEED.value)
    folds = select._Folds(split)
    settings = FitConfig(steps=_STEPS.value, warm_steps=_WARM_STEPS.value)
    sets = [(name,) for name in effects]
    first = folds.evaluate(sets, [fit_effects(sets, fit, settings) for fit in folds.fit])
    continued = folds.evaluate(sets, [fit_effects(sets, fit, settings, initial=[c.fits[k].params for c in first])
                                      for k, fit in enumerate(folds.fit)])
    print(f"{len(examples)} windows; {_STEPS.value} steps, then {_WARM_STEPS.value} more")
    print("| effect | score after the fit | after the continuation | change |")
    print("|---|---:|---:|---:|")
    for before, after in sorted(zip(first, continued), key=lambda pair: pair[0].score):
        print(f"| {before.effects[0]} | {before.score:.2f} | {after.score:.2f} | "
              f"{100 * (after.score - before.score) / before.score:+.2f} % |")


if __name__ == "__main__":
    app.run(main)
