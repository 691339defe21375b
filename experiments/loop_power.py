r"""The loop's power and false discoveries on simulated data sets, each analysis archived in the repository.

  python -m experiments.loop_power --setup=fresh [--archive=results/loop_power] [--pushes_dir=work/loop_power]
      [--cases=clean,...] [--seeds=6] [--clean_seeds=20] [--cached_only]

Records each data set of the set-up (``pushjax.studies.loop_power``: two objects, one surface, two speeds, 100 pushes
per object on the ``ideal`` testbed with the case's effect undeclared) under ``--pushes_dir``, runs the loop on it and
archives its ``report.json``, ``details.json`` and ``analysis.json`` in ``--archive/<setup>/<case>/seed<k>/``; an
analysis already archived is not run again, so the run resumes where a stopped one ended. Then writes the set-up's
table and goal, built from the archive alone, to ``--archive/<setup>/results.md`` and ``results.json``.
``--cached_only`` runs nothing: it rebuilds the table from the archive (from a clone, without the pushes).

Data sets per case: the set-up's plan where it has one (``fresh``: 20 per clean support model, 6 per effect case),
else ``--clean_seeds`` and ``--seeds``; seeds 0, 1, ... taken round-robin over the cases, so a stopped run has every
case's first seeds.
"""

from absl import app, flags

import experiments
from pushjax.studies import loop_power

_SETUP = flags.DEFINE_enum("setup", "fresh", list(loop_power.SETUPS), "Objects, surface, speeds and cases.")
_ARCHIVE = flags.DEFINE_string("archive", "results/loop_power", "Where each analysis and the tables are archived.")
_PUSHES_DIR = flags.DEFINE_string("pushes_dir", "work/loop_power", "Where the data sets' pushes and the loop's full "
                                  "outputs are written (reused when present).")
_CASES = flags.DEFINE_list("cases", None, "Cases to analyse (default: the set-up's).")
_SEEDS = flags.DEFINE_integer("seeds", None, "Data sets per effect case (default: the set-up's plan, else 5).",
                              lower_bound=1)
_CLEAN_SEEDS = flags.DEFINE_integer("clean_seeds", None, "Data sets per clean case (default: the set-up's plan, "
                                    "else 10).", lower_bound=1)
_CACHED_ONLY = flags.DEFINE_bool("cached_only", False, "Analyse nothing: tabulate the archived analyses.")
experiments.require_writable_folder("archive")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    setup = _SETUP.value
    known = loop_power.SETUPS[setup].cases
    cases = list(known) if _CASES.value is None else _CASES.value
    unknown = sorted(set(cases) - set(known))
    if unknown or not cases:
        raise app.UsageError(f"--cases: expected some of {','.join(known)}, got {','.join(unknown) or 'none'}")
    if _CACHED_ONLY.value:
        results, table = loop_power.tabulate(_ARCHIVE.value, setup)
    else:
        counts = loop_power.planned_counts(setup, cases, _SEEDS.value, _CLEAN_SEEDS.value)
        results, table = loop_power.run(setup, _ARCHIVE.value, _PUSHES_DIR.value, counts)
    paths = loop_power.write(results, table, _ARCHIVE.value)
    print(table)
    print(f"wrote {', '.join(str(path) for path in paths)}")


if __name__ == "__main__":
    experiments.run(main)
