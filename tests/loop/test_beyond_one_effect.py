"""The loop beyond one library effect: two undeclared effects at once (one measured, one selected), none, and one
outside the library (see test_undeclared_effects.py; a file of its own so that the cases run on two pytest-xdist
workers)."""

import json

import numpy as np

from pushjax.loop.metrics import combined

from .conftest import CASES, KNOWN_FALSE_DISCOVERIES, REAL_DIFFERENCES


def test_two_effects_at_once_one_measured_and_one_selected(loop_report):
    # The force sensor measures the pusher friction (test_undeclared_effects.py checks the value), so the plain model
    # already has it; the selection must add the centre-of-mass offset on top and nothing that is not there.
    report, workdir = loop_report("com_offset_and_pusher_friction")
    selected = set(report["selected"])
    assert report["pusher_friction"]["from_force_sensor"]
    assert selected & {"cof_offset", "pressure_gradient"}, report["selected"]
    assert selected <= (CASES["com_offset_and_pusher_friction"].expected | REAL_DIFFERENCES
                        | KNOWN_FALSE_DISCOVERIES), report["selected"]
    # On the select split: the selected set's error (the first effect's, cut by each later round's gain) is at most
    # that of any of its effects fitted alone.
    alone = {entry["effect"]: combined(entry["select"]) for entry in report["ranking"]}
    rounds = json.loads((workdir / "details.json").read_text())["rounds"]
    accepted = [r["accepted"] for r in rounds if r["accepted"]]
    final = alone[accepted[0]] * np.prod([1 - r["gains"][r["accepted"]] for r in rounds[1:] if r["accepted"]])
    assert final <= min(alone[name] for name in selected)
    assert combined(report["after"]) <= 0.7 * combined(report["baseline"])


def test_clean_data_selects_only_the_exact_limit_surface(loop_report):
    # Clean pushes differ from Lynch's model only by what any simulator has: the exact limit surface of the support
    # (not its ellipsoid) and, at most, dynamics after the pusher stops.
    report, _ = loop_report("clean")
    assert report["selected"][0] == "limit_surface", report["selected"]
    assert set(report["selected"]) <= REAL_DIFFERENCES, report["selected"]  # issue 29's acceptance
    assert combined(report["after"]) <= 0.75 * combined(report["baseline"])
    # Noise-free data: the floor is near zero, so what is left is not explained.
    assert report["explained"] is False and combined(report["noise_floor"]) < 1.0


def test_effect_outside_the_library_is_unexplained_and_the_fallback_helps(loop_report):
    report, workdir = loop_report("tracking_yaw_bias")
    assert report["explained"] is False
    variable = report["remaining"]["variables"][0]["variable"]
    assert variable in {d["variable"] for d in report["diagnosis"]}
    assert report["remaining"]["variables"][0]["strength"] > 0.1
    assert variable in (workdir / "report.md").read_text()
    assert combined(report["fallback"]) < 0.9 * combined(report["after"])
