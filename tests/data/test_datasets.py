"""The TFDS push datasets at smoke scale: fields, composition, splits, determinism and physical consistency."""

import dataclasses
import filecmp
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from pushjax.data import configs
from pushjax.data.builder import DatasetFolderError, IncompleteRawDirError, PushEffects, build, load
from pushjax.data.examples import ALL_FIELDS
from pushjax.data.schema import FIELDS
from pushjax.geometry import OBJECT_NAMES, THICKNESS
from pushjax.physics import lynch
from pushjax.render import free_camera, project, top_down_camera

QUASI_STATIC_BOUND = 0.25
"""Bound on median |predicted - simulated| / median |simulated| of Lynch's model on the true state of the contact
examples: the ideal testbed's quasi-static agreement (tests/sim); the realistic smoke data measure about 0.12."""


@pytest.fixture(scope="session")
def smoke(smoke_data):
    """experiment -> split -> data source of the suite's smoke datasets (default testbed), built on first request."""
    return lambda experiment: load(experiment, "smoke", data_dir=smoke_data(experiment))


def _column(source, name):
    return np.array([source[i][name] for i in range(len(source))])


def _read(source, indices):
    """{field: [len(indices), ...] array} of the examples at `indices`, with the dtypes of `ALL_FIELDS`."""
    examples = source.__getitems__([int(index) for index in indices])
    return {name: np.asarray([example[name] for example in examples], ALL_FIELDS[name].dtype) for name in examples[0]}


def _all(source):
    return _read(source, range(len(source)))


def test_fields_shapes_and_dtypes(smoke):
    sources = smoke("data_efficiency")
    assert set(sources) == {"train", "validation", "test"}
    size = configs.get_config("data_efficiency", "smoke").image_size
    for source in sources.values():
        example = source[0]
        assert set(example) == set(ALL_FIELDS) and set(FIELDS) <= set(example)
        batch = _read(source, range(8))
        for name, field in ALL_FIELDS.items():
            shape = tuple(size if dim in ("H", "W") else dim for dim in field.shape)
            assert batch[name].shape == (8, *shape), name
            assert batch[name].dtype == field.dtype, name
            assert np.all(np.isfinite(batch[name])), name


def test_no_contact_share_is_a_third(smoke):
    flags = np.concatenate([_column(source, "contact_flag") for source in smoke("data_efficiency").values()])
    assert abs(np.mean(flags == 0) - 1 / 3) <= 0.05


def test_no_contact_examples_are_consistent(smoke):
    data = _all(smoke("data_efficiency")["train"])
    moved = data["pusher_moved"] == 1
    assert np.any(moved)
    assert np.all(data["contact_flag"][moved] == 0)
    np.testing.assert_array_equal(data["motion"][moved], 0.0)
    none = data["contact_flag"] == 0
    for name in ("contact", "normal", "action_from_contact", "push_velocity"):
        np.testing.assert_array_equal(data[name][none], 0.0)
    np.testing.assert_allclose(np.linalg.norm(data["normal"][~none], axis=1), 1.0, atol=1e-5)
    # Several start times per sequence, some windows hold shorter pushes than the full horizon.
    full = 0.5 * 20e-3
    assert np.any(np.linalg.norm(data["action"], axis=1) < 0.9 * full)
    assert len(np.unique(data["start_time"])) > len(np.unique(data["sequence_id"]))


@pytest.mark.parametrize("experiment", ["data_efficiency", "new_pushes", "velocities", "objects", "viewpoint"])
def test_splits_are_disjoint_by_sequence(smoke, experiment):
    sources = smoke(experiment)
    plan = configs.plan_splits(configs.get_config(experiment, "smoke"), "/unused")
    sequences = {name: set(_column(source, "sequence_id").tolist()) for name, source in sources.items()}
    assert sequences == {name: set(ids) for name, ids in plan.splits.items()}
    training = [name for name in sequences if name.startswith("train")]
    held_out = [name for name in sequences if not name.startswith("train")]
    for first in held_out:
        for second in training + [name for name in held_out if name != first]:
            assert not sequences[first] & sequences[second], (first, second)
    if experiment in ("data_efficiency", "new_pushes", "viewpoint"):
        assert not sequences["train"] & set().union(*(sequences[name] for name in held_out))


def test_new_pushes_test_holds_only_held_out_angles_and_points(smoke):
    sources = smoke("new_pushes")
    config = configs.get_config("new_pushes", "smoke")
    test_angles = np.radians(configs.NEW_PUSH_TEST_ANGLES_DEG)

    def held_out(data):
        angle = np.any(np.abs(data["push_angle"][:, None] - test_angles) < 1e-3, axis=1)
        point = np.array([point_id in configs.held_out_contact_points(OBJECT_NAMES[obj], config)
                          for obj, point_id in zip(data["object_id"], data["contact_point_id"])])
        return angle | point

    assert np.all(held_out(_all(sources["test"])))
    for name in ("train", "validation"):
        assert not np.any(held_out(_all(sources[name])))


def test_velocity_and_object_compositions(smoke):
    sources = smoke("velocities")
    for velocity in configs.TEST_VELOCITIES:
        assert set(_column(sources[f"test_{velocity:g}"], "velocity")) == {velocity}
    counts = {name: len(sources[name]) for name in configs.VELOCITY_TRAIN_SETS}
    assert len(set(counts.values())) == 1
    for name, velocities in configs.VELOCITY_TRAIN_SETS.items():
        assert set(_column(sources[name], "velocity")) == set(velocities)

    sources = smoke("objects")
    assert len({len(sources[name]) for name in configs.OBJECT_TRAIN_SETS}) == 1
    for name, objects in {**configs.OBJECT_TRAIN_SETS, **configs.OBJECT_TEST_SETS}.items():
        assert {OBJECT_NAMES[i] for i in _column(sources[name], "object_id")} == set(objects), name


def test_same_seed_gives_same_bytes(smoke_data, tmp_path):
    # `objects`, the smallest smoke dataset with several splits (225 examples; its training splits share
    # sequences), rebuilt by 2 workers from the suite's raw cache against the suite's build by one.
    data_dir = smoke_data("objects")
    build("objects", "smoke", data_dir=tmp_path, workers=2, progress=False,
          raw_dir=data_dir / "push_effects_raw" / "realistic" / "seed0")
    version = str(PushEffects.VERSION)
    first = data_dir / "push_effects" / "objects_smoke" / version
    second = tmp_path / "push_effects" / "objects_smoke" / version
    files = sorted(path.name for path in first.glob("*.array_record-*"))
    assert files and files == sorted(path.name for path in second.glob("*.array_record-*"))
    match, mismatch, errors = filecmp.cmpfiles(first, second, files, shallow=False)
    assert match == files, (mismatch, errors)


def test_ground_truth_state_reproduces_motion(smoke):
    data = _all(smoke("data_efficiency")["train"])
    touching = data["contact_flag"] == 1
    predicted = np.asarray(lynch.predict(data["contact"], data["normal"], data["action_from_contact"], data["l"],
                                         data["mu"], data["contact_flag"]))[touching, :2]
    simulated = data["motion"][touching, :2]
    error = np.median(np.linalg.norm(predicted - simulated, axis=1))
    assert error / np.median(np.linalg.norm(simulated, axis=1)) <= QUASI_STATIC_BOUND
    stage1, _ = lynch.effective_push_velocity(data["contact"], data["normal"], data["action_from_contact"],
                                              data["l"], data["mu"])
    np.testing.assert_allclose(data["push_velocity"], stage1, atol=1e-7)


def test_pixels_and_depth_agree_with_the_camera(smoke):
    data = _all(smoke("data_efficiency")["test"])
    camera = top_down_camera(64, 64)
    lift = np.full((len(data["object_pos"]), 1), THICKNESS)
    pixels = np.asarray(project(np.concatenate([data["object_pos"], lift], 1), camera)[0])
    np.testing.assert_allclose(data["object_pixel"], pixels, atol=1e-3)
    np.testing.assert_allclose(data["camera_extrinsics"][0], camera.world_from_camera, atol=1e-6)
    np.testing.assert_allclose(data["camera_intrinsics"][0], [camera.fx, camera.fy, camera.cx, camera.cy])
    # The depth image sees the object's top face at its centre of mass (pusher never covers it).
    rows, columns = np.floor(data["object_pixel"][:, ::-1]).astype(int).T
    seen = data["depth"][np.arange(len(rows)), rows, columns, 0]
    assert np.mean(np.abs(seen - (0.4 - THICKNESS)) < 1e-3) > 0.9
    # Scene transforms move the recorded scene: the object lands in the configured square, the pusher in view.
    assert np.all(np.abs(data["object_pos"]) <= configs.get_config("data_efficiency", "smoke").max_translation)
    for pusher in (data["pusher_pos"], data["pusher_pos"] + data["action"]):
        pixels = np.asarray(project(np.concatenate([pusher, lift], 1), camera)[0])
        assert np.all((pixels > 0) & (pixels < 64))


def test_viewpoint_point_clouds(smoke):
    data = _all(smoke("viewpoint")["test"])
    camera = free_camera(64, 64)
    np.testing.assert_allclose(data["camera_extrinsics"][0], camera.world_from_camera, atol=1e-6)
    cloud = data["point_cloud"]
    on_table = np.abs(cloud[..., 2]) < 1e-3
    assert on_table.mean() > 0.5
    assert np.any(np.abs(cloud[..., 2] - THICKNESS) < 1e-3)  # object top faces
    np.testing.assert_allclose(data["object_pixel"], np.asarray(project(np.concatenate(
        [data["object_pos"], np.full((len(cloud), 1), THICKNESS)], 1), camera)[0]), atol=1e-2)


def test_repeated_push_under_scene_transforms(smoke):
    data = _all(smoke("repeated")["test"])
    assert len(data["depth"]) == configs.get_config("repeated", "smoke").examples_per_sequence
    assert len(np.unique(data["sequence_id"])) == 1 and np.all(data["contact_flag"] == 1)
    assert len(np.unique(data["scene_transform"][:, 0, 2])) == len(data["depth"])
    # Undoing each scene rotation gives the same recorded motion.
    angle = np.arctan2(data["scene_transform"][:, 1, 0], data["scene_transform"][:, 0, 0])
    cos, sin = np.cos(-angle), np.sin(-angle)
    motion = data["motion"]
    recorded = np.stack([cos * motion[:, 0] - sin * motion[:, 1], sin * motion[:, 0] + cos * motion[:, 1]], 1)
    np.testing.assert_allclose(recorded, np.broadcast_to(recorded[0], recorded.shape), atol=1e-6)
    assert np.linalg.norm(recorded[0]) > 1e-3


def test_loading_never_imports_tensorflow(smoke_data):
    data_dir = smoke_data("data_efficiency")
    script = textwrap.dedent(f"""
        import sys
        import pushjax.data as data
        sources = data.load("data_efficiency", "smoke", data_dir={str(data_dir)!r})
        examples = sources["train"].__getitems__(list(range(16)))
        assert len(examples) == 16 and examples[0]["depth"].shape == (64, 64, 1)
        import tensorflow_datasets as tfds
        source = tfds.data_source("push_effects/data_efficiency_smoke", data_dir={str(data_dir)!r},
                                  split="test", download=False)
        assert len(source) > 0 and source[0]["depth"].shape == (64, 64, 1)
        assert "tensorflow" not in sys.modules, "tensorflow was imported"
        print("ok")
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            env={**os.environ, "MUJOCO_GL": "egl"})
    assert result.returncode == 0 and result.stdout.strip().endswith("ok"), result.stderr[-3000:]


def test_cli_builds_an_ideal_dataset_beside_the_default_realistic_one(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "experiments.build_dataset", "--experiment=repeated", "--scale=smoke",
         f"--data_dir={tmp_path}", "--workers=1", "--testbed=ideal"],
        capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2])
    assert result.returncode == 0, result.stderr[-3000:]
    version = str(PushEffects.VERSION)
    assert f"repeated_smoke_ideal: test 24 examples in {tmp_path}/push_effects/repeated_smoke_ideal/{version}" \
        in result.stdout
    assert f"dataset push_effects/repeated_smoke_ideal version {version}: built in " in result.stderr
    ideal = _all(load("repeated", "smoke", data_dir=tmp_path, testbed="ideal", split="test"))
    build("repeated", "smoke", data_dir=tmp_path, workers=1, progress=False)
    realistic = _all(load("repeated", "smoke", data_dir=tmp_path, split="test"))
    # Each testbed has its own dataset and raw cache; the same push moves the object differently on each.
    assert {path.parent.name for path in (tmp_path / "push_effects_raw").rglob("*.h5")} == {"rect1"}
    assert sorted(path.name for path in (tmp_path / "push_effects_raw").iterdir()) == ["ideal", "realistic"]
    assert len(realistic["motion"]) == 24 and not np.allclose(ideal["motion"], realistic["motion"], atol=1e-4)


def test_a_given_raw_dir_is_never_written(tmp_path):
    raw_dir = tmp_path / "real_mit_files"
    raw_dir.mkdir()
    with pytest.raises(IncompleteRawDirError, match=r"raw_dir: 1 of 1 files .* missing under .*first: .*/"
                                                    r"motion_surface=.*\.h5"):
        build("repeated", "smoke", data_dir=tmp_path / "data", workers=1, progress=False, raw_dir=raw_dir)
    assert not list(raw_dir.iterdir())


def test_cli_refuses_an_incomplete_raw_dir(tmp_path):
    raw_dir = tmp_path / "real_mit_files"
    raw_dir.mkdir()
    result = subprocess.run(
        [sys.executable, "-m", "experiments.build_dataset", "--experiment=repeated", "--scale=smoke",
         f"--data_dir={tmp_path / 'data'}", "--workers=1", f"--raw_dir={raw_dir}"],
        capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2])
    assert result.returncode != 0 and "Traceback" not in result.stderr, result.stderr[-3000:]
    assert "--raw_dir: 1 of 1 files" in result.stderr
    assert not list(raw_dir.iterdir())


@pytest.mark.parametrize("dataset_info, detail", [
    ('{"name": "push_effects", "version": "2.0.0"}', r"AssertionError: .*Builder version: 3\.0\.0\. Proto version: "
                                                     r"2\.0\.0"),
    ("not json", "ParseError: Failed to load JSON"),
])
def test_a_dataset_folder_of_another_version_or_damaged_is_named(tmp_path, dataset_info, detail):
    folder = tmp_path / "push_effects" / "data_efficiency_smoke" / str(PushEffects.VERSION)
    folder.mkdir(parents=True)
    (folder / "dataset_info.json").write_text(dataset_info)
    with pytest.raises(DatasetFolderError, match=f"^data_dir: {folder} is not a readable push_effects "
                                                 rf"{PushEffects.VERSION} dataset \({detail}.*\); delete the folder to "
                                                 "build the dataset again$") as error:
        PushEffects(config="data_efficiency_smoke", data_dir=tmp_path)
    assert "\n" not in str(error.value)
    with pytest.raises(ValueError, match="BuilderConfig bogus_smoke not found") as error:  # not the folder's fault
        PushEffects(config="bogus_smoke", data_dir=tmp_path)
    assert not isinstance(error.value, DatasetFolderError)


def test_cli_names_a_damaged_raw_file(tmp_path):
    """A push file of a given raw folder that is not HDF5: one line naming it, also from a worker process."""
    raw_dir = tmp_path / "real_mit_files"
    planned = configs.plan_splits(configs.get_config("repeated", "smoke"), raw_dir).jobs[0].path
    planned.parent.mkdir(parents=True)
    planned.write_text("not HDF5")
    result = subprocess.run(
        [sys.executable, "-m", "experiments.build_dataset", "--experiment=repeated", "--scale=smoke",
         f"--data_dir={tmp_path / 'data'}", "--workers=2", f"--raw_dir={raw_dir}"],
        capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2])
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr[-3000:]
    assert result.stderr.splitlines()[-1].startswith(f"error: {planned}: unreadable file: corrupt or truncated HDF5 "
                                                     "file ("), result.stderr[-3000:]


def test_seeded_configs_testbeds_and_bad_names():
    assert configs.get_config("objects", "paper", seed=3).name == "objects_paper_seed3"
    assert configs.get_config("objects", "paper").testbed == "realistic"
    assert configs.get_config("objects", "paper", seed=3, testbed="ideal").name == "objects_paper_ideal_seed3"
    with pytest.raises(ValueError, match="testbed: expected one of ideal, realistic, got 'lab'"):
        configs.get_config("data_efficiency", "smoke", testbed="lab")
    with pytest.raises(ValueError, match="experiment"):
        configs.get_config("nope", "smoke")
    with pytest.raises(ValueError, match="scale"):
        configs.get_config("data_efficiency", "huge")


def test_paper_scale_sizes():
    def sizes(experiment):
        config = configs.get_config(experiment, "paper")
        plan = configs.plan_splits(config, "/unused")
        return {name: len(ids) * config.examples_per_sequence for name, ids in plan.splits.items()}

    data_efficiency = sizes("data_efficiency")
    assert {name: data_efficiency[name] for name in ("train", "test")} == pytest.approx(
        {"train": 190e3, "test": 38e3}, rel=0.03)
    # 48 validation sequences per object, 7 for each triangle (its MIT grid has 297 distinct pushes, 290 in use).
    assert data_efficiency["validation"] == (8 * 48 + 3 * 7) * 72
    assert sizes("new_pushes") == pytest.approx({"train": 114e3, "validation": 23e3, "test": 91e3}, rel=0.03)
    assert all(size == pytest.approx(35e3, rel=0.03)
               for name, size in sizes("objects").items() if name.startswith("train"))
    assert sizes("repeated") == {"test": 200}
    cpu = configs.get_config("data_efficiency", "cpu")
    plan = configs.plan_splits(cpu, "/unused")
    assert len(plan.splits["train"]) * cpu.examples_per_sequence == pytest.approx(20e3, rel=0.05)


def test_cpu_full_has_the_papers_composition():
    config = configs.get_config("data_efficiency", "cpu_full")
    plan = configs.plan_splits(config, "/unused")
    sizes = {name: len(ids) * config.examples_per_sequence for name, ids in plan.splits.items()}
    assert sizes == {"train": 190_080, "validation": 6_336, "test": 38_016}
    assert len(plan.splits["test"]) >= 500 and (config.image_size, config.glimpse_size) == (64, 20)
    jobs = [plan.jobs[i] for ids in plan.splits.values() for i in ids]
    assert {job.params.surface for job in jobs} == {"abs", "delrin", "plywood", "pu"}
    assert {job.params.shape for job in jobs} == set(configs.OBJECT_NAMES)
    assert {(job.params.velocity, job.params.acceleration) for job in jobs} == {(20.0, 0.0)}
    test = {i for i in plan.splits["test"]}
    assert not test & set(plan.splits["train"]) and not test & set(plan.splits["validation"])
    # every surface in the test split
    assert {plan.jobs[i].params.surface for i in test} == {"abs", "delrin", "plywood", "pu"}


def test_paper_full_has_cpu_fulls_pushes_at_the_papers_images():
    cpu_full, paper_full = (configs.get_config("data_efficiency", scale) for scale in ("cpu_full", "paper_full"))
    plans = [configs.plan_splits(config, "/unused") for config in (cpu_full, paper_full)]
    assert plans[0].splits == plans[1].splits
    assert [job.params for job in plans[0].jobs] == [job.params for job in plans[1].jobs]
    assert (paper_full.image_size, paper_full.glimpse_size) == (128, 80)
    assert dataclasses.replace(paper_full, scale="cpu_full", image_size=64, glimpse_size=20) == cpu_full
