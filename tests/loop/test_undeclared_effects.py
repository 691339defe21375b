"""The mission's own test: the loop finds effects nobody declared in testbed data.

Every data set is recorded with ``declare_effects=False``, so its files hold exactly what real MIT files
hold. The loop must name the injected effect first and cut the held-out error by at least 30 %, select
nothing on clean data, and report an effect outside the library as unexplained, with the variable the
residual depends on, and a fallback that reduces the error.
"""

import json

import pytest

from pushjax.physics.effects import EFFECT_NAMES

from .conftest import CASES

SUMMARY_KEYS = {"trans_pct", "rot_pct", "trans_mm", "rot_deg"}


def combined(summary):
    return summary["trans_pct"] + summary["rot_pct"]


@pytest.mark.parametrize("name", [name for name, case in CASES.items() if case.expected is not None])
def test_injected_effect_is_selected_first_and_cuts_the_heldout_error(name, loop_report):
    report, _ = loop_report(name)
    assert report["selected"][:1] == [CASES[name].expected], report["selected"]
    assert combined(report["after"]) <= 0.7 * combined(report["baseline"])
    assert report["ranking"][0]["effect"] == CASES[name].expected


def test_clean_data_selects_nothing(loop_report):
    report, _ = loop_report("clean")
    assert report["selected"] == []
    assert report["after"] == report["baseline"]


def test_effect_outside_the_library_is_unexplained_and_the_fallback_helps(loop_report):
    report, workdir = loop_report("tracking_yaw_bias")
    assert report["explained"] is False
    details = json.loads((workdir / "details.json").read_text())
    variable = details["unexplained_variable"]["variable"]
    assert variable in {d["variable"] for d in report["diagnosis"]}
    assert variable in (workdir / "report.md").read_text()
    assert combined(report["fallback"]["heldout"]) < 0.9 * combined(report["after"])


def test_report_follows_the_schema(loop_report):
    report, workdir = loop_report("com_offset")
    assert json.loads((workdir / "report.json").read_text()) == report
    assert set(report) == {"n_pushes", "baseline", "diagnosis", "ranking", "selected", "after", "explained",
                           "fallback"}
    assert set(report["n_pushes"]) == {"fit", "heldout", "skipped"}
    assert sum(report["n_pushes"][key] for key in ("fit", "heldout")) == 120 and report["n_pushes"]["skipped"] == 0
    assert set(report["baseline"]) == set(report["after"]) == SUMMARY_KEYS
    strengths = [entry["strength"] for entry in report["diagnosis"]]
    assert strengths == sorted(strengths, reverse=True)
    assert all(set(entry) == {"variable", "strength"} for entry in report["diagnosis"])
    assert sorted(entry["effect"] for entry in report["ranking"]) == sorted(EFFECT_NAMES)
    for entry in report["ranking"]:
        assert set(entry) == {"effect", "params", "heldout"} and set(entry["heldout"]) == SUMMARY_KEYS
        assert all(set(value) == {"value", "std"} for value in entry["params"].values())
    scores = [combined(entry["heldout"]) for entry in report["ranking"]]
    assert scores == sorted(scores)
    assert report["explained"] is True and report["fallback"] is None
    # The offset is recovered within a few standard errors (the testbed moved the COM by (15, -10) mm).
    offset = report["ranking"][0]["params"]
    for axis, true in (("offset_x_mm", 15.0), ("offset_y_mm", -10.0)):
        assert abs(offset[axis]["value"] - true) < max(4 * offset[axis]["std"], 2.0)
    markdown = (workdir / "report.md").read_text()
    for figure in ("residual_baseline.png", "residual_after.png", "diagnosis.png"):
        assert (workdir / "figures" / figure).stat().st_size > 0 and figure in markdown
