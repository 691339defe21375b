"""Tests of window building, annotation and the split by push sequence."""

import dataclasses

import numpy as np
import pytest

from pushjax.geometry import get_object
from pushjax.loop.windows import VARIABLES, build_examples, split_by_sequence
from pushjax.mit.files import iter_pushes, load_push
from pushjax.physics.effects import PushInputs
from pushjax.sim.dataset import RecordingConfig, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import IDEAL


@pytest.fixture(scope="module")
def clean_examples(record):
    return build_examples(iter_pushes(record("clean")))


def test_windows_follow_the_streams(record, clean_examples):
    examples, summary = clean_examples
    assert summary.n_pushes == 120 and summary.n_skipped == 0
    assert examples.n_sequences == 120 and len(examples) > 5 * 120
    assert set(examples.variables) == set(VARIABLES)
    push = load_push(sorted(record("clean").rglob("*.h5"))[0])
    first = examples.select(examples.sequence == 0)
    horizon = round(0.5 * 250)
    starts = np.round(first.variables["time in the push"] * 250).astype(int)
    # Windows start every horizon / 2 while the pusher moves (20 mm/s: 53 mm in 2.65 s).
    np.testing.assert_array_equal(np.diff(starts), round(0.25 * 250))
    assert starts[0] == 0 and 2.2 < first.variables["time in the push"][-1] < 2.65
    np.testing.assert_allclose(first.target[:, :2], push.object[starts + horizon, :2] - push.object[starts, :2])
    np.testing.assert_allclose(first.target[:, 2], push.object[starts + horizon, 2] - push.object[starts, 2])
    np.testing.assert_allclose(first.inputs.pusher_motion, push.tip[starts + horizon, :2] - push.tip[starts, :2])
    np.testing.assert_allclose(first.inputs.push_speed, 0.02, rtol=0.05)
    np.testing.assert_allclose(first.inputs.l, 0.045 * (np.sqrt(2) + np.log(1 + np.sqrt(2))) / 3, rtol=1e-2)


def test_contacts_are_annotated(clean_examples):
    examples, _ = clean_examples
    inputs = examples.inputs
    touching = inputs.s > 0
    assert 0.8 < touching.mean() < 1.0
    np.testing.assert_allclose(np.linalg.norm(inputs.normal[touching], axis=1), 1.0)
    np.testing.assert_array_equal(inputs.action[~touching], 0.0)
    approach = np.sum(inputs.pusher_motion * inputs.normal, axis=1)
    # rect1 is a 90 mm square: contacts lie on its boundary (in the object's axes).
    yaw = inputs.object_yaw[touching]
    contact = inputs.contact[touching]
    local = np.stack([np.cos(yaw) * contact[:, 0] + np.sin(yaw) * contact[:, 1],
                      -np.sin(yaw) * contact[:, 0] + np.cos(yaw) * contact[:, 1]], axis=1)
    np.testing.assert_allclose(np.abs(local).max(axis=1), 0.045, atol=1e-6)
    # The action after contact is the part of the pusher's motion that follows the gap.
    fraction = 1 - np.linalg.norm(inputs.action, axis=1) / np.linalg.norm(inputs.pusher_motion, axis=1)
    later = touching & (inputs.gap > 0)
    np.testing.assert_allclose(fraction[later], inputs.gap[later] / approach[later], atol=1e-6)
    assert np.all(examples.variables["contact versus no contact"][touching] == "contact")


def test_contacts_beyond_the_window_are_annotated_without_push(record):
    # With a biased tracked frame the annotated outline lies 10 mm behind the true one: the first
    # windows stop short of it, and the contact the pusher would make further on is annotated.
    inputs = build_examples(iter_pushes(record("tracking_bias")))[0].inputs
    ahead = (inputs.s == 0) & np.any(inputs.normal != 0, axis=1)
    assert ahead.mean() > 0.05
    np.testing.assert_array_equal(inputs.action[ahead], 0.0)
    approach = np.sum(inputs.pusher_motion * inputs.normal, axis=1)
    assert np.all(inputs.gap[ahead] >= approach[ahead] - 1e-9)
    assert np.all(inputs.gap[ahead] <= approach[ahead] + 0.03 + 1e-9)


def test_effect_attributes_are_never_read(tmp_path):
    arguments = dict(objects=["tri1"], surfaces=["abs"], pushes=3, workers=1, progress=False)
    settings = RecordingConfig(seed=2, velocities=(50.0,), effects=Effects(com_offset=(0.01, 0.0)), testbed=IDEAL)
    record_pushes(tmp_path / "declared", settings=settings, **arguments)
    record_pushes(tmp_path / "undeclared", settings=dataclasses.replace(settings, declare_effects=False), **arguments)
    declared, _ = build_examples(iter_pushes(tmp_path / "declared"))
    undeclared, _ = build_examples(iter_pushes(tmp_path / "undeclared"))
    for field in dataclasses.fields(PushInputs):
        np.testing.assert_array_equal(getattr(declared.inputs, field.name), getattr(undeclared.inputs, field.name))
    np.testing.assert_array_equal(declared.push_friction, undeclared.push_friction)
    np.testing.assert_array_equal(declared.target, undeclared.target)
    # The triangle's centroid is not its tracked frame: the target is the centroid's displacement.
    centroid = get_object("tri1").centroid
    push = load_push(sorted((tmp_path / "declared").rglob("*.h5"))[0])
    first = declared.select(declared.sequence == 0)
    starts = np.round(first.variables["time in the push"] * 250).astype(int)
    ends = starts + round(0.5 * 250)

    def centre(poses):
        cos, sin = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        return poses[:, :2] + np.stack([cos * centroid[0] - sin * centroid[1], sin * centroid[0] + cos * centroid[1]], 1)

    np.testing.assert_allclose(first.target[:, :2], centre(push.object[ends]) - centre(push.object[starts]))


def test_split_keeps_sequences_together_and_is_seeded(clean_examples):
    examples, _ = clean_examples
    fit, heldout = split_by_sequence(examples, 0.3, seed=4)
    assert not set(fit.sequence) & set(heldout.sequence)
    assert len(fit) + len(heldout) == len(examples)
    assert heldout.n_sequences == 36 and fit.n_sequences == 84
    again, _ = split_by_sequence(examples, 0.3, seed=4)
    np.testing.assert_array_equal(again.sequence, fit.sequence)
    other, _ = split_by_sequence(examples, 0.3, seed=5)
    assert set(other.sequence) != set(fit.sequence)


def test_bad_arguments_are_named(record, clean_examples):
    with pytest.raises(ValueError, match="horizon"):
        build_examples(iter_pushes(record("clean")), horizon=0.0)
    with pytest.raises(ValueError, match="none gave a prediction window"):
        build_examples(iter_pushes(record("clean")), horizon=30.0)
    with pytest.raises(ValueError, match="heldout_fraction"):
        split_by_sequence(clean_examples[0], 1.0)
