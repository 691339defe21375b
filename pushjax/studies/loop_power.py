"""The loop's power and false discoveries on simulated data sets, every analysis archived
(``python -m experiments.loop_power``).

A **set-up** (:data:`SETUPS`) is two objects on one surface at two push velocities, 100 pushes per object from the MIT
grid on the ``ideal`` testbed (nothing unmodelled but what a case adds), every effect undeclared. A **case**
(:data:`CASES`) is a support model and the effect the testbed adds; a **data set** is a case recorded with one seed.
Each data set is analysed as a user analyses pushes: :func:`pushjax.loop.close_loop` with the default
:class:`~pushjax.loop.LoopConfig` (the force sensor's pusher friction, Holm, the floor above the noise floor, the
mechanism check, the per-push variability), the loop's seed the data set's.

Set-ups, in the order they were made:

* ``development``: hex and butter on plywood at 20 and 50 mm/s: the loop was changed after its stiff feet were named
  ``friction_ratio`` (``limit_surface``'s ``feet``), so it measures nothing the loop was not developed against;
* ``held_out``: tri2 and ellip3 on delrin at 15 and 40 mm/s, with a support model the library does not have (a ring of
  16 supports along the outline). Its clean sets were reused to develop the force sensor's correction;
* ``fresh``: rect2 and ellip1 on abs at 30 and 75 mm/s (issue 51): objects and speeds that no version of the loop
  was developed, tuned or tested on (every MIT surface was used by some earlier work; abs was never a power
  set-up's), with the per-push variability cases. Its criteria (:data:`CRITERIA`) and data-set counts
  (:data:`PLANS`) were committed before any of its data sets was analysed;
* ``library``: the per-effect table (BENCHMARKS.md, "Closing the loop on undeclared effects"): rect1 on polyurethane
  at 20 mm/s, 120 pushes, one data set per effect of the loop tests' kinds (tests/loop/conftest.py), no goal; its
  table has a row per analysis with the held-out errors before and after, the noise floor and the fallback.

Criteria (:func:`judge`):

* ``limit_surface`` and ``inertia`` are differences between any simulator and Lynch's model (the exact limit surface,
  the plate's momentum): selecting them is never a false discovery;
* a **false discovery**: a clean data set (``clean``, ``clean_feet``, ``clean_ring``) on which anything else is
  selected; the rate is reported with its one-sided 95 % Clopper-Pearson upper bound;
* **found** (:func:`found`), per case: a moved centre of mass or a tilted table: the first selected effect other than
  the real differences is a right one (``cof_offset`` or ``pressure_gradient``; ``table_tilt``); a centre- or
  rim-loaded pressure: ``limit_surface`` selected with its refitted support pressure moved the injected way
  (:func:`outwardness`); the pusher's friction: the force sensor reads it within :data:`SENSOR_TOLERANCE`; a per-push
  spread of the pusher friction: ``variability.pusher_friction.relative_sd`` within :data:`SPREAD_TOLERANCE` of the
  spread of the draws the pushes were recorded with (:func:`drawn_spread`, from the recording plan);
* **added error**: the plain model's test-split error (``report.json``'s ``baseline``, translation + rotation % of
  zero) on the case, averaged over its data sets, over that on ``clean``, minus 1;
* goals: power >= :data:`POWER_GOAL` for every case whose added error is >= :data:`ADDED_ERROR_FOR_GOAL`; false
  discoveries <= :data:`FALSE_DISCOVERY_GOAL` with (``fresh``) the upper bound <= :data:`FALSE_DISCOVERY_BOUND_GOAL`;
  (``fresh``) every variability case's spread found on >= :data:`POWER_GOAL` of its data sets.

**The archive** (``results/loop_power/<setup>/<case>/seed<k>/``): each analysis's ``report.json`` and ``details.json``
(the loop's own records) and ``analysis.json`` (the data set's recipe, the seconds it took and the
provenance of the code); the pushes stay in a work folder. :func:`tabulate` builds the set-up's table from the
archive alone, so ``results/loop_power/<setup>/results.md`` is rebuilt from a clone (``--cached_only``), and the test
suite checks that it is.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import shutil
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import tqdm
from scipy import stats

from pushjax import outputs, provenance
from pushjax.geometry import get_object, support
from pushjax.loop import LoopConfig, close_loop
from pushjax.physics.effects import support_pressure
from pushjax.sim.dataset import RecordingConfig, drawn_relative_sd, plan_pushes, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import IDEAL

__all__ = ["ADDED_ERROR_FOR_GOAL", "CASES", "CLEAN", "CRITERIA", "Case", "FALSE_DISCOVERY_BOUND_GOAL",
           "FALSE_DISCOVERY_GOAL", "PLANS", "POWER_GOAL", "REAL_DIFFERENCES", "SETUPS", "SPREAD_TOLERANCE",
           "SENSOR_TOLERANCE", "Setup", "analyse", "archived", "drawn_spread", "found", "judge", "planned_counts",
           "rate_interval", "recording_settings", "run", "tabulate", "write"]


@dataclasses.dataclass(frozen=True)
class Case:
    """A kind of data set.

    Attributes:
      support: the testbed's support model (``pushjax.sim.scene.SUPPORT_MODES``).
      effects: the testbed's effects, ``Effects.parse``'s ``name=value;...`` ('' none).
      testbed: overrides of the ``ideal`` testbed profile, ``Testbed.with_overrides``'s ``name=value;...``.
      start_poses: ``fixed`` (the MIT protocol's) or ``scattered`` (``pushjax.sim.dataset.START_POSES``).
    """

    support: str = "grid"
    effects: str = ""
    testbed: str = ""
    start_poses: str = "fixed"

    @property
    def family(self) -> str:
        """What the case adds: ``clean``, ``com_offset``, ``pusher_friction``, ``table_tilt``, ``pressure`` or
        ``variability``."""
        if self.testbed:
            return "variability"
        if not self.effects:
            return "clean"
        return {"com_offset": "com_offset", "pusher_friction": "pusher_friction", "table_tilt_deg": "table_tilt",
                "pressure_rim": "pressure", "friction_anisotropy": "anisotropy",
                "tracking_bias": "tracking_bias"}[self.effects.split("=", 1)[0]]


CASES = {
    "clean": Case(),
    "clean_feet": Case(support="hull"),
    "clean_ring": Case(support="ring"),
    "com_offset_s": Case(effects="com_offset=0.004,-0.003"),
    "com_offset_l": Case(effects="com_offset=0.008,-0.005"),
    "pusher_friction_s": Case(effects="pusher_friction=0.4"),
    "pusher_friction_l": Case(effects="pusher_friction=0.6"),
    "table_tilt_s": Case(effects="table_tilt_deg=3;table_tilt_azimuth_deg=60"),
    "table_tilt_l": Case(effects="table_tilt_deg=5;table_tilt_azimuth_deg=60"),
    "pressure_centre": Case(effects="pressure_rim=-3"),
    "pressure_rim": Case(effects="pressure_rim=3"),
    "variability_s": Case(testbed="pusher_friction_sigma=0.2"),
    "variability_l": Case(testbed="pusher_friction_sigma=0.4"),
    "clean_scattered": Case(start_poses="scattered"),
    # The library set-up's cases: the loop tests' data sets (tests/loop/conftest.py), one effect each, larger.
    "com_offset_xl": Case(effects="com_offset=0.015,-0.01"),
    "pressure_centre_xl": Case(effects="pressure_rim=-4"),
    "anisotropy": Case(effects="friction_anisotropy=1,2.5"),
    "table_tilt_xl": Case(effects="table_tilt_deg=6;table_tilt_azimuth_deg=60"),
    "pusher_friction_xl": Case(effects="pusher_friction=0.8"),
    "tracking_bias": Case(effects="tracking_bias=0.01,-0.006,0"),
    "tracking_yaw_bias": Case(effects="tracking_bias=0,0,0.12"),
    "com_offset_scattered": Case(effects="com_offset=0.004,-0.003", start_poses="scattered"),
}
"""Every case by name: supports ``grid`` (a pressure distributed over the footprint), ``hull`` (a few stiff feet at the
convex hull's corners) and ``ring`` (16 supports along the outline, a dished base on its edge)."""
CLEAN = ("clean", "clean_feet", "clean_ring", "clean_scattered")
REAL_DIFFERENCES = frozenset({"limit_surface", "inertia"})
TESTBED_LEADING_EDGE = "leading_edge"
"""The load's shift towards the leading edge (``mu * thickness / 2``) is in every simulation of the testbed
(RESULTS.md, "Closing the loop on realistic data") and counts as a false discovery under the committed criteria,
which list only :data:`REAL_DIFFERENCES`. Stated after the fresh set-up's first analysis (clean seed 0 selected
``leading_edge`` beside ``limit_surface``), not part of its goal: the tables also count the clean data sets with
anything selected beyond the real differences and ``leading_edge``, a second look, labelled as such."""
RIGHT_FIRST = {"com_offset": {"cof_offset", "pressure_gradient"}, "table_tilt": {"table_tilt"},
               "anisotropy": {"anisotropic_friction"}, "tracking_bias": {"frame_offset"}}
SENSOR_TOLERANCE = 0.1
"""Largest relative error of the force sensor's pusher friction that counts as found."""
SPREAD_TOLERANCE = 0.25
"""Largest relative error of the recovered per-push spread (relative sd) of the pusher friction that counts as found,
against the spread of the draws the data set was recorded with."""
POWER_GOAL, FALSE_DISCOVERY_GOAL, FALSE_DISCOVERY_BOUND_GOAL, ADDED_ERROR_FOR_GOAL = 0.9, 0.05, 0.10, 0.2


@dataclasses.dataclass(frozen=True)
class Setup:
    """Objects, surface and push velocities (mm/s) of a set-up; its cases; those its goal is judged on."""

    objects: tuple[str, ...]
    surface: str
    velocities: tuple[float, ...]
    cases: tuple[str, ...]
    goal_cases: tuple[str, ...]
    bound_goal: bool = False
    """Whether the goal asks for the false-discovery rate's upper bound too (``fresh``: issue 51)."""
    pushes_per_object: int = 100


_BASE = ("clean", "clean_feet", "com_offset_s", "com_offset_l", "pusher_friction_s", "pusher_friction_l",
         "table_tilt_s", "table_tilt_l", "pressure_centre", "pressure_rim")
SETUPS = {
    "development": Setup(("hex", "butter"), "plywood", (20.0, 50.0), _BASE, _BASE),
    "held_out": Setup(("tri2", "ellip3"), "delrin", (15.0, 40.0),
                      _BASE + ("clean_ring", "clean_scattered", "com_offset_scattered"), _BASE + ("clean_ring",)),
    "fresh": Setup(("rect2", "ellip1"), "abs", (30.0, 75.0), _BASE + ("clean_ring", "variability_s", "variability_l"),
                   _BASE + ("clean_ring", "variability_s", "variability_l"), bound_goal=True),
    "library": Setup(("rect1",), "pu", (20.0,), ("clean", "com_offset_xl", "pressure_centre_xl", "anisotropy",
                                                 "table_tilt_xl", "pusher_friction_xl", "tracking_bias",
                                                 "tracking_yaw_bias"), (), pushes_per_object=120),
}
"""The set-ups by name (module docstring; ``library`` is the per-effect table of BENCHMARKS.md: the loop tests'
data sets, rect1 on polyurethane at 20 mm/s, one data set per effect, no goal). ``held_out``'s scattered start poses were added after its goal was set, to
ask whether the small centre-of-mass offset, confounded with a table-fixed friction field from the MIT protocol's one
start pose, is found from scattered starts; they are reported beside the goal, not counted in it."""
PLANS = {
    "fresh": {**{case: 20 for case in ("clean", "clean_feet", "clean_ring")},
              **{case: 6 for case in SETUPS["fresh"].cases if case not in CLEAN}},
    "library": {case: 1 for case in SETUPS["library"].cases},
}
"""Data sets per case (seeds 0, 1, ...) that a set-up's goal is judged on, fixed before its first analysis: ``fresh``
20 clean data sets per support model (60) and 6 per effect case; ``library`` one per case. A table judged on fewer
says so."""
CRITERIA = (
    "Fixed before any analysis of the fresh set-up (issue 51). False discoveries: on the 60 clean data sets (20 per "
    "support model), anything selected but limit_surface and inertia; goal <= 5 % with the one-sided 95 % "
    "Clopper-Pearson upper bound <= 10 %. Power: per effect case, the share of its 6 data sets on which the case's "
    "physics is found (pushjax.studies.loop_power.found); goal >= 90 % for every case whose plain-model test error is "
    ">= 20 % above the clean grid data sets'. Variability: relative sd of the per-push pusher friction recovered "
    "within +-25 % of the draws' on >= 90 % of each variability case's data sets. One look, judged when every planned "
    "data set is analysed.")


def analysis_folder(archive: str | Path, setup: str, case: str, seed: int) -> Path:
    return Path(archive) / setup / case / f"seed{seed}"


def analyse(archive: str | Path, pushes_dir: str | Path, setup: str, case: str, seed: int,
            source: dict | None = None) -> dict:
    """Records (or reuses) data set ``case`` with ``seed`` under ``pushes_dir`` and runs the loop on it into the
    archive (``report.json``, ``details.json``, ``analysis.json``); an analysis already archived is read, not run.

    Args:
      source: the code's state (:func:`pushjax.provenance.source_state`) taken when the run started, so that a long
        run's records name the code it imported, not later edits of the checkout (None: taken now).

    Returns:
      The archived analysis (:func:`archived`).
    """
    folder = analysis_folder(archive, setup, case, seed)
    if (folder / "analysis.json").is_file():
        return archived(folder)
    chosen, kind = SETUPS[setup], CASES[case]
    pushes = Path(pushes_dir) / setup / case / f"seed{seed}"
    record_pushes(pushes / "pushes", list(chosen.objects), [chosen.surface], chosen.pushes_per_object,
                  recording_settings(setup, case, seed), workers=1, progress=False)
    start = time.process_time()
    close_loop(pushes / "pushes", pushes / "loop", LoopConfig(), seed=seed, progress=False)
    seconds = time.process_time() - start
    folder.mkdir(parents=True, exist_ok=True)
    for name in ("report.json", "details.json"):
        shutil.copyfile(pushes / "loop" / name, folder / name)
    record = {"setup": setup, "case": case, "seed": seed, "recipe": dataclasses.asdict(kind),
              "objects": list(chosen.objects), "surface": chosen.surface, "velocities_mm_s": list(chosen.velocities),
              "pushes_per_object": chosen.pushes_per_object,
              "loop_cpu_seconds": round(seconds, 1),
              "provenance": provenance.write_source_diff(folder, source or provenance.source_state())}
    (folder / "analysis.json").write_text(json.dumps(record, indent=1) + "\n")
    return archived(folder)


def recording_settings(setup: str, case: str, seed: int) -> RecordingConfig:
    """How data set ``case`` with ``seed`` of ``setup`` is recorded: its effects undeclared, on the ``ideal`` testbed
    with the case's overrides."""
    chosen, kind = SETUPS[setup], CASES[case]
    return RecordingConfig(seed=seed, velocities=chosen.velocities, effects=Effects.parse(kind.effects),
                           declare_effects=False, support=kind.support, testbed=IDEAL.with_overrides(kind.testbed),
                           start_poses=kind.start_poses)


@functools.cache
def drawn_spread(setup: str, case: str, seed: int) -> float:
    """Relative sd of the pusher-friction factors the testbed draws for the data set's pushes (0 without draws), from
    the recording plan: the pushes are undeclared, so their files do not carry their draws (the archived analyses
    by f8889a5 and d2e1a08 store 0 for it in ``analysis.json``, read from those files; nothing reads that field)."""
    chosen = SETUPS[setup]
    jobs = plan_pushes(Path("unused"), list(chosen.objects), [chosen.surface], chosen.pushes_per_object,
                       recording_settings(setup, case, seed))
    return drawn_relative_sd(jobs)


def archived(folder: str | Path) -> dict:
    """An archived analysis: {"analysis": analysis.json, "report": report.json, "details": details.json}."""
    folder = Path(folder)
    return {key: json.loads((folder / f"{key}.json").read_text()) for key in ("analysis", "report", "details")}


def false_discoveries(outcome: Mapping, also_real: frozenset[str] = frozenset()) -> list[str]:
    """The effects selected beyond the real differences (and ``also_real``), in the order selected."""
    return [name for name in outcome["report"]["selected"] if name not in REAL_DIFFERENCES | also_real]


def plain_score(outcome: Mapping) -> float:
    """The plain model's test-split error, translation + rotation % of zero."""
    baseline = outcome["report"]["baseline"]
    return baseline["trans_percent"] + baseline["rot_percent"]


def outwardness(limit_surface: Mapping, objects: Sequence[str]) -> float:
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


def found(outcome: Mapping) -> bool | None:
    """Whether the loop found the case's physics (module docstring); None for a clean case."""
    analysis, report = outcome["analysis"], outcome["report"]
    kind = Case(**analysis["recipe"])
    if kind.family == "clean":
        return None
    if kind.family == "pusher_friction":
        reading = report["pusher_friction"]["force_sensor"]["value"]
        return reading is not None and abs(reading / Effects.parse(kind.effects).pusher_friction - 1) <= SENSOR_TOLERANCE
    if kind.family == "variability":
        drawn = drawn_spread(analysis["setup"], analysis["case"], analysis["seed"])
        recovered = (report.get("variability") or {}).get("pusher_friction", {}).get("relative_sd")
        return recovered is not None and abs(recovered - drawn) <= SPREAD_TOLERANCE * drawn
    if kind.family == "pressure":
        fitted = outcome["details"]["selected_params"].get("limit_surface")
        injected = Effects.parse(kind.effects).pressure_rim
        return fitted is not None and bool(np.sign(outwardness(fitted, analysis["objects"]) - 1) == np.sign(injected))
    others = false_discoveries(outcome)
    if kind.family == "tracking_bias" and not any(Effects.parse(kind.effects).tracking_bias[:2]):
        return not others  # a yaw bias turns the annotated outline: no library effect models it
    return bool(others) and others[0] in RIGHT_FIRST[kind.family]


def upper_bound(count: int, total: int, level: float = 0.95) -> float:
    """One-sided Clopper-Pearson upper bound of a rate of ``count`` in ``total``."""
    return 1.0 if count == total else float(stats.beta.ppf(level, count + 1, total - count))


def rate_interval(count: int, total: int, level: float = 0.95) -> tuple[float, float]:
    """Two-sided Clopper-Pearson interval of a rate of ``count`` in ``total``."""
    tail = (1 - level) / 2
    low = 0.0 if count == 0 else float(stats.beta.ppf(tail, count, total - count + 1))
    return low, upper_bound(count, total, 1 - tail)


def _spread_row(outcome: Mapping) -> dict:
    """A variability data set's drawn and recovered relative sd of the pusher friction, with its interval."""
    analysis = outcome["analysis"]
    recovered = (outcome["report"].get("variability") or {}).get("pusher_friction") or {}
    return {"case": analysis["case"], "seed": analysis["seed"],
            "drawn": drawn_spread(analysis["setup"], analysis["case"], analysis["seed"]),
            "recovered": recovered.get("relative_sd"), "interval": recovered.get("interval"), "found": found(outcome)}


def _seeds(root: Path) -> list[int]:
    return sorted(int(path.name[4:]) for path in root.glob("seed*") if (path / "analysis.json").is_file())


def judge(setup: str, outcomes: Mapping[str, Sequence[Mapping]]) -> dict:
    """The set-up's table rows and goal from its analyses ({case: [archived analysis, ...]}); the goal is judged
    (``goal_met`` True or False) only once every goal case has analyses and the set-up's plan, if any, is archived
    (else None)."""
    chosen = SETUPS[setup]
    clean = [plain_score(outcome) for outcome in outcomes.get("clean", [])]
    reference = float(np.mean(clean)) if clean else math.nan
    rows, spreads, met, wrong, wrong_leading_edge, clean_total = [], [], True, 0, 0, 0
    for case in chosen.cases:
        results = outcomes.get(case, [])
        if not results:
            continue
        kind = CASES[case]
        scores = [plain_score(outcome) for outcome in results]
        hits = [found(outcome) for outcome in results]
        beyond = sum(bool(false_discoveries(outcome)) for outcome in results)
        beyond_leading_edge = sum(bool(false_discoveries(outcome, frozenset({TESTBED_LEADING_EDGE})))
                                  for outcome in results)
        added = float(np.mean(scores)) / reference - 1
        power = None if case in CLEAN else float(np.mean(hits))
        if kind.family == "variability":
            spreads += [_spread_row(outcome) for outcome in results]
        rows.append({"case": case, "support": kind.support, "effects": kind.effects, "testbed": kind.testbed,
                     "start_poses": kind.start_poses, "data_sets": len(results), "seeds": [
                         outcome["analysis"]["seed"] for outcome in results],
                     "plain_score": float(np.mean(scores)), "added_error": added, "power": power,
                     "power_interval": None if power is None else rate_interval(sum(hits), len(hits)),
                     "beyond_real_differences": beyond, "beyond_leading_edge": beyond_leading_edge, "selections": [_listing(outcome) for outcome in results],
                     "in_goal": case in chosen.goal_cases or not chosen.goal_cases})
        if case not in chosen.goal_cases:
            continue
        if case in CLEAN:
            wrong += beyond
            wrong_leading_edge += beyond_leading_edge
            clean_total += len(results)
        elif kind.family == "variability" or added >= ADDED_ERROR_FOR_GOAL:
            met &= power >= POWER_GOAL
    rate = wrong / clean_total if clean_total else math.nan
    bound = upper_bound(wrong, clean_total) if clean_total else math.nan
    met &= clean_total > 0 and rate <= FALSE_DISCOVERY_GOAL
    if chosen.bound_goal:
        met &= bound <= FALSE_DISCOVERY_BOUND_GOAL
    planned = PLANS.get(setup)
    missing = {case: count - len(outcomes.get(case, [])) for case, count in (planned or {}).items()
               if len(outcomes.get(case, [])) < count}
    complete = all(outcomes.get(case) for case in chosen.goal_cases) and not missing
    if not chosen.goal_cases:
        met = None
    return {"setup": setup, "rows": rows, "false_discoveries": wrong, "clean_data_sets": clean_total,
            "false_discovery_rate": rate, "false_discovery_upper_bound": bound,
            "beyond_leading_edge": wrong_leading_edge, "spreads": spreads,
            "goal_met": bool(met) if complete and met is not None else None,
            "analyses": [_analysis_row(outcome) for case in chosen.cases for outcome in outcomes.get(case, [])]
            if not chosen.goal_cases else None,
            "complete": complete, "missing": missing, "criteria": CRITERIA if setup in PLANS else None}


def _analysis_row(outcome: Mapping) -> dict:
    """One analysis's held-out errors (translation + rotation % of zero) and decision, from its report."""
    report = outcome["report"]

    def total(errors: Mapping) -> float:
        return errors["trans_percent"] + errors["rot_percent"]

    return {"case": outcome["analysis"]["case"], "seed": outcome["analysis"]["seed"],
            "baseline": total(report["baseline"]), "after": total(report["after"]),
            "selected": report["selected"], "noise_floor": total(report["noise_floor"]),
            "explained": report["explained"], "fallback": total(report["fallback"]), "found": found(outcome)}


def _listing(outcome: Mapping) -> str:
    """The selected effects, and in brackets those the data could not tell a selected one from."""
    report = outcome["report"]
    rivals = "; ".join(f"{name} or {' or '.join(others)}" for name, others in report.get("alternatives", {}).items())
    return ("+".join(report["selected"]) or "-") + (f" (not decided: {rivals})" if rivals else "")


def tabulate(archive: str | Path, setup: str) -> tuple[dict, str]:
    """The set-up's results (:func:`judge`) and their markdown, from the archive alone."""
    root = Path(archive) / setup
    outcomes = {case: [archived(analysis_folder(archive, setup, case, seed)) for seed in _seeds(root / case)]
                for case in SETUPS[setup].cases}
    results = judge(setup, outcomes)
    return results, markdown(results)


def planned_counts(setup: str, cases: Sequence[str], seeds: int | None = None,
                   clean_seeds: int | None = None) -> dict[str, int]:
    """Data sets per case: ``clean_seeds`` (clean cases) and ``seeds`` (effect cases) where given, else the set-up's
    plan (:data:`PLANS`), else 10 per clean case and 5 per effect case."""
    plan = PLANS.get(setup, {})
    return {case: (clean_seeds if case in CLEAN else seeds) or plan.get(case) or (10 if case in CLEAN else 5)
            for case in cases}


def run(setup: str, archive: str | Path, pushes_dir: str | Path, counts: Mapping[str, int],
        progress: bool = True) -> tuple[dict, str]:
    """Analyses ``counts[case]`` data sets of each case (seeds 0, 1, ... round-robin over the cases, so that a stopped
    run has every case's first seeds; archived ones are read, not run) and returns the set-up's table from the whole
    archive (:func:`tabulate`). The provenance of every new analysis is the code's state when the run started."""
    source = provenance.source_state()
    order = [(case, seed) for seed in range(max(counts.values(), default=0)) for case in counts if seed < counts[case]]
    for case, seed in tqdm.tqdm(order, desc=f"loop power analyses ({setup})", unit="data set", disable=not progress):
        report = analyse(archive, pushes_dir, setup, case, seed, source)["report"]
        if progress:
            tqdm.tqdm.write(f"{case} seed {seed}: selected {'+'.join(report['selected']) or '-'}, force sensor "
                            f"{report['pusher_friction']['force_sensor']['value']}")
    return tabulate(archive, setup)


def write(results: Mapping, table: str, archive: str | Path) -> list[Path]:
    """``results.json`` and ``results.md`` of the set-up in ``archive/<setup>/``; returns their paths."""
    return outputs.write_report(Path(archive) / results["setup"], results, table)


def markdown(results: Mapping) -> str:
    """The table of :func:`judge`'s results."""
    lines = ["| case | support | testbed effect | start poses | plain model, test % | added error | data sets | found [95 %] | "
             "anything beyond limit_surface, inertia | ... and leading_edge | selections |",
             "|---|---|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for row in results["rows"]:
        effect = "; ".join(part for part in (row["effects"], row["testbed"]) if part) or "-"
        power = "-" if row["power"] is None else (f"{row['power']:.0%} [{row['power_interval'][0]:.0%}, "
                                                  f"{row['power_interval'][1]:.0%}]")
        lines.append(f"| {row['case']}{'' if row['in_goal'] else ' (beside the goal)'} | {row['support']} | {effect} | "
                     f"{row['start_poses']} | {row['plain_score']:.1f} | {row['added_error']:+.0%} | "
                     f"{row['data_sets']} | {power} | {row['beyond_real_differences']} | {row['beyond_leading_edge']} | "
                     f"{'; '.join(row['selections'])} |")
    if results.get("analyses") is not None:
        lines += ["", "| case | seed | baseline | after | cut | selected | noise floor | explained | fallback | found |",
                  "|---|---:|---:|---:|---:|---|---:|---|---:|---|"]
        lines += [f"| {row['case']} | {row['seed']} | {row['baseline']:.1f} | {row['after']:.1f} | "
                  f"{1 - row['after'] / row['baseline']:.0%} | {', '.join(row['selected']) or '-'} | "
                  f"{row['noise_floor']:.1f} | {row['explained']} | {row['fallback']:.1f} | "
                  f"{'-' if row['found'] is None else row['found']} |" for row in results["analyses"]]
        lines += ["", "Held-out errors: translation + rotation % of the zero baseline on the test split; `baseline` "
                  "the plain model with the force sensor's pusher friction, `after` the selected model, `fallback` "
                  "the learned error term. No goal: the per-effect table."]
        return "\n".join(lines) + "\n"
    if results.get("spreads"):
        lines += ["", "| case | seed | pusher friction's relative sd: drawn | recovered [95 %] | within +-25 % |",
                  "|---|---:|---:|---|---|"]
        lines += [f"| {row['case']} | {row['seed']} | {row['drawn']:.3f} | "
                  + ("-" if row["recovered"] is None else
                     f"{row['recovered']:.3f} [{row['interval'][0]:.3f}, {row['interval'][1]:.3f}]")
                  + f" | {row['found']} |" for row in results["spreads"]]
    total = results["clean_data_sets"]
    lines += ["", f"False discoveries on the goal's clean data sets: {results['false_discoveries']} of {total}"
              + (f" ({results['false_discovery_rate']:.1%}; one-sided 95 % upper bound "
                 f"{results['false_discovery_upper_bound']:.1%})" if total else "") + "."]
    if total:
        beyond = results["beyond_leading_edge"]
        lines.append(f"Second look, stated after the first analysis and not the goal's criterion (`leading_edge` is in "
                     f"every simulation): {beyond} of {total} with anything selected beyond limit_surface, inertia and "
                     f"leading_edge (one-sided 95 % upper bound {upper_bound(beyond, total):.1%}).")
    if results["complete"]:
        lines.append(f"Goal: **{'met' if results['goal_met'] else 'not met'}**.")
    else:
        missing = ", ".join(f"{count} {case}" for case, count in results["missing"].items())
        lines.append("Goal: **not judged**: the planned analyses are not all archived"
                     + (f" (missing {missing})" if missing else "") + ".")
    if results["criteria"]:
        lines += ["", f"Criteria: {results['criteria']}"]
    return "\n".join(lines) + "\n"
