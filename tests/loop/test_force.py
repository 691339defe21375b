"""The pusher–object friction read from the force sensor (pushjax.loop.force)."""

import dataclasses

import numpy as np
import pytest

from pushjax.geometry import get_object
from pushjax.loop import force
from pushjax.loop.windows import build_examples, tracking_noise
from pushjax.mit.files import iter_pushes
from pushjax.sim.dataset import RecordingConfig, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION
from pushjax.sim.testbed import IDEAL


@pytest.mark.parametrize("name, true", [("clean", PUSHER_OBJECT_FRICTION), ("pusher_friction", 0.8)])
def test_sliding_pushes_read_the_simulated_coefficient(name, true, record):
    examples, _ = build_examples(iter_pushes(record(name)))
    measured = force.estimate(examples.push_friction, examples.push, examples.sequence)
    assert measured.measured and measured.value == pytest.approx(true, rel=0.01)
    assert measured.std < 0.01 * true
    # Pushes that stick throughout have no estimate, and are counted.
    assert measured.n_pushes + measured.n_pushes_without == examples.n_pushes
    assert measured.n_pushes_without > 0 and measured.n_pushes > examples.n_pushes / 2


def test_a_push_without_force_readings_has_no_estimate(record):
    push = next(push for push in iter_pushes(record("clean"))
                if np.isfinite(force.sliding_friction(push, get_object(push.params.shape), tracking_noise(push.object))[0]))
    silent = dataclasses.replace(push, wrench=np.zeros_like(push.wrench))
    assert np.all(np.isnan(force.sliding_friction(silent, get_object(push.params.shape), tracking_noise(push.object))))


def test_estimates_pool_pushes_by_sequence():
    # Sequence 0: pushes 0 and 1 (0.2, 0.4); sequence 1: push 2 (0.5); push 3 never slid.
    push = np.array([0, 0, 1, 2, 2, 3])
    sequence = np.array([0, 0, 0, 1, 1, 1])
    values = np.array([0.2, 0.2, 0.4, 0.5, 0.5, np.nan])
    measured = force.estimate(values, push, sequence)
    assert measured.value == pytest.approx(0.4) and measured.std == pytest.approx(0.1)
    assert (measured.n_sequences, measured.n_pushes, measured.n_pushes_without) == (2, 3, 1)
    assert not measured.measured  # fewer than MIN_SEQUENCES sequences
    nothing = force.estimate(np.full(3, np.nan), np.arange(3), np.arange(3))
    assert nothing.value is None and nothing.std is None and not nothing.measured


def test_a_turning_object_whose_contact_sticks_is_not_read_as_sliding(tmp_path):
    # At 40 mm/s the ellipse turns fast enough that its contact point moves around the round tip while the contact
    # sticks; those samples lie inside the cone. Only the tip's slip over the object counts as sliding, so every
    # push that slid reads the simulated coefficient (the touched point's motion along the outline read 0.22-0.6).
    settings = RecordingConfig(seed=0, velocities=(40.0,), effects=Effects(pusher_friction=0.6),
                               declare_effects=False, testbed=IDEAL)
    record_pushes(tmp_path, ["ellip3"], ["delrin"], 12, settings, workers=1, progress=False)
    pushes = list(iter_pushes(tmp_path))
    values = np.array([force.sliding_friction(push, get_object("ellip3"), tracking_noise(push.object))[0]
                       for push in pushes])
    assert np.count_nonzero(np.isfinite(values)) >= 3
    np.testing.assert_allclose(values[np.isfinite(values)], 0.6, rtol=0.05)


def test_readings_from_shared_touches_equal_their_own(record):
    # build_examples annotates each push's contacts once and gives them to both readings.
    push = next(iter(iter_pushes(record("clean"))))
    obj, noise = get_object(push.params.shape), tracking_noise(push.object)
    touches = force.touches_of(push, obj)
    starts = np.arange(0, len(push.time) - 50, 25)
    assert force.sliding_friction(push, obj, noise, touches) == force.sliding_friction(push, obj, noise)
    np.testing.assert_array_equal(force.window_wrenches(push, obj, starts, starts + 50, touches),
                                  force.window_wrenches(push, obj, starts, starts + 50))
