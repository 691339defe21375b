"""A second look at the fresh set-up's variability cases: the spread between pushes by each random-effects estimator.

The power study (``pushjax.studies.loop_power``, set-up ``fresh``) archived the loop's ``report.json`` of every
variability data set, whose spread was DerSimonian-Laird's estimate (the loop before 648b20b). This run, stated after
that first look and apart from the study's goal, reads the same pushes again (recorded from the study's recipe, or
reused under ``--pushes_dir``), takes the loop's own split and force-sensor readings (``pushjax.loop.pipeline``'s
``measured_split`` with the default ``LoopConfig``, the data set's seed), and estimates the spread over the pool's
pushes by both estimators of ``pushjax.loop.metrics.TAU_ESTIMATORS``:

* check: DerSimonian-Laird's estimate equals the archived report's to 1e-9 (the same readings as the first look);
* criterion, the study's, unchanged: the relative sd within +-25 % of the draws' (``loop_power.drawn_spread``) on
  >= 90 % of each variability case's data sets.

    python benchmarks/loop_power_spread.py --pushes_dir=DIR --workdir=results/loop_power/fresh/spread_second_look

Writes ``results.json`` and ``results.md`` to ``--workdir``.
"""

import argparse
from pathlib import Path

from pushjax import outputs
from pushjax.loop import LoopConfig, metrics, variability
from pushjax.loop.pipeline import measured_split
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.sim.dataset import record_pushes
from pushjax.studies import loop_power

ARCHIVE = Path(__file__).resolve().parents[1] / "results" / "loop_power"
SETUP = "fresh"
CASES = ("variability_s", "variability_l")


def pool(pushes: Path, seed: int):
    """The loop's pool windows of the pushes (its split with the default ``LoopConfig`` and ``seed``)."""
    settings = LoopConfig()
    examples, _ = build_examples(iter_pushes(pushes), horizon=settings.horizon, stride=settings.stride,
                                 pusher_friction=settings.pusher_friction)
    return measured_split(examples, settings, seed)[0].pool


def look(pushes_dir: Path, case: str, seed: int) -> dict:
    """One variability data set: its drawn spread, the archived estimate and both estimators' on the same readings."""
    chosen = loop_power.SETUPS[SETUP]
    pushes = pushes_dir / SETUP / case / f"seed{seed}" / "pushes"
    record_pushes(pushes, list(chosen.objects), [chosen.surface], chosen.pushes_per_object,
                  loop_power.recording_settings(SETUP, case, seed), workers=1, progress=False)
    readings = variability.pusher_friction_readings(pool(pushes, seed))
    archived = loop_power.archived(loop_power.analysis_folder(ARCHIVE, SETUP, case, seed))
    first_look = archived["report"]["variability"]["pusher_friction"]["relative_sd"]
    drawn = loop_power.drawn_spread(SETUP, case, seed)
    row = {"case": case, "seed": seed, "drawn": drawn, "first_look": first_look}
    for name in metrics.TAU_ESTIMATORS:
        found = variability.spread(*readings, variability.PUSHER_FRICTION_SOURCE, estimator=name)
        row[name] = {"relative_sd": found.relative_sd, "interval": found.interval, "n_pushes": found.n_pushes,
                     "within": bool(abs(found.relative_sd - drawn) <= loop_power.SPREAD_TOLERANCE * drawn)}
    if abs(row["dersimonian_laird"]["relative_sd"] - first_look) > 1e-9:
        raise SystemExit(f"{case} seed {seed}: DerSimonian-Laird gives {row['dersimonian_laird']['relative_sd']} on "
                         f"these pushes, the archive {first_look}: not the first look's readings")
    return row


def markdown(rows: list[dict]) -> str:
    lines = ["| case | seed | drawn | archived (first look) | DerSimonian-Laird [95 %] | within | Paule-Mandel | within |",
             "|---|---:|---:|---:|---|---|---:|---|"]
    for row in rows:
        dl, pm = row["dersimonian_laird"], row["paule_mandel"]
        lines.append(f"| {row['case']} | {row['seed']} | {row['drawn']:.3f} | {row['first_look']:.3f} | "
                     f"{dl['relative_sd']:.3f} [{dl['interval'][0]:.3f}, {dl['interval'][1]:.3f}] | {dl['within']} | "
                     f"{pm['relative_sd']:.3f} | {pm['within']} |")
    lines.append("")
    for case in CASES:
        mine = [row for row in rows if row["case"] == case]
        counts = {name: sum(row[name]["within"] for row in mine) for name in metrics.TAU_ESTIMATORS}
        verdicts = {name: "met" if count >= loop_power.POWER_GOAL * len(mine) else "not met"
                    for name, count in counts.items()}
        lines.append(f"{case}: within +-25 % of the draws' spread on {counts['dersimonian_laird']} of {len(mine)} "
                     f"(DerSimonian-Laird, {verdicts['dersimonian_laird']}) and {counts['paule_mandel']} of {len(mine)} "
                     f"(Paule-Mandel, {verdicts['paule_mandel']}); the criterion asks for >= 90 %.")
    lines += ["", "A second look, stated after the study's first (its goal is judged on the archived reports alone)."]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pushes_dir", type=Path, required=True, help="where the study's pushes are (or go)")
    parser.add_argument("--workdir", type=Path, required=True, help="where results.json and results.md go")
    args = parser.parse_args()
    rows = [look(args.pushes_dir, case, seed) for case in CASES for seed in range(loop_power.PLANS[SETUP][case])]
    table = markdown(rows)
    outputs.write_report(args.workdir, {"rows": rows}, table)
    print(table)


if __name__ == "__main__":
    main()
