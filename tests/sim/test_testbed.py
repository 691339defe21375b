"""Tests for pushjax.sim.testbed: the profiles, and each mechanism of the realistic testbed changing its statistic.

Every mechanism is switched on alone (from the ideal profile) and compared with the same push without it.
"""

import dataclasses
import json

import h5py
import numpy as np
import pytest

from pushjax import planar
from pushjax.geometry import get_object, limit_surface_ratio
from pushjax.geometry.contact import annotate
from pushjax.mit import protocol
from pushjax.mit.files import PushParams, load_push, read_raw_push
from pushjax.physics import lynch
from pushjax.sim import dataset, push, scene
from pushjax.sim.effects import Effects
from pushjax.sim.push import SAMPLE_RATE, simulate_push, simulator
from pushjax.sim.surfaces import SURFACE_NAMES, get_surface
from pushjax.sim.testbed import IDEAL, REALISTIC, draw_conditions, from_flags
from pushjax.sim.testbed import Testbed as Profile


def params(shape="rect1", side=0, point=0.5, angle=0.0, velocity=20.0, surface="abs"):
    return PushParams(surface=surface, shape=shape, acceleration=0.0, velocity=velocity, side=side, point=point,
                      angle=angle)


def conditions(push_key=(0, 1, 2, 3), obj="rect1", surface="abs", seed=0, **magnitudes):
    """The draw of a testbed with only ``magnitudes`` on (the rest ideal)."""
    supports = len(scene.support_points(obj)[0])
    return draw_conditions(dataclasses.replace(IDEAL, **magnitudes), seed, obj, surface, push_key, supports)


def motion(recording):
    """(displacement m [2], rotation rad) of the tracked frame over the recording, in the start pose's frame."""
    pose = recording.true_object_pose
    return planar.rotate(pose[-1, 1:3] - pose[0, 1:3], -pose[0, 3]), pose[-1, 3] - pose[0, 3]


# The profile as data.

def test_profiles_and_overrides():
    assert IDEAL.ideal and not IDEAL.physical and IDEAL == Profile()
    assert not REALISTIC.ideal and REALISTIC.physical
    assert from_flags("ideal") == IDEAL and from_flags("realistic") == REALISTIC
    changed = from_flags("realistic", "drop_rate=0; friction_field_sigma=0.2")
    assert changed == dataclasses.replace(REALISTIC, drop_rate=0.0, friction_field_sigma=0.2)
    assert Profile.from_dict(json.loads(REALISTIC.to_json())) == REALISTIC
    assert from_flags("realistic", ";".join(f"{name}=0" for name in REALISTIC.to_dict()
                                             if not name.endswith("_length"))).ideal


@pytest.mark.parametrize("profile, spec, message", [
    ("lab", "", "testbed: expected one of ideal, realistic"),
    ("realistic", "wind=1", "unknown field.*wind"),
    ("realistic", "drop_rate", "expected 'name=value'"),
    ("realistic", "drop_rate=1", "drop_rate: expected a probability"),
    ("realistic", "pusher_friction_sigma=-0.1", "pusher_friction_sigma: expected a value >= 0"),
    ("realistic", "friction_field_length=0", "friction_field_length: expected a length"),
    ("realistic", "tracking_noise_xy=abc", "tracking_noise_xy: expected a number"),
    ("realistic", "timestamp_jitter=nan", "timestamp_jitter: expected a finite number"),
    ("realistic", "drop_rate=0;drop_rate=0.1", "given twice"),
])
def test_bad_profiles_name_the_field_in_one_line(profile, spec, message):
    with pytest.raises(ValueError, match=message) as raised:
        from_flags(profile, spec)
    assert "\n" not in str(raised.value)


def test_draws_are_seeded_per_surface_object_and_push():
    first = conditions(seed=3, friction_field_sigma=0.1, pusher_friction_sigma=0.2, pressure_plate_sigma=1.0)
    again = conditions(seed=3, friction_field_sigma=0.1, pusher_friction_sigma=0.2, pressure_plate_sigma=1.0)
    points = np.random.default_rng(0).uniform(-0.1, 0.1, (10, 2))
    np.testing.assert_array_equal(first.friction_field(points), again.friction_field(points))
    assert first.pusher_friction == again.pusher_friction
    np.testing.assert_array_equal(first.plate_pressure, again.plate_pressure)
    other_push = conditions(push_key=(0, 1, 2, 4), seed=3, pusher_friction_sigma=0.2, pressure_plate_sigma=1.0)
    assert other_push.pusher_friction != first.pusher_friction  # per push
    np.testing.assert_array_equal(other_push.plate_pressure, first.plate_pressure)  # per object
    other_surface = conditions(seed=3, surface="pu")
    assert not np.allclose(other_surface.friction_field(points), first.friction_field(points))  # per surface
    # The pusher coefficient's multiplier is log-normal with the profile's spread.
    draws = [conditions(push_key=(0, k), pusher_friction_sigma=0.2).pusher_friction for k in range(400)]
    assert np.std(np.log(draws)) == pytest.approx(0.2, rel=0.15)


# Each mechanism changes its own statistic.

def test_friction_field_makes_the_same_push_at_two_places_differ():
    """An off-centre push of rect1 at two table positions: its rotation differs by < 0.2° on a uniform surface and
    by several degrees with a 30 % friction field (5 cm correlation length)."""
    p = params(point=0.8)
    places = [(0.0, 0.0, 0.0), (0.12, -0.08, 0.0)]

    def rotations(draw):
        return [np.degrees(motion(simulate_push(p, initial_pose=place, conditions=draw))[1]) for place in places]

    uniform = rotations(conditions())
    field = rotations(conditions(friction_field_sigma=0.3))
    assert abs(uniform[0] - uniform[1]) < 0.2
    assert abs(field[0] - field[1]) > 1.0 + 5 * abs(uniform[0] - uniform[1]), (uniform, field)


def test_four_surfaces_each_with_its_own_friction_field():
    """The four MIT surfaces have distinct nominal coefficients; each has its own friction field (the realisations
    are unrelated), with the profile's relative spread over the table on every surface, so the absolute spread of
    the coefficient over a surface is proportional to the surface's coefficient."""
    nominal = [get_surface(name).object_friction for name in SURFACE_NAMES]
    assert SURFACE_NAMES == ("abs", "delrin", "plywood", "pu") and len(set(nominal)) == 4
    axis = np.linspace(-0.3, 0.3, 50)
    table = np.stack(np.meshgrid(axis, axis), axis=-1).reshape(-1, 2)
    log_factors = np.array([np.log(conditions(surface=surface, friction_field_sigma=0.1).position_factors(
        table, np.ones(len(table)))) for surface in SURFACE_NAMES])
    np.testing.assert_allclose(log_factors.std(axis=1), 0.1, rtol=0.25)
    np.testing.assert_allclose(log_factors.mean(axis=1), 0.0, atol=0.03)
    correlations = np.corrcoef(log_factors)[np.triu_indices(len(SURFACE_NAMES), 1)]
    assert np.abs(correlations).max() < 0.3, correlations


def test_position_factors_evaluated_after_half_a_millimetre_follow_the_object(monkeypatch):
    """The position factors are evaluated again only once a support point has moved 0.5 mm: the push is then the
    one that evaluating them at every 4 ms period gives, up to a small part of what freezing them at the start of
    the push (the object slides 5 cm over fields that vary over 3-5 cm) would change."""
    p = params(point=0.8)
    draw = conditions(friction_field_sigma=0.3, pressure_table_sigma=0.7)

    def rotation(distance):
        monkeypatch.setattr(push, "FIELD_UPDATE_DISTANCE", distance)
        return np.degrees(motion(simulate_push(p, conditions=draw))[1])

    every_period, lazy, frozen = rotation(0.0), rotation(5e-4), rotation(1.0)
    assert abs(frozen - every_period) > 0.5, (every_period, frozen)
    assert abs(lazy - every_period) < 0.1 * abs(frozen - every_period), (every_period, lazy, frozen)


def test_plate_pressure_turns_a_central_push():
    """A central push translates rect1 on a uniform pressure (< 1°); on a few high points the centre of friction
    leaves the push line and the plate turns."""
    p = params()
    _, flat = motion(simulate_push(p, conditions=conditions()))
    _, uneven = motion(simulate_push(p, conditions=conditions(pressure_plate_sigma=1.0)))
    assert abs(np.degrees(flat)) < 1.0
    assert abs(np.degrees(uneven)) > 3.0 + abs(np.degrees(flat)), (flat, uneven)


def test_table_pressure_moves_the_load_with_the_object():
    """The load of the plate's own unevenness moves with the plate (its centre of friction sits ~2.7 mm off the
    centroid wherever the plate is); the table's load changes with where the plate is: its centre of friction moves
    by millimetres and the limit-surface ratio l by ~15 % between three places."""
    obj = get_object("rect1")
    local, areas = scene.support_points(obj)

    def centre_and_ratio(draw, shift):
        weights = areas * draw.position_factors(local + shift, areas)
        centre = weights @ local / weights.sum() - obj.centroid
        return centre, limit_surface_ratio(obj, support_points=local, support_weights=weights / weights.mean())

    shifts = [np.array([0.0, 0.0]), np.array([0.05, 0.0]), np.array([0.0, 0.1])]
    plate = [centre_and_ratio(conditions(pressure_plate_sigma=0.7), shift) for shift in shifts]
    table = [centre_and_ratio(conditions(pressure_table_sigma=0.7), shift) for shift in shifts]
    uniform = centre_and_ratio(conditions(), shifts[0])
    assert np.linalg.norm(uniform[0]) < 1e-4
    assert np.linalg.norm(plate[0][0]) > 1e-3
    for centre, ratio in plate[1:]:
        np.testing.assert_allclose(centre, plate[0][0], atol=1e-12)
        assert ratio == pytest.approx(plate[0][1], rel=1e-9)
    centres = np.array([centre for centre, _ in table])
    ratios = np.array([ratio for _, ratio in table])
    assert np.linalg.norm(centres - centres[0], axis=1).max() > 2e-3, centres
    assert np.ptp(ratios) / uniform[1] > 0.05, ratios / uniform[1]


def test_object_friction_scales_the_support_coefficients():
    draw = conditions(obj="tri1", object_friction_sigma=0.2)
    local, areas = scene.support_points("tri1")
    factors = draw.position_factors(local, areas)
    np.testing.assert_allclose(factors, draw.object_friction)
    assert abs(np.log(draw.object_friction)) > 1e-3
    assert conditions(obj="tri1", surface="pu", object_friction_sigma=0.2).object_friction == draw.object_friction


def slide_ratio(velocity, draw):
    """Object displacement along the push over the pusher's travel, central push of rect1."""
    p = params(velocity=velocity)
    displacement, _ = motion(simulate_push(p, conditions=draw))
    return -displacement[0] / (protocol.PUSH_DISTANCE + protocol.APPROACH_DISTANCE)


def test_object_friction_changes_how_far_a_fast_push_slides_on():
    """The quasi-static model does not depend on the plate–surface coefficient; after a fast push the plate
    slides on the further, the lower its coefficient."""
    draw = conditions(object_friction_sigma=0.05)
    slippery, rough = (slide_ratio(200.0, dataclasses.replace(draw, object_friction=factor)) for factor in (0.8, 1.25))
    assert slippery > rough + 0.05, (slippery, rough)


def test_speed_dependent_friction_changes_fast_pushes_beyond_the_quasi_static_scaling():
    """The quasi-static model scales the motion with the pusher's travel, whatever the speed. At 20 mm/s the plate
    follows the pusher with or without speed-dependent friction; at 200 mm/s it slides on after the pusher stops,
    and less so when friction grows by 30 % per decade of sliding speed."""
    constant = conditions()
    growing = conditions(friction_speed_gain=0.3)
    slow = [slide_ratio(20.0, draw) for draw in (constant, growing)]
    fast = [slide_ratio(200.0, draw) for draw in (constant, growing)]
    assert slow[0] == pytest.approx(slow[1], abs=0.01)
    assert fast[0] > slow[0] + 0.1  # inertia: sliding on after contact is lost, in both
    assert fast[0] - fast[1] > 0.04, (slow, fast)  # ~ 2.5 mm less sliding on at 200 mm/s
    factor = conditions(friction_speed_gain=0.1).speed_factors(np.array([0.02, 0.2, 0.0]))
    np.testing.assert_allclose(factor, [1.0, 1.1, 1.0 - 0.1 * np.log10(20)])


def test_pusher_friction_draw_changes_the_slip_along_the_side():
    p = params(angle=0.6)
    stop = int(np.ceil(protocol.push_duration(p) * SAMPLE_RATE))

    def slip(multiplier):
        draw = dataclasses.replace(conditions(pusher_friction_sigma=0.2), pusher_friction=multiplier)
        recording = simulate_push(p, conditions=draw)
        pose, tip = recording.true_object_pose, recording.tip_pose
        local = planar.rotate(tip[:, 1:3] - pose[:, 1:3], -pose[:, 3])
        return abs(local[stop, 1] - local[60, 1])

    low, high = slip(0.5), slip(2.0)
    assert low > 1.5 * high, (low, high)
    # The model's pusher coefficients are restored after the push.
    model = simulator("rect1", "abs", Effects(), "grid").model
    np.testing.assert_allclose(model.pair_friction[-1, :2], scene.pusher_friction())
    butter = simulator("butter", "abs", Effects(), "grid")
    assert len(butter._pusher_pairs) == len(scene.convex_pieces(get_object("butter"))) > 1
    assert len(set(butter._support_pairs)) == scene.GRID_SUPPORTS


def test_stepped_simulation_without_physical_mechanisms_is_the_ideal_push():
    """Stepping the push one step at a time with every coefficient at its nominal value reproduces the rollout."""
    p = params("tri2", side=1, point=0.3, angle=0.349)
    ideal = simulate_push(p)
    stepped = simulate_push(p, conditions=conditions())
    for name in ("true_object_pose", "tip_pose", "ft_wrench"):
        np.testing.assert_allclose(getattr(stepped, name), getattr(ideal, name), atol=1e-9)


def test_motion_capture_noise_jitter_and_drops():
    p = params("tri1", side=1, point=0.3, angle=0.349)
    clean = simulate_push(p, conditions=conditions())
    tracked = simulate_push(p, conditions=conditions(tracking_noise_xy=5e-4, tracking_noise_yaw=0.01,
                                                     timestamp_jitter=3e-4, drop_rate=0.1))
    np.testing.assert_array_equal(tracked.true_object_pose, clean.true_object_pose)
    samples = len(clean.object_pose)
    kept = np.isin(np.round(tracked.object_pose[:, 0] * SAMPLE_RATE), np.arange(samples))
    assert kept.all()
    index = np.round(tracked.object_pose[:, 0] * SAMPLE_RATE).astype(int)
    assert 1 - len(index) / samples == pytest.approx(0.1, abs=0.03)
    assert index[0] == 0 and index[-1] == samples - 1
    error = tracked.object_pose - clean.object_pose[index]
    error[:, 3] = np.angle(np.exp(1j * error[:, 3]))
    np.testing.assert_allclose(error.std(axis=0), [3e-4, 5e-4, 5e-4, 0.01], rtol=0.15)


# Recording: deterministic, resumable, readable; the ideal profile is unchanged.

SELECTION = dict(objects=["rect1"], surfaces=["abs"], pushes=2, progress=False)
REALISTIC_RUN = dataset.RecordingConfig(seed=7, velocities=(20.0, 200.0), testbed=REALISTIC)


def files(root):
    return {path.relative_to(root).as_posix(): path.read_bytes() for path in sorted(root.rglob("*.h5"))}


def test_realistic_recording_is_deterministic_readable_and_refuses_other_testbeds(tmp_path):
    first = dataset.record_pushes(tmp_path / "first", settings=REALISTIC_RUN, workers=1, **SELECTION)
    dataset.record_pushes(tmp_path / "second", settings=REALISTIC_RUN, workers=2, **SELECTION)
    assert files(tmp_path / "first") == files(tmp_path / "second")
    ideal = dataset.record_pushes(tmp_path / "ideal", settings=dataclasses.replace(REALISTIC_RUN, testbed=IDEAL),
                                  workers=1, **SELECTION)
    assert [path.name for path in ideal.written] == [path.name for path in first.written]
    assert all(files(tmp_path / "first")[name] != content for name, content in files(tmp_path / "ideal").items())
    for path in ideal.written:
        with h5py.File(path, "r") as file:
            assert "pushjax_testbed" not in file.attrs and "pushjax_testbed_draw" not in file.attrs

    raws = [read_raw_push(path) for path in first.written]
    assert sum(len(raw.object_pose) for raw in raws) < sum(len(raw.tip_pose) for raw in raws)  # dropped samples
    for path, raw in zip(first.written, raws):
        assert Profile.from_dict(json.loads(raw.attributes["pushjax_testbed"])) == REALISTIC
        assert set(json.loads(raw.attributes["pushjax_testbed_draw"])) == {"object_friction_factor",
                                                                             "pusher_friction_factor"}
        assert raw.attributes["pushjax_pusher_friction"] == scene.pusher_friction()  # the nominal, what models see
        assert len(raw.object_pose) <= len(raw.tip_pose) == len(raw.ft_wrench)
        push = load_push(path)
        assert np.all(np.isfinite(push.object)) and np.all(np.diff(push.time) > 0)

    before = files(tmp_path / "first")
    other = dataclasses.replace(REALISTIC, drop_rate=0.0)
    with pytest.raises(dataset.OutDirConflictError, match=r" testbed \(drop_rate 0.01 there, 0.0 now\)"):
        dataset.record_pushes(tmp_path / "first", settings=dataclasses.replace(REALISTIC_RUN, testbed=other), workers=1,
                              **SELECTION)
    with pytest.raises(dataset.OutDirConflictError, match=" testbed "):
        dataset.record_pushes(tmp_path / "ideal", settings=REALISTIC_RUN, workers=1, **SELECTION)
    assert files(tmp_path / "first") == before


def test_a_manifest_without_testbed_counts_as_ideal(tmp_path):
    run = dict(objects=["rect1"], surfaces=["abs"], pushes=1, workers=1, progress=False)
    ideal = dataset.RecordingConfig(seed=1, velocities=(50.0,), testbed=IDEAL)
    dataset.record_pushes(tmp_path, settings=ideal, **run)
    manifest = tmp_path / dataset.MANIFEST_NAME
    content = json.loads(manifest.read_text())
    del content["settings"]["testbed"]
    manifest.write_text(json.dumps(content))
    assert len(dataset.record_pushes(tmp_path, settings=ideal, **run).skipped) == 1
    with pytest.raises(dataset.OutDirConflictError, match=" testbed "):
        dataset.record_pushes(tmp_path, settings=dataclasses.replace(ideal, testbed=REALISTIC), **run)


def test_lynch_model_runs_on_realistic_files_and_errs_more(tmp_path):
    """Windows of 0.5 s from recorded files, annotated and predicted as the quasi-static baseline does: finite on
    realistic files, and further from the recorded motion than on ideal files of the same pushes."""
    run = dict(objects=["rect1"], surfaces=["abs"], pushes=3, workers=1, progress=False)
    errors = {}
    for name, profile in (("ideal", IDEAL), ("realistic", REALISTIC)):
        settings = dataset.RecordingConfig(seed=2, velocities=(20.0,), testbed=profile)
        summary = dataset.record_pushes(tmp_path / name, settings=settings, **run)
        shape = get_object("rect1")
        simulated, predicted = [], []
        for path in summary.written:
            push = load_push(path)
            starts = np.arange(0, len(push.time) - 250, 60)
            pose0, pose1 = push.object[starts], push.object[starts + 125]
            tip0 = push.tip[starts, :2]
            state = annotate(shape, pose0, tip0, push.tip[starts + 125, :2] - tip0)
            keep = np.asarray(state.touches)
            prediction = np.asarray(lynch.predict(state.contact_rel_com, state.normal, state.action_from_contact,
                                                  limit_surface_ratio(shape), scene.pusher_friction()))
            assert np.all(np.isfinite(prediction))
            com = planar.centre_of_mass
            simulated.append((com(shape.centroid, pose1) - com(shape.centroid, pose0))[keep])
            predicted.append(prediction[keep, :2])
        simulated, predicted = np.concatenate(simulated), np.concatenate(predicted)
        assert len(simulated) >= 10
        errors[name] = np.median(np.linalg.norm(predicted - simulated, axis=1)) / np.median(
            np.linalg.norm(simulated, axis=1))
    assert errors["realistic"] > errors["ideal"], errors
