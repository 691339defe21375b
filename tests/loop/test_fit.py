"""Tests of the effect fits, the forward selection and the error-correction fallback on synthetic
targets: the windows of a recorded data set with targets predicted by a known augmented model."""

import dataclasses
import os
import threading

import numpy as np
import pytest

from pushjax.loop import correction, fit, hierarchy, metrics, select, splits
from pushjax.loop.windows import build_examples, split_by_sequence
from pushjax.mit.files import iter_pushes
from pushjax.physics import effects as effects_lib
from pushjax.physics.effects import EFFECT_NAMES

from .conftest import FIT, STRIDE

TRUE = {"cof_offset": {"offset": np.array([0.008, -0.004])},
        "friction_ratio": {"log_scale": np.array(np.log(1.4))}}


@pytest.fixture(scope="module")
def synthetic(record):
    """Examples whose targets follow cof_offset + friction_ratio, plus 0.2 mm / 0.2 deg noise."""
    examples, _ = build_examples(iter_pushes(record("clean")), stride=STRIDE)
    truth = fit.FitResult(effects=tuple(TRUE), params=TRUE, loss=0.0)
    target = fit.predict([truth], examples)[0]
    noise = np.random.default_rng(0).normal(size=target.shape) * np.array([2e-4, 2e-4, np.radians(0.2)])
    return dataclasses.replace(examples, target=target + noise)


def test_fits_several_candidates_at_once_and_recovers_the_parameters(synthetic):
    train, heldout = split_by_sequence(synthetic, 0.3, seed=0)
    results = fit.fit_effects([("friction_ratio", "cof_offset"), ("cof_offset",), ("table_tilt",)], train)
    assert [r.effects for r in results] == [("cof_offset", "friction_ratio"), ("cof_offset",), ("table_tilt",)]
    both = results[0]
    np.testing.assert_allclose(both.params["cof_offset"]["offset"], TRUE["cof_offset"]["offset"], atol=5e-4)
    np.testing.assert_allclose(both.params["friction_ratio"]["log_scale"], np.log(1.4), atol=0.03)
    scale = both.physical["friction_ratio"]["scale"]
    assert 0 < scale["std"] < 0.05 and abs(scale["value"] - 1.4) < 5 * scale["std"] + 0.01
    offset = both.physical["cof_offset"]["offset_x_mm"]
    assert 0 < offset["std"] < 1.0 and abs(offset["value"] - 8.0) < 5 * offset["std"] + 0.1
    assert both.loss < results[1].loss < results[2].loss
    predictions = fit.predict([None, *results], heldout)
    scores = [metrics.combined(metrics.summarize(metrics.window_errors(p, heldout.target, heldout.sequence)))
              for p in predictions]
    assert scores[1] < 0.3 * scores[0] and scores[1] < scores[2] < scores[0]


CENTRE_SHIFTS = ("cof_offset", "pressure_gradient")
"""Both move the centre of friction by their ``offset``; pressure_gradient also shrinks l, which friction_ratio
absorbs, so with friction_ratio either one is the true model (which one wins depends on the split)."""


def test_forward_selection_adds_both_effects_and_stops(synthetic):
    split = splits.split(synthetic, len(EFFECT_NAMES), seed=1)
    selection = select.select_effects(split, settings=FIT)
    assert len(selection.selected) == 2 and "friction_ratio" in selection.selected
    shift = next(effect for effect in selection.selected if effect != "friction_ratio")
    assert shift in CENTRE_SHIFTS
    assert selection.rounds[-1].accepted is None and len(selection.rounds) == 3
    assert selection.converged and all(abs(r.incumbent_change) <= select.CONVERGENCE_TOLERANCE
                                       and r.continuations == 0 for r in selection.rounds)
    assert selection.ranking[0].effects[0] in TRUE
    assert selection.final.score < 0.5 * selection.baseline.score
    # The reported model is refitted on the pool (fit and select sequences, never the test split's) and recovers
    # the true centre-of-friction offset.
    assert set(selection.model.effects) == set(selection.selected)
    np.testing.assert_allclose(selection.model.params[shift]["offset"], TRUE["cof_offset"]["offset"], atol=5e-4)
    assert not set(split.pool.sequence) & set(split.test.sequence)


def test_fits_stopped_far_from_their_optimum_add_nothing(synthetic):
    # Ten Adam steps leave the first effect's fit far from its optimum, and each continuation by ten more moves its
    # selection score by more than the tolerance, so after the last continuation the round refuses instead of
    # crediting the second effect with the first one's unfinished fit.
    split = splits.split(synthetic, len(EFFECT_NAMES), seed=1)
    selection = select.select_effects(split, settings=fit.FitConfig(steps=10, warm_steps=10))
    first, second = selection.rounds[:2]
    assert first.converged and first.accepted is not None
    assert second.continuations == select.MAX_CONTINUATIONS
    assert second.incumbent_change > select.CONVERGENCE_TOLERANCE and not second.converged
    assert second.accepted is None and len(selection.rounds) == 2 and not selection.converged
    assert selection.selected == [first.accepted]


def test_error_correction_learns_what_the_model_misses(synthetic):
    train, heldout = split_by_sequence(synthetic, 0.3, seed=2)
    plain_train, plain_heldout = fit.predict([None], train)[0], fit.predict([None], heldout)[0]
    term = correction.fit_error_correction(train, plain_train, correction.CorrectionConfig(steps=600), seed=0)
    before = metrics.combined(metrics.summarize(metrics.window_errors(plain_heldout, heldout.target, heldout.sequence)))
    corrected, std = term(heldout, plain_heldout)
    after = metrics.combined(metrics.summarize(metrics.window_errors(corrected, heldout.target, heldout.sequence)))
    assert after < 0.8 * before
    np.testing.assert_array_equal(term(heldout, plain_heldout)[0], corrected)
    # The predicted spread follows the error: its 95 % intervals hold most of the held-out outputs.
    scores = metrics.predictive_scores(corrected, std, heldout.target, heldout.inputs.object_yaw)
    assert 0.8 < scores["coverage_95"] <= 1 and scores["coverage_68"] < scores["coverage_95"]


def test_unknown_effects_are_rejected(synthetic):
    with pytest.raises(ValueError, match="unknown 'wind'"):
        fit.fit_effects([("wind",)], synthetic)


def _two_surfaces(examples, scales):
    """The windows labelled as two surfaces (alternate sequences), targets following pusher_friction with the
    log-scale ``scales[surface]`` on each, plus 0.2 mm / 0.2 deg noise."""
    surface = np.where(examples.sequence % 2 == 0, "abs", "pu")
    target = np.zeros_like(examples.target)
    for name, scale in scales.items():
        truth = fit.FitResult(effects=("pusher_friction",), params={"pusher_friction": {"log_scale": np.array(scale)}},
                              loss=0.0)
        target[surface == name] = fit.predict([truth], examples)[0][surface == name]
    noise = np.random.default_rng(3).normal(size=target.shape) * np.array([2e-4, 2e-4, np.radians(0.2)])
    return dataclasses.replace(examples, target=target + noise,
                               variables={**examples.variables, "surface": surface})


def test_an_effect_whose_parameters_flip_between_surfaces_is_a_knob(record):
    examples, _ = build_examples(iter_pushes(record("clean")), stride=STRIDE)
    settings = fit.FitConfig(steps=150)
    start = {"pusher_friction": {"log_scale": np.array(0.0)}}
    same = select.check_mechanism(_two_surfaces(examples, {"abs": 0.5, "pu": 0.5}), ("pusher_friction",),
                                  "pusher_friction", settings, start)
    flipped = select.check_mechanism(_two_surfaces(examples, {"abs": 0.6, "pu": -0.6}), ("pusher_friction",),
                                     "pusher_friction", settings, start)
    # The same mechanism, a little stronger on one surface (mu x 1.65 and x 1.82): beyond the noise but within the
    # practical margin, as a true effect looks when many noise-free pushes meet a misfit the library has no name for.
    near = select.check_mechanism(_two_surfaces(examples, {"abs": 0.5, "pu": 0.6}), ("pusher_friction",),
                                  "pusher_friction", settings, start)
    assert same.variable == flipped.variable == "surface" and set(flipped.values["surface"]) == {"abs", "pu"}
    assert not same.is_knob(0.05) and flipped.is_knob(0.05), (same.p_value, flipped.p_value)
    assert near.p_value <= 0.05 and near.tests[0].relative_spread < select.MECHANISM_SPREAD, near.tests
    assert not near.is_knob(0.05) and flipped.tests[0].relative_spread > select.MECHANISM_SPREAD, flipped.tests
    # Per surface with shrinkage: both surfaces are fitted precisely, so each keeps its own value.
    model = fit.fit_effects([("pusher_friction",)], _two_surfaces(examples, {"abs": 0.5, "pu": 0.6}), settings,
                            initial=[start])[0]
    (values,) = hierarchy.hierarchical(_two_surfaces(examples, {"abs": 0.5, "pu": 0.6}), model, settings)
    assert (values.variable, values.effect, values.value) == ("surface", "pusher_friction", "mu_scale")
    np.testing.assert_allclose([values.groups[name]["shrunk"] for name in ("abs", "pu")], np.exp([0.5, 0.6]),
                               rtol=0.02)
    assert np.exp(0.5) < values.shared["value"] < np.exp(0.6) and values.p_value <= 0.05
    # One surface, one object, one velocity: nothing to compare, so the check cannot call it a knob.
    single = select.check_mechanism(examples, ("pusher_friction",), "pusher_friction", settings, start)
    assert single.p_value is None and not single.is_knob(0.05)


def test_predictions_in_chunks_equal_the_model_on_every_window(synthetic):
    # More windows than one chunk of fit.MIN_PADDED_SIZE: the chunked predictions (and the padding) must line up.
    assert len(synthetic) > 2 * fit.MIN_PADDED_SIZE
    exact = fit.FitResult(effects=("limit_surface",), params=effects_lib.init_params(("limit_surface",)), loss=0.0)
    for result in (fit.FitResult(effects=tuple(TRUE), params=TRUE, loss=0.0), exact):
        direct = effects_lib.compose(result.effects)(result.params, synthetic.inputs)
        np.testing.assert_allclose(fit.predict([result], synthetic)[0], direct, rtol=1e-5, atol=1e-7)


def test_side_by_side_runs_the_fits_at_once_in_order():
    assert fit.side_by_side(lambda k: k * k, range(5)) == [0, 1, 4, 9, 16]
    assert fit.side_by_side(lambda k: k, []) == []

    def fails_on_two(k):
        if k == 2:
            raise ValueError("fold 2")
        return k

    with pytest.raises(ValueError, match="fold 2"):
        fit.side_by_side(fails_on_two, range(4))
    if (os.cpu_count() or 1) < 2:
        pytest.skip("one core: the fits run one after another")
    both = threading.Barrier(2, timeout=30)  # each waits for the other: they must run at the same time
    assert fit.side_by_side(lambda k: (both.wait(), k)[1], [0, 1]) == [0, 1]


@pytest.mark.parametrize("count", [1, 255, 256, 257, 1000, 2048, 2049, 2192, 3237, 4096, 4097, 9000, 70000])
def test_padded_sizes_are_few_and_close_above_the_fine_padding(count):
    size = fit.padded_size(count)
    assert size >= max(count, fit.MIN_PADDED_SIZE) and size % fit.MIN_PADDED_SIZE == 0
    power = 1 << (size - 1).bit_length()
    if size <= fit.FINE_PADDING_ABOVE:
        assert size == max(power, fit.MIN_PADDED_SIZE)
    else:  # one of the 8 sizes between two powers of two: at most an eighth more windows
        assert size % (power // 16) == 0 and size <= 1.125 * count
