"""Tests for pushjax.mit.files: file names, HDF5 round trips, cleaning, resampling and iteration."""

import concurrent.futures
import json
import logging
import math
import multiprocessing
import pickle
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pushjax.mit import files
from pushjax.mit.files import PushFileError, PushParams

PARAMS = PushParams(surface="abs", shape="rect1", acceleration=0.0, velocity=20.0, side=0, point=0.7, angle=-0.175,
                    repetition=4)
CANONICAL_NAME = "motion_surface=abs_shape=rect1_a=0_v=20_i=0.000_s=0.700_t=-0.175_rep=0004.h5"


def linear_push(n=26, rate=250.0, offset=0.0):
    """Three streams of a straight push along x at 20 mm/s, sampled at `rate` Hz from `offset` s."""
    t = offset + np.arange(n) / rate
    tip = np.stack([t, 0.02 * t - 0.05, np.zeros(n), np.zeros(n)], axis=-1)
    obj = np.stack([t, 0.02 * t, np.zeros(n), 0.1 * t], axis=-1)
    wrench = np.stack([t, np.full(n, 1.5), np.zeros(n), np.full(n, 0.01)], axis=-1)
    return tip, obj, wrench


def write_file(path, **datasets):
    """Writes a hand-made file with h5py directly (for content the writer refuses to write)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "w") as file:
        for name, data in datasets.items():
            file.create_dataset(name, data=data)
    return path


# File names.

def test_canonical_name_and_round_trip():
    assert files.push_file_name(PARAMS) == CANONICAL_NAME
    assert files.parse_push_file_name(CANONICAL_NAME) == PARAMS
    single = PushParams("delrin", "tri2", 0.0, 150.0, 2, 0.0, 0.349)
    assert files.push_file_name(single) == "motion_surface=delrin_shape=tri2_a=0_v=150_i=2.000_s=0.000_t=0.349.h5"
    assert files.parse_push_file_name(files.push_file_name(single)) == single


def test_parse_accepts_any_float_formatting_and_paths():
    name = "dir/motion_surface=pu_shape=ellip2_a=100.0_v=1.0e1_i=3_s=.5_t=-1.75E-1_rep=12.h5"
    assert files.parse_push_file_name(Path(name)) == PushParams("pu", "ellip2", 100.0, 10.0, 3, 0.5, -0.175, 12)


def test_name_rounds_to_three_decimals_without_negative_zero():
    params = PushParams("abs", "hex", 0.0, 12.5, 1, 0.12345, -0.0001)
    assert files.push_file_name(params) == "motion_surface=abs_shape=hex_a=0_v=12.5_i=1.000_s=0.123_t=0.000.h5"


def test_velocity_and_acceleration_in_si():
    params = PushParams("abs", "rect1", 1500, np.float32(20.0), np.int64(0), 0.5, 0.0)
    assert type(params.velocity) is float and type(params.side) is int and type(params.acceleration) is float
    assert params.velocity_si == pytest.approx(0.02)
    assert params.acceleration_si == pytest.approx(1.5)


@settings(max_examples=50, deadline=None)
@given(
    acceleration=st.integers(0, 5000), velocity=st.integers(1, 500), side=st.integers(0, 20),
    point=st.integers(0, 1000), angle=st.integers(-1570, 1570), repetition=st.none() | st.integers(0, 9999),
)
def test_name_round_trip_property(acceleration, velocity, side, point, angle, repetition):
    params = PushParams("plywood", "butter", float(acceleration), float(velocity), side, point / 1000,
                        angle / 1000, repetition)
    assert files.parse_push_file_name(files.push_file_name(params)) == params


@pytest.mark.parametrize("name", [
    "motion_surface=abs_shape=rect1_a=0_v=20_i=0.000_s=0.700.h5",  # no angle
    "motion_surface=abs_shape=rect1_a=0_v=20_i=0.000_s=0.700_t=0.000.json",  # not .h5
    "motion_surface=abs_shape=rect1_a=0_v=fast_i=0.000_s=0.700_t=0.000.h5",  # not a number
    "motion_surface=abs_shape=rect1_a=0_v=20_i=0.500_s=0.700_t=0.000.h5",  # side not integral
    "motion_surface=abs_shape=rect1_a=0_v=20_i=0.000_s=1.700_t=0.000.h5",  # point outside 0..1
    "motion_surface=abs_shape=rect1_a=0_v=0_i=0.000_s=0.700_t=0.000.h5",  # zero velocity
    "motion_surface=abs_shape=rect1_a=0_v=20_i=0.000_s=0.700_t=nan.h5",
    "motion_surface=abs_shape=rect1_a=0_v=1e999_i=0.000_s=0.700_t=0.000.h5",  # infinite
    "motion_surface=abs_shape=rect1_a=0_v=20_i=0.000_s=0.700_t=0.000_rep=x.h5",
    "surface=abs_shape=rect1_a=0_v=20_i=0.000_s=0.700_t=0.000.h5",
])
def test_malformed_names_raise_naming_the_file(name):
    with pytest.raises(ValueError, match=name.replace(".", r"\.")) as error:
        files.parse_push_file_name(name)
    assert error.value.reason == "unparseable file name"


@pytest.mark.parametrize("kwargs", [
    dict(surface="a_b"), dict(shape=""), dict(side=-1), dict(side=1.0), dict(velocity=-1.0),
    dict(angle=math.inf), dict(point=-0.1), dict(repetition=-2),
])
def test_invalid_params_raise(kwargs):
    fields = dict(surface="abs", shape="rect1", acceleration=0.0, velocity=20.0, side=0, point=0.5, angle=0.0)
    with pytest.raises(ValueError, match=next(iter(kwargs))):
        PushParams(**(fields | kwargs))


def test_push_file_path(tmp_path):
    assert files.push_file_path(tmp_path, PARAMS) == tmp_path / "abs" / "rect1" / CANONICAL_NAME


# Writing and raw reading.

def test_raw_round_trip_is_exact_and_adds_nothing_without_attributes(tmp_path):
    rng = np.random.default_rng(0)
    tip, obj, wrench = (np.column_stack([np.sort(rng.uniform(0, 1, n)), rng.normal(size=(n, 3))])
                        for n in (30, 31, 29))
    path = files.write_push(files.push_file_path(tmp_path, PARAMS), PARAMS, tip, obj, wrench)
    raw = files.read_raw_push(path)
    assert raw.path == path and raw.params == PARAMS and raw.attributes == {}
    np.testing.assert_array_equal(raw.tip_pose, tip)
    np.testing.assert_array_equal(raw.object_pose, obj)
    np.testing.assert_array_equal(raw.ft_wrench, wrench)
    assert raw.declared_effects is None
    with h5py.File(path) as file:
        assert sorted(file) == ["ft_wrench", "object_pose", "tip_pose"]
        assert len(file.attrs) == 0
        assert all(file[name].dtype == np.dtype("<f8") for name in file)
    assert [p.name for p in path.parent.iterdir()] == [CANONICAL_NAME]  # no partial file left behind


def test_attributes_round_trip(tmp_path):
    effects = {"floor_friction_patch": {"mu": 0.4}}
    attributes = {"pushjax_effects": json.dumps(effects), "pushjax_version": "0.1.0", "seed": 7, "noisy": True,
                  "gain": 0.5, "offsets": np.array([1.0, 2.0])}
    path = files.write_push(tmp_path / "x.h5", None, *linear_push(), attributes=attributes)
    raw = files.read_raw_push(path)
    assert raw.params is None
    assert list(raw.attributes) == sorted(attributes)
    assert {k: v for k, v in raw.attributes.items() if k != "offsets"} == {
        k: v for k, v in attributes.items() if k != "offsets"}
    assert type(raw.attributes["seed"]) is int and type(raw.attributes["noisy"]) is bool
    np.testing.assert_array_equal(raw.attributes["offsets"], [1.0, 2.0])
    assert raw.declared_effects == effects
    assert files.load_push(path).declared_effects == effects


def test_writer_is_deterministic(tmp_path):
    tip, obj, wrench = linear_push()
    attributes = {"pushjax_effects": "[]", "seed": 3}
    first = files.write_push(tmp_path / "a" / CANONICAL_NAME, PARAMS, tip, obj, wrench, attributes)
    second = files.write_push(tmp_path / "b" / CANONICAL_NAME, PARAMS, tip, obj, wrench, dict(reversed(
        attributes.items())))
    first_bytes = first.read_bytes()
    time.sleep(1.1)  # HDF5 time stamps have 1 s resolution: any stored time would now differ.
    files.write_push(first, PARAMS, tip, obj, wrench, attributes)  # overwrite in place
    assert first_bytes == second.read_bytes() == first.read_bytes()


def _write_when_all_are_ready(task):
    """Worker: signals ready, waits for the other writers, then writes `path` `writes` times."""
    path, ready_dir, writer, writers, writes = task
    (ready_dir / str(writer)).touch()
    while len(list(ready_dir.iterdir())) < writers:
        time.sleep(0.001)
    tip, obj, wrench = linear_push(n=2000)
    for _ in range(writes):
        files.write_push(path, PARAMS, tip, obj, wrench, {"seed": 3})


def test_concurrent_writers_of_one_file_never_collide(tmp_path):
    path = files.push_file_path(tmp_path / "shared", PARAMS)
    ready = tmp_path / "ready"
    ready.mkdir()
    writers = 2
    with concurrent.futures.ProcessPoolExecutor(writers, mp_context=multiprocessing.get_context("spawn")) as pool:
        list(pool.map(_write_when_all_are_ready, [(path, ready, writer, writers, 30) for writer in range(writers)]))
    alone = files.write_push(tmp_path / "alone" / CANONICAL_NAME, PARAMS, *linear_push(n=2000), {"seed": 3})
    assert path.read_bytes() == alone.read_bytes()
    assert [p.name for p in path.parent.iterdir()] == [CANONICAL_NAME]  # no temporary file left behind


@pytest.mark.parametrize("change, message", [
    (lambda s: s[:, :3], r"tip_pose must have shape \[N, 4\]"),
    (lambda s: np.where(np.arange(4) == 1, np.nan, s), "NaN"),
    (lambda s: np.column_stack([np.zeros(len(s)), s[:, 1:]]), "fewer than 2 distinct time stamps"),
])
def test_writer_validates_streams(tmp_path, change, message):
    tip, obj, wrench = linear_push()
    with pytest.raises(ValueError, match=message):
        files.write_push(tmp_path / "x.h5", None, change(tip), obj, wrench)
    assert not list(tmp_path.iterdir())


def test_writer_checks_name_and_attributes(tmp_path):
    with pytest.raises(ValueError, match="does not end in the file name of params"):
        files.write_push(tmp_path / "x.h5", PARAMS, *linear_push())
    with pytest.raises(ValueError, match="attribute 'effects' must be"):
        files.write_push(tmp_path / "x.h5", None, *linear_push(), attributes={"effects": {"a": 1}})


def test_truncated_file_raises_naming_it(tmp_path):
    path = files.write_push(files.push_file_path(tmp_path, PARAMS), PARAMS, *linear_push(n=500))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    for read in (files.read_raw_push, files.load_push):
        with pytest.raises(PushFileError, match=str(path).replace(".", r"\.")) as error:
            read(path)
        assert error.value.reason == "unreadable file" and error.value.path == path


@pytest.mark.parametrize("datasets, reason", [
    (dict(tip_pose=np.zeros((5, 4)), object_pose=np.zeros((5, 4))), "missing dataset"),
    (dict(tip_pose=np.ones((5, 3)), object_pose=np.ones((5, 3)), ft_wrench=np.ones((5, 3))), "wrong shape"),
    (dict(tip_pose=np.array([b"a", b"b"]), object_pose=np.ones((5, 4)), ft_wrench=np.ones((5, 4))),
     "not numeric"),
])
def test_malformed_files_raise_with_reason(tmp_path, datasets, reason):
    path = write_file(tmp_path / "bad.h5", **datasets)
    with pytest.raises(PushFileError, match=f"{path}: {reason}") as error:
        files.read_raw_push(path)
    assert error.value.reason == reason


def test_nan_and_single_time_stamp_files_raise(tmp_path):
    tip, obj, wrench = linear_push()
    nan_obj = obj.copy()
    nan_obj[3, 2] = np.nan
    with pytest.raises(PushFileError, match="non-finite values"):
        files.read_raw_push(write_file(tmp_path / "nan.h5", tip_pose=tip, object_pose=nan_obj, ft_wrench=wrench))
    constant_time = wrench.copy()
    constant_time[:, 0] = 0.5
    with pytest.raises(PushFileError, match="too few time stamps"):
        files.load_push(write_file(tmp_path / "t.h5", tip_pose=tip, object_pose=obj, ft_wrench=constant_time))


@pytest.mark.parametrize("change, reason, message", [
    (dict(object_pose=lambda pose: np.where(np.arange(len(pose))[:, None] == 3, np.nan, pose)), "non-finite values",
     "object_pose holds NaN or infinite values"),
    (dict(tip_pose=lambda pose: pose[:, :3]), "wrong shape", r"tip_pose must have shape \[N, 4\], got \(26, 3\)"),
    (dict(ft_wrench=lambda pose: pose[None]), "wrong shape", r"ft_wrench must have shape \[N, 4\], got \(1, 26, 4\)"),
])
def test_a_bad_pose_is_one_line_naming_the_file_and_the_field(tmp_path, change, reason, message):
    streams = dict(zip(("tip_pose", "object_pose", "ft_wrench"), linear_push()))
    streams.update({name: damage(streams[name]) for name, damage in change.items()})
    path = write_file(tmp_path / "bad.h5", **streams)
    for read in (files.read_raw_push, files.load_push):
        with pytest.raises(PushFileError, match=f"^{path}: {reason}: {message}$") as error:
            read(path)
        assert "\n" not in str(error.value) and error.value.path == path


def test_push_file_errors_cross_process_boundaries(tmp_path):
    """A worker's PushFileError (a dataset build's process pool) reaches the parent whole, not as a broken pool."""
    error = PushFileError(tmp_path / "x.h5", "unreadable file", "corrupt or truncated HDF5 file (eof)")
    copy = pickle.loads(pickle.dumps(error))
    assert (type(copy), str(copy), copy.path, copy.reason, copy.detail) == (
        PushFileError, str(error), error.path, error.reason, error.detail)
    truncated = files.write_push(files.push_file_path(tmp_path, PARAMS), PARAMS, *linear_push(n=500))
    truncated.write_bytes(truncated.read_bytes()[:300])
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        with pytest.raises(PushFileError, match=f"^{truncated}: unreadable file: corrupt or truncated") as raised:
            pool.submit(files.load_push, truncated).result()
    assert raised.value.reason == "unreadable file" and raised.value.path == truncated


def test_missing_file_is_not_a_data_error(tmp_path):
    with pytest.raises(FileNotFoundError):
        files.read_raw_push(tmp_path / "absent.h5")


# Cleaning and resampling.

def test_cleaning_drops_duplicates_sorts_and_unwraps_yaw(tmp_path):
    t = np.arange(6) * 0.004
    yaw = np.array([3.0, 3.1, -3.1, -3.0, -2.9, -2.8])  # crosses +π: a -2π jump between rows 1 and 2
    x = 0.01 * np.arange(6)
    clean_object = np.column_stack([t, x, -x, yaw])
    # Stored: rows shuffled, row 2 repeated with other values after its first occurrence.
    stored_object = clean_object[[3, 0, 2, 5, 1, 4]]
    stored_object = np.insert(stored_object, 4, [t[2], 9.0, 9.0, 9.0], axis=0)
    tip, _, wrench = linear_push(n=6)
    stored_wrench = np.concatenate([wrench[3:], wrench[:3], wrench[:1] + [0, 5.0, 5.0, 5.0]])  # late duplicate
    path = files.write_push(tmp_path / "x.h5", None, tip, stored_object, stored_wrench)

    push = files.load_push(path, frequency=250.0)
    np.testing.assert_allclose(push.time, t, atol=1e-15)
    np.testing.assert_allclose(push.object[:, :2], clean_object[:, 1:3], atol=1e-12)
    np.testing.assert_allclose(push.object[:, 2], [3.0, 3.1, 2 * np.pi - 3.1, 2 * np.pi - 3.0, 2 * np.pi - 2.9,
                                                   2 * np.pi - 2.8], atol=1e-12)
    np.testing.assert_allclose(push.wrench, wrench[:, 1:], atol=1e-12)
    np.testing.assert_allclose(push.tip, tip[:, 1:], atol=1e-12)
    # The raw reader leaves the stored rows alone.
    np.testing.assert_array_equal(files.read_raw_push(path).object_pose, stored_object)


def test_resampling_a_linear_signal_on_the_overlap(tmp_path):
    tip, _, _ = linear_push(n=100, rate=240.0, offset=0.013)  # 0.013 .. 0.4255 s
    _, obj, _ = linear_push(n=130, rate=260.0, offset=0.0)  # 0 .. 0.4962 s
    _, _, wrench = linear_push(n=90, rate=200.0, offset=0.02)  # 0.02 .. 0.465 s
    path = files.write_push(tmp_path / "x.h5", None, tip, obj, wrench)
    push = files.load_push(path, frequency=100.0)
    start, end = 0.02, 0.013 + 99 / 240.0
    assert push.time.shape == (math.floor((end - start) * 100.0) + 1,)
    np.testing.assert_allclose(push.time, np.arange(push.time.size) / 100.0)
    query = start + push.time
    np.testing.assert_allclose(push.tip, np.column_stack([0.02 * query - 0.05, 0 * query, 0 * query]), atol=1e-14)
    np.testing.assert_allclose(push.object, np.column_stack([0.02 * query, 0 * query, 0.1 * query]), atol=1e-14)
    np.testing.assert_allclose(push.wrench[:, 0], 1.5)
    assert push.tip.shape == push.object.shape == push.wrench.shape == (push.time.size, 3)
    assert not push.time.flags.writeable and not push.object.flags.writeable


def test_streams_without_overlap_raise(tmp_path):
    tip, obj, wrench = linear_push(n=10)
    late_wrench = wrench + [1.0, 0, 0, 0]
    path = files.write_push(tmp_path / "x.h5", None, tip, obj, late_wrench)
    with pytest.raises(PushFileError, match="no time overlap"):
        files.load_push(path)
    with pytest.raises(ValueError, match="frequency"):
        files.load_push(path, frequency=0.0)


def test_zero_initial_pose(tmp_path):
    n = 11
    t = np.arange(n) / 250.0
    x0, y0, yaw0 = 0.1, 0.2, np.pi / 2
    # The object slides along world +y (its own +x after the rotation) while turning slowly.
    obj = np.column_stack([t, np.full(n, x0), y0 + 0.02 * t, yaw0 + 0.1 * t])
    tip = np.column_stack([t, np.full(n, x0), y0 - 0.05 + 0.02 * t, np.full(n, yaw0)])
    wrench = np.column_stack([t, np.zeros(n), np.full(n, 2.0), np.full(n, 0.03)])  # pushing along world +y
    path = files.write_push(tmp_path / "x.h5", None, tip, obj, wrench)

    push = files.load_push(path, zero_initial_pose=True)
    np.testing.assert_allclose(push.object[0], [0, 0, 0], atol=1e-15)
    np.testing.assert_allclose(push.object, np.column_stack([0.02 * t, 0 * t, 0.1 * t]), atol=1e-15)
    np.testing.assert_allclose(push.tip, np.column_stack([0.02 * t - 0.05, 0 * t, 0 * t]), atol=1e-15)
    np.testing.assert_allclose(push.wrench, np.column_stack([np.full(n, 2.0), 0 * t, np.full(n, 0.03)]), atol=1e-15)
    # The world-frame version is untouched, and distances are preserved.
    world = files.load_push(path)
    np.testing.assert_allclose(world.object, obj[:, 1:], atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(push.tip[:, :2] - push.object[:, :2], axis=-1),
                               np.linalg.norm(world.tip[:, :2] - world.object[:, :2], axis=-1), atol=1e-15)


# Iterating over a dataset root.

@pytest.fixture
def dataset_root(tmp_path):
    tip, obj, wrench = linear_push()
    for surface, shape, velocity, acceleration in [
        ("abs", "rect1", 20, 0), ("abs", "rect1", 50, 0), ("abs", "tri1", 20, 0), ("delrin", "rect1", 20, 0),
        ("abs", "rect1", 20, 1500),
    ]:
        params = PushParams(surface, shape, acceleration, velocity, 0, 0.5, 0.0)
        files.write_push(files.push_file_path(tmp_path, params), params, tip, obj, wrench)
    truncated = files.write_push(files.push_file_path(tmp_path, PARAMS), PARAMS, tip, obj, wrench)
    truncated.write_bytes(truncated.read_bytes()[:300])
    missing = PushParams("abs", "rect1", 0, 20, 1, 0.5, 0.0)
    write_file(files.push_file_path(tmp_path, missing), tip_pose=tip, object_pose=obj)
    (tmp_path / "abs" / "rect1" / "notes.h5").write_bytes(b"not a push")
    (tmp_path / "abs" / "rect1" / "README.txt").write_text("ignored")
    return tmp_path


def test_iter_pushes_yields_sorted_and_reports_skipped(dataset_root, caplog):
    pushes = files.iter_pushes(dataset_root)
    with caplog.at_level(logging.INFO):
        loaded = list(pushes)
    names = [push.path.relative_to(dataset_root).as_posix() for push in loaded]
    assert names == sorted(names) and len(names) == 5
    assert {reason: [p.name for p in paths] for reason, paths in pushes.skipped.items()} == {
        "missing dataset": ["motion_surface=abs_shape=rect1_a=0_v=20_i=1.000_s=0.500_t=0.000.h5"],
        "unparseable file name": ["notes.h5"],
        "unreadable file": [CANONICAL_NAME],
    }
    assert pushes.n_skipped == 3 and pushes.n_filtered == 0
    assert "5 pushes yielded, 0 filtered out, 3 skipped (missing dataset: 1, unparseable file name: 1, " \
           "unreadable file: 1); the first that failed to load: " \
           f"{dataset_root}/abs/rect1/{CANONICAL_NAME}: unreadable file: corrupt or truncated" in caplog.text
    # A second pass yields the same pushes and the same report.
    assert [push.path for push in pushes] == [push.path for push in loaded] and pushes.n_skipped == 3


def test_iter_pushes_filters(dataset_root):
    def kept(**filters):
        return sorted((p.params.surface, p.params.shape, p.params.velocity, p.params.acceleration)
                      for p in files.iter_pushes(dataset_root, **filters))

    assert kept(objects={"tri1"}) == [("abs", "tri1", 20.0, 0.0)]
    assert kept(surfaces=["delrin"]) == [("delrin", "rect1", 20.0, 0.0)]
    assert kept(objects={"rect1"}, surfaces={"abs"}, velocities=[50.0000001]) == [("abs", "rect1", 50.0, 0.0)]
    assert kept(accelerations=[1500]) == [("abs", "rect1", 20.0, 1500.0)]
    assert kept(velocities=[20], accelerations=[0], surfaces={"abs"}) == [
        ("abs", "rect1", 20.0, 0.0), ("abs", "tri1", 20.0, 0.0)]
    pushes = files.iter_pushes(dataset_root, objects={"tri1"}, zero_initial_pose=True, frequency=100.0)
    (push,) = list(pushes)
    assert pushes.n_filtered == 6 and pushes.n_skipped == 1  # only the unparseable name is never filtered
    np.testing.assert_allclose(push.time[1], 0.01)


def test_iter_pushes_rejects_bad_arguments(dataset_root):
    with pytest.raises(ValueError, match="not a directory"):
        files.iter_pushes(dataset_root / "absent")
    with pytest.raises(ValueError, match="objects must be a collection"):
        files.iter_pushes(dataset_root, objects="rect1")
    with pytest.raises(ValueError, match="frequency"):
        files.iter_pushes(dataset_root, frequency=-1.0)
