"""Push-to-push variability recovered by the loop's force sensor: the pusher friction's spread between pushes.

Records rect1 on polyurethane at 20 mm/s on the realistic testbed with the profile's per-push pusher friction spread
``pusher_friction_sigma`` set to each ``--sigmas`` value (0: constant friction), and on the ideal testbed, then
estimates the spread from the force sensor's per-push readings (:func:`pushjax.loop.variability.measure`) and sets it
beside the truth: the profile's relative sd ``sqrt(exp(sigma^2) - 1)`` and the sample of the draws the pushes were
recorded with. Writes ``results.json`` and ``results.md`` to ``--workdir``.

    python benchmarks/loop_variability.py --data_dir work/loop_variability --workdir results/loop_variability

The pushes are recorded under ``--data_dir`` (reused when present with the same settings).
"""

import argparse
import math
from pathlib import Path

from pushjax import outputs
from pushjax.loop import variability
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.sim.dataset import RecordingConfig, drawn_relative_sd, plan_pushes, record_pushes
from pushjax.sim.testbed import IDEAL, REALISTIC

GOAL = 0.25
"""The recovered relative sd must lie within this share of the simulated one (of the draws)."""


def measure(folder: Path, testbed, pushes: int, seed: int) -> dict:
    """Records (or reuses) `pushes` pushes in `folder` on `testbed`; the recovered spread beside the drawn one."""
    settings = RecordingConfig(seed=seed, velocities=(20.0,), testbed=testbed)
    record_pushes(folder, ["rect1"], ["pu"], pushes, settings, workers=1, progress=True)
    examples, _ = build_examples(list(iter_pushes(folder)))
    found = variability.measure(examples)["pusher_friction"]
    drawn = drawn_relative_sd(plan_pushes(folder, ["rect1"], ["pu"], pushes, settings))
    sigma = testbed.pusher_friction_sigma
    return {"testbed": "ideal" if testbed.ideal else "realistic", "sigma": sigma,
            "profile_relative_sd": math.sqrt(math.exp(sigma ** 2) - 1), "drawn_relative_sd": drawn,
            "recovered": found.as_dict(),
            "within_goal": bool(abs(found.relative_sd - drawn) <= GOAL * drawn) if drawn > 0
            else bool(found.interval[0] == 0.0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data_dir", type=Path, required=True, help="where the pushes are recorded (or reused)")
    parser.add_argument("--workdir", type=Path, required=True, help="where results.json and results.md go")
    parser.add_argument("--sigmas", default="0,0.2,0.4", help="the profile's pusher_friction_sigma values")
    parser.add_argument("--pushes", type=int, default=120, help="pushes per data set")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rows = [measure(args.data_dir / f"realistic_sigma{sigma}",
                    REALISTIC.with_overrides(f"pusher_friction_sigma={sigma}"), args.pushes, args.seed)
            for sigma in map(float, args.sigmas.split(","))]
    rows.append(measure(args.data_dir / "ideal", IDEAL, args.pushes, args.seed))
    lines = ["| testbed | sigma | relative sd: profile | drawn | recovered [95 %] | pushes | within ±25 % (or reaches 0) |",
             "|---|---:|---:|---:|---|---:|---|"]
    for row in rows:
        found = row["recovered"]
        lines.append(f"| {row['testbed']} | {row['sigma']:g} | {row['profile_relative_sd']:.3f} | "
                     f"{row['drawn_relative_sd']:.3f} | {found['relative_sd']:.3f} [{found['interval'][0]:.3f}, "
                     f"{found['interval'][1]:.3f}] | {found['n_pushes']} | {row['within_goal']} |")
    table = "\n".join(lines) + "\n"
    outputs.write_report(args.workdir, {"object": "rect1", "surface": "pu", "velocity_mm_s": 20.0, "seed": args.seed,
                                        "pushes": args.pushes, "goal": GOAL, "rows": rows}, table)
    print(table)


if __name__ == "__main__":
    main()
