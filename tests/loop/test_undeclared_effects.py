"""The mission's own test: the loop finds effects nobody declared in testbed data.

Every data set is recorded with ``declare_effects=False``, so its files hold exactly what real MIT files
hold. The loop must name the injected effect, name nothing else but what any simulator differs in from Lynch's model
(:data:`REAL_DIFFERENCES`) and the knobs it is known to still take (:data:`KNOWN_FALSE_DISCOVERIES`), and cut the
test-split error (push sequences that took no part in fitting or selecting) by at least 30 %. Clean data, two effects
at once and an effect outside the library: test_beyond_one_effect.py.
"""

import json

import numpy as np
import pytest

from pushjax.loop.metrics import combined
from pushjax.physics.effects import EFFECT_NAMES
from pushjax.sim.effects import Effects

from .conftest import CASES, KNOWN_FALSE_DISCOVERIES, REAL_DIFFERENCES

SUMMARY_KEYS = {"trans_percent", "rot_percent", "trans_mm", "rot_deg"}
SINGLE = [name for name, case in CASES.items() if case.effects != Effects() and case.expected and "_and_" not in name]
"""A moved centre of mass is found beside a measured pusher friction: test_beyond_one_effect.py's two-effect case."""
MEASURED = ["com_offset_and_pusher_friction"]
"""The loop where the pusher friction differs from the nominal one (the force sensor alone reads the pusher-friction
case: test_force.py)."""


@pytest.mark.parametrize("name", SINGLE)
def test_injected_effect_is_selected_with_no_false_discovery_and_cuts_the_test_error(name, loop_report):
    report, _ = loop_report(name)
    selected = set(report["selected"])
    assert selected & CASES[name].expected, report["selected"]
    assert selected <= CASES[name].expected | REAL_DIFFERENCES | KNOWN_FALSE_DISCOVERIES, report["selected"]
    assert combined(report["after"]) <= 0.7 * combined(report["baseline"])


@pytest.mark.parametrize("name", MEASURED)
def test_pusher_friction_is_measured_by_the_force_sensor_not_fitted(name, loop_report):
    report, workdir = loop_report(name)
    friction = report["pusher_friction"]
    assert friction["from_force_sensor"] and friction["force_sensor"]["measured"]
    assert friction["used"] == friction["force_sensor"]["value"] == pytest.approx(CASES[name].pusher_friction, rel=0.02)
    assert "pusher_friction" not in report["selected"]
    assert "pusher_friction" not in {entry["effect"] for entry in report["ranking"]}
    assert "Pusher friction from the force sensor" in (workdir / "report.md").read_text()


def test_report_follows_the_schema(loop_report):
    report, workdir = loop_report("com_offset_and_pusher_friction")
    assert json.loads((workdir / "report.json").read_text()) == report
    assert set(report) == {"n_pushes", "baseline", "diagnosis", "ranking", "selected", "alternatives", "after",
                           "noise_floor", "pusher_friction", "explained", "fallback", "remaining", "uncertainty",
                           "per_group", "limit_surface_shape", "variability"}
    assert set(report["alternatives"]) <= set(report["selected"])
    assert all(0.05 < p <= 1 for rivals in report["alternatives"].values() for p in rivals.values())
    assert report["per_group"] == []  # one object on one surface: no groups to fit apart
    spread = report["variability"]["pusher_friction"]  # one pusher friction for every push: no spread between pushes
    assert spread["interval"][0] == 0.0 and spread["relative_sd"] < 0.02 and spread["n_pushes"] > 20
    friction = report["pusher_friction"]
    assert set(friction) == {"nominal", "force_sensor", "from_force_sensor", "used"}
    assert set(friction["force_sensor"]) == {"value", "std", "n_sequences", "n_pushes", "n_pushes_without", "measured"}
    floor = report["noise_floor"]
    assert floor["source"] == "tracking" and floor["n_windows"] > 0  # no push is repeated
    assert set(report["remaining"]) == {"above_floor", "variables", "variability_share"}
    for key in ("trans_percent", "rot_percent"):
        assert 0 <= floor["interval"][key][0] <= floor[key] <= floor["interval"][key][1]
        assert report["remaining"]["above_floor"][key] == pytest.approx(report["after"][key] - floor[key])
    assert report["n_pushes"] == {"fit": 67, "select": 90, "test": 30, "skipped": 0}  # cross-fitted: every pool push selects
    for key in ("baseline", "after", "fallback"):
        assert set(report[key]) == SUMMARY_KEYS | {"interval"} and set(report[key]["interval"]) == SUMMARY_KEYS
        assert all(low <= report[key][metric] <= high for metric, (low, high) in report[key]["interval"].items())
    for model in ("selected", "fallback"):
        scores = report["uncertainty"][model]
        assert np.isfinite(scores["nlpd"]) and 0 < scores["coverage_68"] < scores["coverage_95"] <= 1
        # Split-conformal intervals from the select split hold their level on the test split, within what its 30
        # push sequences can resolve: two standard errors of a share over sequences (17 and 8 points; this data set
        # gave 74 % at 68 % once). The method itself is held to 1 point in test_metrics.py; the issue's +-5 points
        # are measured on the realistic testbed's 60 test sequences (RESULTS.md).
        sequences = report["n_pushes"]["test"]
        for level in (68, 95):
            resolvable = 2 * np.sqrt(level / 100 * (1 - level / 100) / sequences)
            assert abs(scores[f"calibrated_coverage_{level}"] - level / 100) < resolvable, scores
    strengths = [entry["strength"] for entry in report["diagnosis"]]
    assert strengths == sorted(strengths, reverse=True)
    assert all(set(entry) == {"variable", "strength"} for entry in report["diagnosis"])
    assert sorted(entry["effect"] for entry in report["ranking"]) == sorted(set(EFFECT_NAMES) - {"pusher_friction"})
    for entry in report["ranking"]:
        assert set(entry) == {"effect", "params", "select"} and set(entry["select"]) == SUMMARY_KEYS
        assert all(set(value) == {"value", "std"} for value in entry["params"].values())
    scores = [combined(entry["select"]) for entry in report["ranking"]]
    assert scores == sorted(scores)
    # The offset is recovered within a few standard errors (the testbed moved the COM by (15, -10) mm).
    offset = next(entry["params"] for entry in report["ranking"] if entry["effect"] == "cof_offset")
    for axis, true in (("offset_x_mm", 15.0), ("offset_y_mm", -10.0)):
        assert abs(offset[axis]["value"] - true) < max(4 * offset[axis]["std"], 2.0)
    markdown = (workdir / "report.md").read_text()
    for figure in ("residual_baseline.png", "residual_after.png", "diagnosis.png"):
        assert (workdir / "figures" / figure).stat().st_size > 0 and figure in markdown
