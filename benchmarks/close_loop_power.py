"""Power and false discoveries of the loop on pushes from a set-up it was not developed against (by hand; not a
timed test).

The loop is developed on rect1 on polyurethane at 20 mm/s (``tests/loop``) and was tuned on ellip2 and tri1 on abs
(an earlier version of this benchmark). Two set-ups (``--setup``), 100 pushes per object (200 per data set), the
``ideal`` testbed, every effect undeclared:

  * ``development``: hex and butter (a non-convex outline) on plywood at 20 and 50 mm/s. ``limit_surface``'s share of
    the load on the hull's corners (``feet``) was added after this set-up's stiff feet were named ``friction_ratio``
    (commit 5890f85), so it no longer measures anything the loop was not developed against;
  * ``held_out``: tri2 and ellip3 on delrin at 15 and 40 mm/s, and besides the grid and the stiff feet a support model
    the library does not have, a ring of 16 supports along the outline (``support="ring"``, a dished base on its edge).

Support models: the grid (a pressure distributed over the footprint), ``clean_feet``: a few stiff feet at the convex
hull's corners (``pushjax.sim.scene.support_points(obj, "hull")``), ``clean_ring``: the ring (held-out only). Each data
set is analysed as the loop analyses it: ``pushjax.loop.pipeline.decide`` with the default settings (the force
sensor's pusher friction, Holm, the floor above the noise floor, the mechanism check); the test split is drawn and left
alone.

Criteria, fixed before measuring (issue 29, part 6):
  * the real differences: ``limit_surface`` and ``inertia`` are differences between any simulator and Lynch's model
    (the exact limit surface, the plate's momentum), so selecting them is never a false discovery;
  * false discovery: a clean data set (``clean``, ``clean_feet``) on which anything else is selected; the rate is
    reported with its one-sided 95 % Clopper-Pearson upper bound;
  * power, per case: the share of data sets on which the case's physics is found (:func:`found`): the first
    selected effect other than the real differences is a right one (a moved centre of mass: ``cof_offset`` or
    ``pressure_gradient``; a tilted table: ``table_tilt``); a centre- or rim-loaded pressure: ``limit_surface``
    selected with its refitted support pressure moved the injected way: its mean squared radius
    (:func:`outwardness`, ``rim`` and ``feet`` together, averaged over the set-up's objects) above the uniform
    pressure's for a rim-loaded case, below it for a centre-loaded one; the pusher's friction: the force sensor reads it within
    ``SENSOR_TOLERANCE`` (``pusher_friction`` is then no candidate of the selection);
  * added error: the plain model's error on the case over that on ``clean`` data, minus 1;
  * goal: power >= 90 % for every case whose added error is >= 20 %, and false discoveries <= 5 %.

    python benchmarks/close_loop_power.py [--setup held_out] [--data_dir work/bench/close_loop_power_v3/<setup>]
        [--seeds 5] [--clean_seeds 10] [--cases clean,...] [--first_seed 0]

Resumable: recorded pushes are reused, and each analysis is stored in ``<data_dir>/outcomes/<case>_seed<k>.json``
and not repeated. ``--cached_only`` prints the table of the analyses stored so far (a run in progress) and judges the
goal on them only.
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy import stats

import jax.numpy as jnp

from pushjax.geometry import get_object, support
from pushjax.loop import fit as fit_lib
from pushjax.loop import metrics
from pushjax.loop.pipeline import LoopConfig, decide
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.physics.effects import support_pressure
from pushjax.sim.dataset import RecordingConfig, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import IDEAL

CASES = {  # name: (support, testbed effects, start poses)
    "clean": ("grid", "", "fixed"),
    "clean_feet": ("hull", "", "fixed"),
    "clean_ring": ("ring", "", "fixed"),
    "com_offset_s": ("grid", "com_offset=0.004,-0.003", "fixed"),
    "com_offset_l": ("grid", "com_offset=0.008,-0.005", "fixed"),
    "pusher_friction_s": ("grid", "pusher_friction=0.4", "fixed"),
    "pusher_friction_l": ("grid", "pusher_friction=0.6", "fixed"),
    "table_tilt_s": ("grid", "table_tilt_deg=3;table_tilt_azimuth_deg=60", "fixed"),
    "table_tilt_l": ("grid", "table_tilt_deg=5;table_tilt_azimuth_deg=60", "fixed"),
    "pressure_centre": ("grid", "pressure_rim=-3", "fixed"),
    "pressure_rim": ("grid", "pressure_rim=3", "fixed"),
    "clean_scattered": ("grid", "", "scattered"),
    "com_offset_scattered": ("grid", "com_offset=0.004,-0.003", "scattered"),
}
CLEAN = ("clean", "clean_feet", "clean_ring", "clean_scattered")
SUPPLEMENTARY = ("clean_scattered", "com_offset_scattered")
"""Cases added after the goal was set, to ask whether the small centre-of-mass offset, confounded with a table-fixed
friction field from the MIT protocol's one start pose, is found from scattered start poses
(``pushjax.sim.dataset.START_POSES``); reported beside the goal, not counted in it."""
REAL_DIFFERENCES = {"limit_surface", "inertia"}
RIGHT_FIRST = {"com_offset": {"cof_offset", "pressure_gradient"}, "table_tilt": {"table_tilt"}}
SENSOR_TOLERANCE = 0.1
"""Largest relative error of the force sensor's pusher friction that counts as found."""
SETUPS = {  # name: (objects, surfaces, velocities in mm/s, cases)
    "development": (["hex", "butter"], ["plywood"], (20.0, 50.0),
                    [case for case in CASES if case != "clean_ring" and case not in SUPPLEMENTARY]),
    "held_out": (["tri2", "ellip3"], ["delrin"], (15.0, 40.0), list(CASES)),
}
GOAL_CASES = {  # the cases the goal is judged on
    setup: [case for case in cases if case not in SUPPLEMENTARY] for setup, (_, _, _, cases) in SETUPS.items()
}
PUSHES_PER_OBJECT = 100
POWER_GOAL, FALSE_DISCOVERY_GOAL, ADDED_ERROR_FOR_GOAL = 0.9, 0.05, 0.2


def analyse(data_dir: Path, setup: str, case: str, seed: int, cached_only: bool = False) -> dict | None:
    """Records (or reuses) one data set and runs the loop's decision on it; the outcome is cached as JSON.
    With ``cached_only``, the cached outcome or None."""
    path = data_dir / "outcomes" / f"{case}_seed{seed}.json"
    if path.exists():
        return json.loads(path.read_text())
    if cached_only:
        return None
    support, effects, start_poses = CASES[case]
    pushes = data_dir / case / f"seed{seed}"
    objects, surfaces, velocities, _ = SETUPS[setup]
    settings = RecordingConfig(seed=seed, velocities=velocities, effects=Effects.parse(effects),
                               declare_effects=False, support=support, testbed=IDEAL, start_poses=start_poses)
    record_pushes(pushes, objects, surfaces, PUSHES_PER_OBJECT, settings, workers=1, progress=False)
    start = time.perf_counter()
    examples = build_examples(iter_pushes(pushes))[0]
    plain = metrics.window_errors(fit_lib.predict([None], examples)[0], examples.target, examples.sequence)
    decision = decide(examples, LoopConfig(), seed)
    model = decision.selection.model
    outcome = {"selected": decision.selection.selected,
               "alternatives": decision.selection.alternatives,
               "params": model.physical if model is not None else {},
               "force_sensor": decision.force.as_dict(),
               "plain_score": metrics.combined(metrics.summarize(plain)),
               "seconds": time.perf_counter() - start}
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(outcome, indent=1))
    return outcome


def false_discoveries(outcome: dict) -> list[str]:
    return [name for name in outcome["selected"] if name not in REAL_DIFFERENCES]


def outwardness(limit_surface: dict, objects: list[str]) -> float:
    """The fitted support pressure's mean squared radius over the uniform pressure's, averaged over ``objects``
    (``limit_surface``: its reported values {"rim": {"value": ...}, "feet": {"value": ...}})."""
    params = {name: jnp.asarray(limit_surface[name]["value"]) for name in ("rim", "feet")}
    ratios = []
    for name in objects:
        points, areas, loads, _ = support(get_object(name))
        pressure = np.asarray(support_pressure(params, *map(jnp.asarray, (points, areas, loads))))
        square = np.sum(points ** 2, axis=1)
        ratios.append(pressure @ square / (areas @ square / areas.sum()))
    return float(np.mean(ratios))


def found(setup: str, case: str, outcome: dict) -> bool:
    """Whether the loop found the case's physics (module docstring)."""
    family = case.rsplit("_", 1)[0]
    if family == "pusher_friction":
        true_mu = Effects.parse(CASES[case][1]).pusher_friction
        reading = outcome["force_sensor"]["value"]
        return reading is not None and abs(reading / true_mu - 1) <= SENSOR_TOLERANCE
    if family == "pressure":
        fitted = outcome["params"].get("limit_surface")
        injected = Effects.parse(CASES[case][1]).pressure_rim
        return fitted is not None and np.sign(outwardness(fitted, SETUPS[setup][0]) - 1) == np.sign(injected)
    others = false_discoveries(outcome)
    return bool(others) and others[0] in RIGHT_FIRST[family]


def _listing(outcome: dict) -> str:
    """The selected effects, and in brackets those the data could not tell a selected one from (analyses stored
    before the loop reported them have no brackets)."""
    rivals = "; ".join(f"{name} or {' or '.join(others)}" for name, others in outcome.get("alternatives", {}).items())
    return ("+".join(outcome["selected"]) or "-") + (f" (not decided: {rivals})" if rivals else "")


def upper_bound(count: int, total: int, level: float = 0.95) -> float:
    """One-sided Clopper-Pearson upper bound of a rate."""
    return 1.0 if count == total else float(stats.beta.ppf(level, count + 1, total - count))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--setup", default="held_out", choices=list(SETUPS), help="objects, surface and speeds")
    parser.add_argument("--data_dir", type=Path, default=None,
                        help="where pushes and analyses are kept (default: work/bench/close_loop_power_v3/<setup>)")
    parser.add_argument("--seeds", type=int, default=5, help="data sets per effect case")
    parser.add_argument("--clean_seeds", type=int, default=10, help="data sets per clean case")
    parser.add_argument("--first_seed", type=int, default=0)
    parser.add_argument("--cases", default=None, help="comma-separated cases to analyse (default: the set-up's)")
    parser.add_argument("--cached_only", action="store_true", help="tabulate the stored analyses, run none")
    args = parser.parse_args()
    if args.seeds < 1 or args.clean_seeds < 1 or args.first_seed < 0:
        parser.error(f"--seeds, --clean_seeds, --first_seed: expected >= 1, >= 1, >= 0, got {args.seeds}, "
                     f"{args.clean_seeds}, {args.first_seed}")
    setup_cases = SETUPS[args.setup][3]
    cases = setup_cases if args.cases is None else args.cases.split(",")
    if unknown := sorted(set(cases) - set(setup_cases)):
        parser.error(f"--cases: unknown {', '.join(unknown)}; expected some of {', '.join(setup_cases)}")
    data_dir = args.data_dir or Path("work/bench/close_loop_power_v3") / args.setup
    start = time.perf_counter()
    outcomes = {}
    for case in sorted(cases, key=lambda name: name not in CLEAN):
        count = args.clean_seeds if case in CLEAN else args.seeds
        outcomes[case] = []
        for seed in range(args.first_seed, args.first_seed + count):
            outcome = analyse(data_dir, args.setup, case, seed, args.cached_only)
            if outcome is None:
                continue
            outcomes[case].append(outcome)
            print(f"{case} seed {seed}: {outcome['selected']} force {outcome['force_sensor']['value']} "
                  f"params {outcome['params']} ({outcome['seconds']:.0f} s; {time.perf_counter() - start:.0f} s)",
                  flush=True)
    cases = [case for case in cases if outcomes[case]]
    if "clean" not in cases:
        print("no clean data set analysed (the added error of every case is measured against it): no table")
        return
    clean = np.mean([outcome["plain_score"] for outcome in outcomes["clean"]])
    print("\n| case | support | testbed effect | start poses | plain model sum % | added error | data sets | found | "
          "anything beyond limit_surface, inertia | selections |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|---|")
    met, wrong, clean_total = True, 0, 0
    for case in cases:
        support, effects, start_poses = CASES[case]
        results = outcomes[case]
        added = np.mean([outcome["plain_score"] for outcome in results]) / clean - 1
        beyond = np.mean([bool(false_discoveries(outcome)) for outcome in results])
        listing = "; ".join(_listing(outcome) for outcome in results)
        power = None if case in CLEAN else np.mean([found(args.setup, case, outcome) for outcome in results])
        print(f"| {case} | {support} | {effects or '-'} | {start_poses} | "
              f"{np.mean([o['plain_score'] for o in results]):.1f} | "
              f"{added:+.0%} | {len(results)} | {'-' if power is None else f'{power:.0%}'} | {beyond:.0%} | "
              f"{listing} |")
        if case in SUPPLEMENTARY:
            continue
        if case in CLEAN:
            wrong += sum(bool(false_discoveries(outcome)) for outcome in results)
            clean_total += len(results)
        elif added >= ADDED_ERROR_FOR_GOAL:
            met &= power >= POWER_GOAL
    rate = wrong / clean_total
    met &= rate <= FALSE_DISCOVERY_GOAL
    complete = set(GOAL_CASES[args.setup]) <= set(cases) and not args.cached_only
    judged = "" if complete else (f" (judged on the analyses of "
                                  f"{', '.join(c for c in cases if c not in SUPPLEMENTARY)} only)")
    print(f"\nfalse discoveries on clean data: {wrong} of {clean_total} ({rate:.0%}; one-sided 95 % upper bound "
          f"{upper_bound(wrong, clean_total):.0%})")
    print(f"goal (power >= {POWER_GOAL:.0%} where the added error >= {ADDED_ERROR_FOR_GOAL:.0%}, false discoveries <= "
          f"{FALSE_DISCOVERY_GOAL:.0%}){judged}: {'met' if met else 'NOT met'}; {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
