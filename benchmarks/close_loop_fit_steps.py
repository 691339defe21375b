"""Does the loop's fit converge? Fit losses of candidate effect sets against the number of Adam steps.

Fits each candidate (`pushjax.loop.fit.fit_effects`, the loop's optimiser) on the windows of the first ``--pushes``
push files under ``--data_dir`` (MIT layout; windows as `experiments.close_loop` cuts them by default, overlapping by
half, or ``--stride`` apart) at every step count of ``--steps``, and prints each fit's loss and, for the candidates with more than one
effect (and alone too with ``--show_alone``), the fitted parameters of ``--show``. A loss still falling between the default (300) and more steps means the
selection compares fits that have not converged; an effect whose parameters move towards zero as the others converge
is absorbing their misfit.

    python benchmarks/close_loop_fit_steps.py --data_dir=PUSHES [--pushes=40] [--steps=150,300,600,1200] \
        [--candidates=limit_surface;limit_surface,table_tilt;table_tilt] [--show=table_tilt] [--show_alone] [--stride=0.5]

PUSHES: e.g. a centre-loaded pressure like ``tests/loop``'s case ``pressure`` (rect1 on polyurethane, ideal testbed),
recorded with ``python -m experiments.record_pushes --out_dir=PUSHES --objects=rect1 --surfaces=pu --pushes=120 --seed=1 --effects=pressure_rim=-4.0 --declare_effects=false --testbed=ideal``.
"""

import tempfile
from pathlib import Path

from absl import app, flags

from pushjax.loop.fit import FitConfig, fit_effects
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes

_DATA_DIR = flags.DEFINE_string("data_dir", None, "Root of the push files (MIT layout).", required=True)
_PUSHES = flags.DEFINE_integer("pushes", 40, "Use the first this many push files (sorted by path).", lower_bound=1)
_STEPS = flags.DEFINE_list("steps", ["150", "300", "600", "1200"], "Adam step counts.")
_CANDIDATES = flags.DEFINE_string("candidates", "limit_surface;limit_surface,table_tilt;table_tilt",
                                  "Candidate effect sets, ';' between sets, ',' between effects.")
_SHOW = flags.DEFINE_string("show", "table_tilt", "Effect whose fitted parameters are printed.")
_SHOW_ALONE = flags.DEFINE_bool("show_alone", False, "Also print --show's parameters where it is fitted alone.")
_STRIDE = flags.DEFINE_float("stride", None, "Seconds between window starts (default: half the 0.5 s horizon, as "
                             "experiments.close_loop; tests/loop's STRIDE is 0.5).", lower_bound=0.0)


def main(argv):
    del argv
    paths = sorted(Path(_DATA_DIR.value).rglob("*.h5"))[:_PUSHES.value]
    if not paths:
        raise app.UsageError(f"--data_dir={_DATA_DIR.value}: no push files (*.h5) below it")
    candidates = [tuple(part.split(",")) for part in _CANDIDATES.value.split(";") if part]
    with tempfile.TemporaryDirectory() as folder:
        for path in paths:  # links to the chosen files, in their layout (the user's folder is not written)
            link = Path(folder) / path.relative_to(_DATA_DIR.value)
            link.parent.mkdir(parents=True, exist_ok=True)
            link.symlink_to(path.resolve())
        examples, _ = build_examples(iter_pushes(folder), stride=_STRIDE.value)
    print(f"{len(paths)} pushes, {len(examples)} windows")
    print("| steps | " + " | ".join("+".join(candidate) for candidate in candidates) + f" | {_SHOW.value} parameters |")
    print("|---:|" + "---:|" * len(candidates) + "---|")
    for steps in map(int, _STEPS.value):
        results = fit_effects(candidates, examples, FitConfig(steps=steps))
        shown = "; ".join(f"{name} {', '.join(f'{x:.4f}' for x in value.ravel())}" for result in results
                          if _SHOW.value in result.effects and (len(result.effects) > 1 or _SHOW_ALONE.value)
                          for name, value in result.params[_SHOW.value].items())
        print(f"| {steps} | " + " | ".join(f"{result.loss:.5f}" for result in results) + f" | {shown} |")


if __name__ == "__main__":
    app.run(main)
