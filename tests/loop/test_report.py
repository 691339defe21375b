"""Tests of the loop's typed results and their serialisation (``pushjax.loop.report``).

``report_small/`` holds the files of a small hand-made result. Its ``report.md`` files were first written by the
markdown code from before the results were typed (which read the two JSON files' dicts back by key), and the JSON files
had the keys, in order, of the files that code's loop wrote: the typed results changed no key and no byte. Since then
the files gained the per-group values (``per_group``), the calibrated coverages and the limit surface's shape from the
force sensor (``limit_surface_shape``), the effects the data cannot tell a selected one from (``alternatives``),
the push-to-push variability (``variability``, the noise floor's ``from_variability`` and ``remaining``'s
``variability_share``), and nothing else.
"""

import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from pushjax.loop import report as report_lib
from pushjax.loop.diagnose import Dependence
from pushjax.loop.force import ForceFriction
from pushjax.loop.hierarchy import GroupValues
from pushjax.loop.metrics import NoiseFloor
from pushjax.loop.shape import LimitSurfaceShape
from pushjax.loop.variability import PUSHER_FRICTION_SOURCE, Variability
from pushjax.loop.select import Heterogeneity, MechanismCheck, Round
from pushjax.physics import model_file

EXPECTED = Path(__file__).parent / "report_small"


def _errors(scale: float) -> report_lib.HeldOutErrors:
    return report_lib.HeldOutErrors(
        trans_percent=20.0 * scale, rot_percent=30.0 * scale, trans_mm=1.5 * scale, rot_deg=0.75 * scale,
        interval={"trans_percent": [18.0 * scale, 22.5 * scale], "rot_percent": [27.0 * scale, 33.25 * scale],
                  "trans_mm": [1.25 * scale, 1.75 * scale], "rot_deg": [0.5 * scale, 1.0 * scale]})


def small_result(measured_friction: bool) -> report_lib.LoopResult:
    """A loop result of two candidate effects and two variables: the pusher friction measured and the test error
    unexplained, or the nominal friction and the error explained."""
    before = [Dependence("object yaw", 0.25, 0.125, "object", True), Dependence("push velocity", 0.0625, -0.01, "push",
                                                                                 False)]
    after = [Dependence("object yaw", 0.125, 0.03125, "world", True), Dependence("push velocity", 0.01, -0.02, "push",
                                                                                 False)]
    offset = {"offset_x_mm": {"value": 14.5, "std": 1.25}, "offset_y_mm": {"value": -9.75, "std": None}}
    tilt = {"tilt_deg": {"value": 0.5, "std": 0.25}}
    force = (ForceFriction(value=0.7890625, std=0.015625, n_sequences=12, n_pushes=40, n_pushes_without=3)
             if measured_friction else ForceFriction(value=None, std=None, n_sequences=0, n_pushes=0,
                                                     n_pushes_without=43))
    floor = NoiseFloor(trans_percent=5.0, rot_percent=7.5, interval={"trans_percent": [4.0, 6.0],
                                                                     "rot_percent": [6.5, 8.5]},
                       source="tracking", n_windows=300,
                       from_variability={"trans_percent": 1.0, "rot_percent": 0.5} if measured_friction else
                       {"trans_percent": 0.0, "rot_percent": 0.0})
    rounds = [
        Round(candidates=[], additions=["cof_offset", "table_tilt", "friction_field"], gains=[0.375, 0.0625, 0.3125],
              p_values=[0.0001, 0.25, 0.0002], levels=[0.0166, 0.05, 0.025], beyond_noise=[True, False, True],
              floor=1.5,
              mechanism=[MechanismCheck("cof_offset", [Heterogeneity("surface", "offset_x_mm", 0.5, 0.75)], {}),
                         MechanismCheck("cof_offset", [Heterogeneity("object", "offset_y_mm", 0.01, 0.625),
                                                       Heterogeneity("surface", "offset_x_mm", 0.5, 0.25)], {}),
                         MechanismCheck("cof_offset", [], {})],
              incumbent_change=0.0, continuations=0, converged=True, accepted="cof_offset",
              indistinguishable={"friction_field": 0.125}),
        Round(candidates=[], additions=["table_tilt"], gains=[-0.125], p_values=[0.75], levels=[0.05],
              beyond_noise=[False], floor=0.75, mechanism=[], incumbent_change=0.015625, continuations=3,
              converged=False,
              accepted=None, indistinguishable={}),
    ]
    report = report_lib.LoopReport(
        n_pushes={"fit": 60, "select": 90, "test": 30, "skipped": 2},
        baseline=_errors(1.0),
        diagnosis=before,
        ranking=[report_lib.RankedEffect("cof_offset", offset, report_lib.Errors(10.0, 12.5, 0.75, 0.375)),
                 report_lib.RankedEffect("table_tilt", tilt, report_lib.Errors(19.5, 29.0, 1.5, 0.75))],
        selected=["cof_offset"],
        alternatives={"cof_offset": {"friction_field": 0.125}} if measured_friction else {},
        after=_errors(0.5 if measured_friction else 0.25),  # explained without the measurement
        noise_floor=floor,
        variability={"pusher_friction": Variability(relative_sd=0.1875, interval=[0.125, 0.25], mean=0.7890625,
                                                    mean_std=0.015625, measurement_relative_sd=0.0125, n_pushes=40,
                                                    source=PUSHER_FRICTION_SOURCE)} if measured_friction else {},
        pusher_friction=report_lib.PusherFriction(nominal=0.25, force_sensor=force,
                                                  from_force_sensor=measured_friction,
                                                  used=0.7890625 if measured_friction else 0.25),
        fallback=_errors(0.375),
        remaining=[d for d in after if d.beyond_noise],
        uncertainty=report_lib.Uncertainty(selected={"nlpd": 3.5, "coverage_68": 0.625, "coverage_95": 0.875,
                                                     "calibrated_coverage_68": 0.6875,
                                                     "calibrated_coverage_95": 0.9375},
                                           noise=np.array([0.0015, 0.00075, 0.01]),
                                           fallback={"nlpd": 3.25, "coverage_68": 0.6875, "coverage_95": 0.9375,
                                                     "calibrated_coverage_68": 0.6875,
                                                     "calibrated_coverage_95": 0.953125}),
        per_group=[GroupValues(variable="surface", effect="cof_offset", value="offset_x_mm",
                               shared={"value": 14.5, "std": 1.25}, spread=0.5, p_value=0.25,
                               groups={"abs": {"fitted": 14.0, "fitted_std": 1.5, "shrunk": 14.25, "shrunk_std": 1.0},
                                       "pu": {"fitted": 15.0, "fitted_std": 1.5, "shrunk": 14.75, "shrunk_std": 1.0}})]
        if measured_friction else [],
        limit_surface_shape=LimitSurfaceShape(
            regimes=[(0.0, 0.3), (0.3, 1.0), (1.0, math.inf)],
            measured=[{"c_over_l": 0.75, "std": 0.0125, "n_windows": 250, "n_sequences": 50}, None,
                      {"c_over_l": 1.0625, "std": 0.00390625, "n_windows": 150, "n_sequences": 36}],
            models={"Lynch's ellipsoid (l)": [1.0, None, 1.0], "exact surface, uniform pressure": [0.78125, None, 1.0]},
            rim_from_force={"value": -0.5, "std": 0.125}) if measured_friction else LimitSurfaceShape(regimes=[(0.0, math.inf)], measured=[None], models={}),
    )
    details = report_lib.LoopDetails(
        data_dir="/data/pushes", horizon=0.5, seed=3, pusher_friction=0.25, alpha=0.05, min_gain=0.1,
        cross_fitted=True, n_sequences={"pool": 40, "test": 10}, n_windows={"fit": 600, "select": 900, "test": 300},
        skipped={"unknown object": ["a.h5", "b.h5"]}, diagnosis_before=before, diagnosis_after=after,
        select_noise_floor=floor, rounds=rounds, fallback_gain=0.125, fallback_p_value=0.0625,
        fallback_beyond_noise=False, selected_params={"cof_offset": offset})
    model = model_file.AugmentedModel.create(("cof_offset",), {"cof_offset": {"offset": [0.004, -0.001]}}, 0.25)
    return report_lib.LoopResult(report=report, details=details, model=model)


def test_report_files_keep_every_key_and_byte(tmp_path):
    for measured_friction in (True, False):
        workdir = tmp_path / str(measured_friction)
        workdir.mkdir()
        report_lib.write(workdir, small_result(measured_friction))
        for name in ("report.json", "details.json", "report.md"):
            expected = EXPECTED / f"{'measured' if measured_friction else 'nominal'}_{name}"
            assert (workdir / name).read_text() == expected.read_text(), name
        assert json.loads((workdir / "report.json").read_text()) == small_result(measured_friction).report.as_dict()
        assert model_file.read(workdir / "model.json").as_dict() == small_result(measured_friction).model.as_dict()


def test_explained_is_the_test_error_within_the_noise_floor_interval():
    report = small_result(True).report
    assert not report.explained and report.above_floor == {"trans_percent": 5.0, "rot_percent": 7.5}
    # The spread adds 1.5 points to the tracking noise's 11: of the 25 - 11 points above the tracking noise, 1.5 / 14.
    assert report.variability_share == 1.5 / 14
    within = report_lib.HeldOutErrors(**{**vars(report.after), "trans_percent": 6.0, "rot_percent": 8.5})
    assert report_lib.LoopReport(**{**vars(report), "after": within}).explained


def test_the_force_data_narrows_the_motion_fits_rim():
    result = small_result(True)
    details = dataclasses.replace(result.details, selected_params={
        **result.details.selected_params, "limit_surface": {"rim": {"value": -1.0, "std": 0.25}}})
    text = report_lib.markdown(dataclasses.replace(result, details=details))
    # z = -0.5 / 0.28 = -1.8: they agree. Inverse-variance weights 16 and 64: (-16 - 32) / 80 = -0.6 with standard
    # error 1 / sqrt(80) = 0.11.
    assert ("From the motion fit: -1 ± 0.25; they agree (z = -1.8); both together: -0.6 ± 0.11, an interval 2.2 times "
            "narrower than the motion's alone.") in text
    details = dataclasses.replace(result.details, selected_params={
        **result.details.selected_params, "limit_surface": {"rim": {"value": 0.5, "std": 0.25}}})
    assert ("From the motion fit: 0.5 ± 0.25; the two disagree (z = 3.6, p = 0.00035), so the motion fit's rim "
            "absorbs something") in report_lib.markdown(dataclasses.replace(result, details=details))
