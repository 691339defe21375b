"""The limit surface's shape from the force sensor (pushjax.loop.shape, pushjax.loop.force.window_wrenches)."""

import dataclasses

import numpy as np
import pytest

from pushjax.geometry import get_object
from pushjax.loop import force, shape
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes


def test_an_ellipsoid_of_another_ratio_reads_that_ratio_in_every_regime():
    rng = np.random.default_rng(0)
    count = 3000
    l = np.full(count, 0.03)
    twist = np.column_stack([rng.normal(0, 0.01, (count, 2)), rng.normal(0, 0.3, count)])
    wrench = np.column_stack([twist[:, :2], twist[:, 2] * (0.8 * l) ** 2]) * rng.uniform(0.5, 2.0, (count, 1))
    result = shape.limit_surface_shape(twist, wrench, l, np.arange(count) % 50, {"ellipsoid": wrench})
    for measured, model in zip(result.measured, result.models["ellipsoid"]):
        assert measured["c_over_l"] == pytest.approx(0.8, rel=1e-9) and model == pytest.approx(0.8, rel=1e-9)
        assert measured["std"] < 1e-9  # every sequence has the same ratio
    # Windows without a force reading are left out, and a regime without enough windows has no value.
    wrench[: count - 10] = np.nan
    assert shape.limit_surface_shape(twist, wrench, l, np.arange(count) % 50, {}).measured == [None] * 3


def test_the_force_sensor_sees_the_exact_surface_not_the_ellipsoid(record):
    # Clean pushes (uniform pressure on the testbed's support grid): near pure translation the torque-to-force ratio is
    # about 0.75 l (a uniform plate's second moment along the motion), not Lynch's l; the exact surface of the same
    # support predicts it at the same twists within a few percent in every regime.
    examples, _ = build_examples(iter_pushes(record("clean")))
    models = shape.shape_models(examples, None)
    result = shape.limit_surface_shape(shape.measured_twists(examples), examples.wrench, examples.inputs.l,
                                       examples.sequence, models)
    exact = result.models["exact surface, uniform pressure"]
    assert result.models["Lynch's ellipsoid (l)"] == pytest.approx([1.0] * 3)
    assert all(measured is not None for measured in result.measured)
    for measured, predicted in zip(result.measured, exact):
        assert abs(measured["c_over_l"] - predicted) < 0.05, (result.measured, exact)
    near_translation = result.measured[0]
    assert near_translation["c_over_l"] < 0.85 and near_translation["std"] < 0.03
    # The force data alone put the pressure near uniform (the testbed's 24 support points differ a little from the
    # model's cells: the grid's l is 1-2 % below the uniform plate's).
    rim = shape.rim_from_force(examples, result)
    assert abs(rim["value"]) < 0.15 and 0 < rim["std"] < 0.05, rim
    # A rim-loaded pressure moves the ratio near translation up, towards l.
    rim_loaded = shape.shape_models(examples, {"limit_surface": {"rim": np.array(2.0), "feet": np.array(0.0)}})
    rim_result = shape.limit_surface_shape(shape.measured_twists(examples), examples.wrench, examples.inputs.l,
                                           examples.sequence, rim_loaded)
    assert rim_result.models["exact surface, fitted pressure (rim 2, feet 0)"][0] > exact[0] + 0.05


def test_window_wrenches_are_missing_where_the_sensor_reads_nothing(record):
    push = next(iter(iter_pushes(record("clean"))))
    starts = np.array([0, 50, 100])
    obj = get_object(push.params.shape)
    read = force.window_wrenches(push, obj, starts, starts + 50)
    assert np.isfinite(read[1:]).all()
    silent = force.window_wrenches(dataclasses.replace(push, wrench=np.zeros_like(push.wrench)), obj, starts,
                                   starts + 50)
    assert np.isnan(silent).all()


def test_a_centre_loaded_support_reads_a_negative_rim_from_the_force_data_alone(record):
    examples, _ = build_examples(iter_pushes(record("pressure")))  # the testbed's pressure_rim = -4
    result = shape.limit_surface_shape(shape.measured_twists(examples), examples.wrench, examples.inputs.l,
                                       examples.sequence, shape.shape_models(examples, None))
    rim = shape.rim_from_force(examples, result)
    assert rim is not None and rim["value"] < -3 and rim["std"] < 1, rim
