"""Dataset configurations: one per experiment of the paper and per scale, and their split plans.

An experiment (Kloss, Schaal & Bohg, Secs. IV-C to IV-F and V) fixes which simulated push sequences are
recorded and how they are assigned to splits; a scale fixes how many, how many examples each sequence gives and
the image resolution. Splits are made per push sequence: a sequence's examples all land in the same split, and
no training split shares a sequence with a validation or test split. The ``velocities`` and ``objects``
experiments offer several alternative training splits (``train_*``), which share sequences with each other by
design (each is a different training set for the same test splits); those alternatives all have the same number
of sequences and take an equal share from each of their velocities or objects.

Experiments (split names in brackets):

``data_efficiency`` [train, validation, test]
    All 11 objects at 20 mm/s on abs, a random 5/6 : 1/6 split of each object's sequences into train and test,
    and ``test_pushes_per_object`` further sequences per object for validation (learning curves and the choice of
    the training schedule; never reported as a result), fewer where the object's MIT grid has no more distinct
    pushes (the triangles at ``paper`` scale: 7).
``new_pushes`` [train, validation, test]
    The same sequences; test holds every push at the angles 0° and ±20° and every push at a held-out tenth of
    each object's contact points (side, point); the rest is split 5/6 : 1/6 into train and validation.
``velocities`` [train_20, train_10_20, train_20_50, test_10, test_20, ..., test_300]
    All objects; test sets per velocity from 10 to 300 mm/s, training sets at 20, at 10 + 20 and at
    20 + 50 mm/s.
``objects`` [train_butter, train_butter_hex, train_butter_hex_ellip1, train_butter_hex_tri1, test_ellipses,
test_triangles]
    Training on butter, butter + hex, and butter + hex + ellip1 or tri1; tests on all ellipses and on all
    triangles (for ellip1 and tri1 on sequences kept out of training).
``viewpoint`` [train, validation, test]
    As ``data_efficiency``, seen by the free (oblique) camera; examples carry the organised point cloud.
``repeated`` [test]
    One push configuration (``REPEATED_PUSH``) seen under many scene transforms, for the visual figures.

Scales:

``smoke``
    At most 2 k examples per dataset, built in seconds; used by the tests.
``cpu`` (default)
    Sized so that the full ``data_efficiency`` experiment (issue 6) trains on a 2-core machine within a few
    hours: 64 x 64 depth images, 20 x 20 px glimpses and about 20 k training examples (11 objects x 25 training
    sequences x 72 examples; 72 examples per sequence as at ``paper`` scale, which also keeps the simulation's
    share of the build time at about a third). The top-down camera sees a 0.331 m square of the table, so a pixel covers
    5.2 mm (``paper``: 2.6 mm). Locating a point by whole pixels then costs 5.2 / sqrt(12) = 1.5 mm RMS per
    axis (``paper``: 0.75 mm); a learned localiser interpolates below a pixel, but expect its position error
    to be about a millimetre larger than at ``paper`` resolution, with the object's motion over 0.5 s at
    20 mm/s being about 10 mm.
``cpu_full``
    The paper's composition at ``cpu`` images (issue 30): all 11 objects on all four surfaces at 20 mm/s without
    acceleration, 66 push sequences per object and surface plus 8 per object for validation, 72 examples per
    sequence, 64 x 64 images and 20 x 20 px glimpses. ``data_efficiency``: 2 640 training sequences (190 080
    examples), 528 test sequences (38 016 examples) and 88 validation sequences (6 336 examples), as the paper's
    191 k / 38 k.
``paper_full``
    ``cpu_full``'s pushes, splits and examples (the same seeds draw the same pushes, windows and transforms) rendered at
    the paper's 128 x 128 px with 80 x 80 px glimpses: the paper's composition at the paper's images, for a GPU
    (issue 30, part 4).
``paper``
    The paper's sizes: ``data_efficiency`` 191 k / 38 k, ``new_pushes`` about 114 k / 23 k / 91 k,
    ``objects`` 35 k per training set, ``viewpoint`` 191 k / 38 k, ``repeated`` 200; 128 x 128 images and
    80 x 80 px glimpses (the paper's glimpse size, which sets the 1.8 M / 2.7 M parameter counts).

Testbeds: every dataset is simulated with a testbed profile of :mod:`pushjax.sim.testbed`, ``realistic`` by default
(the physics Lynch's model leaves out, calibrated against the paper); ``ideal`` (pushes exactly as the model
assumes) is the clean reference, its datasets named ``<experiment>_<scale>_ideal``.

All numbers that define a dataset live in :class:`DatasetConfig`; ``get_config(experiment, scale, seed, testbed)``
returns the one used by the builders.

Grown test splits (issue 30): ``get_config(..., min_test_sequences=N)`` is a test-only dataset, named
``<experiment>_<scale>..._test<N>``: each test split of the experiment's dataset, its sequences kept, grown by further
draws of the pools it tests to at least N sequences (``plan_grown_test_splits``). Trained models are evaluated on it
(``--min_test_sequences`` of the experiment binaries); their training and validation splits are untouched.
"""

from __future__ import annotations

import collections
import dataclasses
import math
import zlib
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from pushjax.geometry.objects import OBJECT_NAMES, get_object
from pushjax.mit.files import PushParams, push_file_path
from pushjax.mit.protocol import MIT_ANGLES, side_points
from pushjax.sim.dataset import PushJob, RecordingConfig, plan_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.surfaces import SURFACE_NAMES
from pushjax.sim.testbed import DEFAULT_PROFILE, PROFILES, Testbed

EXPERIMENTS = ("data_efficiency", "new_pushes", "velocities", "objects", "viewpoint", "repeated")
SCALES = ("smoke", "cpu", "cpu_full", "paper_full", "paper")
DEFAULT_SCALE = "cpu"

TRAIN_VELOCITY = 20.0
"""mm/s, the velocity of every experiment but ``velocities``."""
TEST_VELOCITIES = (10.0, 20.0, 50.0, 75.0, 100.0, 150.0, 200.0, 300.0)
"""mm/s, the test velocities of the ``velocities`` experiment."""
VELOCITY_TRAIN_SETS = {"train_20": (20.0,), "train_10_20": (10.0, 20.0), "train_20_50": (20.0, 50.0)}
OBJECT_TRAIN_SETS = {
    "train_butter": ("butter",),
    "train_butter_hex": ("butter", "hex"),
    "train_butter_hex_ellip1": ("butter", "hex", "ellip1"),
    "train_butter_hex_tri1": ("butter", "hex", "tri1"),
}
OBJECT_TEST_SETS = {"test_ellipses": ("ellip1", "ellip2", "ellip3"), "test_triangles": ("tri1", "tri2", "tri3")}
NEW_PUSH_TEST_ANGLES_DEG = (-20.0, 0.0, 20.0)
REPEATED_PUSH = PushParams(surface="abs", shape="rect1", acceleration=0.0, velocity=20.0, side=0, point=0.3,
                           angle=0.349)
"""The push of the ``repeated`` experiment: rect1, 30 % along side 0, 20° to the normal, 20 mm/s."""


@dataclasses.dataclass(frozen=True)
class DatasetConfig:
    """Everything that defines one dataset.

    Attributes:
      experiment: one of :data:`EXPERIMENTS`.
      scale: one of :data:`SCALES`.
      seed: seed of the push draws, splits, windows, scene transforms and pusher displacements.
      testbed: name of the testbed profile the pushes are simulated with (``pushjax.sim.testbed.PROFILES``).
      image_size: height = width of the depth image, pixels.
      glimpse_size: side of the square glimpse a model cuts around the pusher, pixels (not used to build the
        data; stored so that models read it from the dataset config).
      horizon: prediction horizon, s.
      camera: ``"top_down"`` or ``"free"`` (see :mod:`pushjax.render.camera`).
      surfaces: surfaces of the recorded pushes.
      pushes_per_object: sequences per object and velocity in pools that feed training splits.
      test_pushes_per_object: sequences per object and velocity in pools that only feed test splits (and the
        validation splits of ``data_efficiency`` and ``viewpoint``).
      windows_per_sequence: random window start times drawn per sequence.
      transforms_per_window: random scene transforms per window.
      no_contact_fraction: share of examples whose pusher is moved so that it does not touch the object.
      test_fraction: share of a shared pool's sequences that go to the test split.
      validation_fraction: share of the remaining sequences that go to the validation split (``new_pushes``).
      held_out_point_fraction: share of each object's contact points held out for the ``new_pushes`` test.
      max_translation: the object's centre of mass lands uniformly in a square of this half width about the
        camera's table point, m.
      max_rotation: scene rotations are uniform in [-max_rotation, max_rotation], rad.
      repeated_start_time: window start of the ``repeated`` examples, s.
      min_test_sequences: 0: the experiment's dataset. N > 0: a test-only dataset holding the experiment's test
        splits, each grown to at least N sequences (see :func:`plan_grown_test_splits`).
    """

    experiment: str
    scale: str
    seed: int = 0
    testbed: str = DEFAULT_PROFILE
    image_size: int = 64
    glimpse_size: int = 20
    horizon: float = 0.5
    camera: str = "top_down"
    surfaces: tuple[str, ...] = ("abs",)
    pushes_per_object: int = 30
    test_pushes_per_object: int = 5
    windows_per_sequence: int = 24
    transforms_per_window: int = 3
    no_contact_fraction: float = 1.0 / 3.0
    test_fraction: float = 1.0 / 6.0
    validation_fraction: float = 1.0 / 6.0
    held_out_point_fraction: float = 0.1
    max_translation: float = 0.04
    max_rotation: float = math.pi
    repeated_start_time: float = 0.5
    min_test_sequences: int = 0

    def __post_init__(self):
        if self.experiment not in EXPERIMENTS:
            raise ValueError(f"experiment: expected one of {', '.join(EXPERIMENTS)}, got {self.experiment!r}")
        if self.scale not in SCALES:
            raise ValueError(f"scale: expected one of {', '.join(SCALES)}, got {self.scale!r}")
        if self.camera not in ("top_down", "free"):
            raise ValueError(f"camera: expected 'top_down' or 'free', got {self.camera!r}")
        if self.testbed not in PROFILES:
            raise ValueError(f"testbed: expected one of {', '.join(PROFILES)}, got {self.testbed!r}")
        if not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"seed: expected an integer >= 0, got {self.seed!r}")
        for name in ("image_size", "glimpse_size", "pushes_per_object", "test_pushes_per_object",
                     "windows_per_sequence", "transforms_per_window"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 1:
                raise ValueError(f"{name}: expected an integer >= 1, got {getattr(self, name)!r}")
        for name in ("no_contact_fraction", "test_fraction", "validation_fraction", "held_out_point_fraction"):
            if not 0.0 <= getattr(self, name) < 1.0:
                raise ValueError(f"{name}: expected a fraction in [0, 1), got {getattr(self, name)!r}")
        if not self.horizon > 0:
            raise ValueError(f"horizon: expected > 0 s, got {self.horizon!r}")
        if not isinstance(self.min_test_sequences, int) or self.min_test_sequences < 0:
            raise ValueError(f"min_test_sequences: expected an integer >= 0, got {self.min_test_sequences!r}")
        if self.min_test_sequences and self.experiment == "repeated":
            raise ValueError("min_test_sequences: the repeated experiment tests one push; expected 0")

    @property
    def name(self) -> str:
        """The TFDS config name: ``<experiment>_<scale>``, with ``_<testbed>`` for a testbed other than the default,
        ``_test<N>`` for grown test splits and ``_seed<seed>`` for seeds other than 0 (e.g.
        ``data_efficiency_smoke_ideal_seed3``, ``velocities_cpu_test150``)."""
        return (f"{self.experiment}_{self.scale}" + (f"_{self.testbed}" if self.testbed != DEFAULT_PROFILE else "")
                + (f"_test{self.min_test_sequences}" if self.min_test_sequences else "")
                + (f"_seed{self.seed}" if self.seed else ""))

    @property
    def testbed_profile(self) -> Testbed:
        """The magnitudes of the testbed profile :attr:`testbed`."""
        return PROFILES[self.testbed]

    @property
    def examples_per_sequence(self) -> int:
        return self.windows_per_sequence * self.transforms_per_window

    @property
    def has_point_cloud(self) -> bool:
        return self.camera == "free"


# (pushes_per_object, test_pushes_per_object, windows_per_sequence, transforms_per_window) per scale; images.
_SIZES = {
    "smoke": dict(pushes_per_object=6, test_pushes_per_object=1, windows_per_sequence=4, transforms_per_window=3,
                  image_size=64, glimpse_size=20),
    "cpu": dict(pushes_per_object=30, test_pushes_per_object=5, windows_per_sequence=24, transforms_per_window=3,
                image_size=64, glimpse_size=20),
    "cpu_full": dict(pushes_per_object=66, test_pushes_per_object=8, windows_per_sequence=24,
                     transforms_per_window=3, image_size=64, glimpse_size=20, surfaces=SURFACE_NAMES),
    "paper_full": dict(pushes_per_object=66, test_pushes_per_object=8, windows_per_sequence=24,
                       transforms_per_window=3, image_size=128, glimpse_size=80, surfaces=SURFACE_NAMES),
    "paper": dict(pushes_per_object=290, test_pushes_per_object=48, windows_per_sequence=24,
                  transforms_per_window=3, image_size=128, glimpse_size=80),
}
_EXPERIMENT_SIZES = {
    ("velocities", "smoke"): dict(pushes_per_object=3, windows_per_sequence=3),
    ("objects", "smoke"): dict(test_pushes_per_object=2, windows_per_sequence=3),
    ("objects", "cpu"): dict(pushes_per_object=50, test_pushes_per_object=10),
    ("objects", "paper"): dict(pushes_per_object=240, transforms_per_window=6),
    ("repeated", "smoke"): dict(transforms_per_window=24),
    ("repeated", "cpu"): dict(transforms_per_window=200),
    ("repeated", "paper"): dict(transforms_per_window=200),
}


def get_config(experiment: str, scale: str = DEFAULT_SCALE, seed: int = 0,
               testbed: str = DEFAULT_PROFILE, min_test_sequences: int = 0) -> DatasetConfig:
    """The configuration of ``experiment`` at ``scale`` (see the module docstring) with ``seed`` and ``testbed``;
    ``min_test_sequences`` > 0: its test splits grown to that many sequences, as a test-only dataset."""
    if scale not in _SIZES:
        raise ValueError(f"scale: expected one of {', '.join(SCALES)}, got {scale!r}")
    sizes = dict(_SIZES[scale], **_EXPERIMENT_SIZES.get((experiment, scale), {}))
    if experiment == "viewpoint":
        sizes["camera"] = "free"
    if experiment == "repeated":
        sizes["windows_per_sequence"] = 1
        sizes["no_contact_fraction"] = 0.0
    return DatasetConfig(experiment=experiment, scale=scale, seed=seed, testbed=testbed,
                         min_test_sequences=min_test_sequences, **sizes)


def all_configs(seed: int = 0) -> list[DatasetConfig]:
    """Every experiment at every scale on every testbed profile, with ``seed``."""
    return [get_config(experiment, scale, seed, testbed)
            for experiment in EXPERIMENTS for scale in SCALES for testbed in PROFILES]


@dataclasses.dataclass(frozen=True)
class SplitPlan:
    """The sequences of a dataset and the sequence ids of each split.

    Attributes:
      jobs: the push sequences, indexed by sequence id, as ``pushjax.sim.dataset.PushJob`` values: where the raw
        file is cached and how to record it when it is missing.
      splits: split name -> sorted sequence ids.
    """

    jobs: tuple[PushJob, ...]
    splits: dict[str, tuple[int, ...]]


def _key(*parts) -> list[int]:
    return [zlib.crc32(str(part).encode("utf-8")) for part in parts]


def _pool(obj: str, velocity: float, pushes: int, config: DatasetConfig, raw_dir: Path) -> list[PushJob]:
    """The recording jobs of ``pushes`` draws of ``obj`` at ``velocity`` on every configured surface."""
    return plan_pushes(raw_dir, [obj], list(config.surfaces), pushes,
                       RecordingConfig(seed=config.seed, velocities=(velocity,), testbed=config.testbed_profile))


def _split_off(items: list, fraction: float, rng: np.random.Generator) -> tuple[list, list]:
    """(rest, held) with ``round(len * fraction)`` items (at least 1 when ``fraction`` > 0) held, at random."""
    count = min(len(items) - 1, max(1 if fraction > 0 else 0, round(len(items) * fraction)))
    order = rng.permutation(len(items))
    held = sorted(order[:count])
    rest = sorted(order[count:])
    return [items[i] for i in rest], [items[i] for i in held]


def _distinct_pushes(obj: str) -> int:
    """The pushes of ``obj`` on the MIT grid at one velocity: sides x contact points x angles."""
    return len(get_object(obj).sides) * len(side_points(obj)) * len(MIT_ANGLES)


def held_out_contact_points(obj: str, config: DatasetConfig) -> frozenset[int]:
    """Contact point ids (see :func:`contact_point_id`) of ``obj`` held out for the ``new_pushes`` test."""
    count = len(get_object(obj).sides) * len(side_points(obj))
    rng = np.random.default_rng(_key(config.seed, obj, "held-out points"))
    return frozenset(int(i) for i in rng.permutation(count)[:max(1, round(count * config.held_out_point_fraction))])


def contact_point_id(params: PushParams) -> int:
    """``side * points_per_side + index of the point`` on the MIT grid of ``params.shape``."""
    points = side_points(params.shape)
    return params.side * len(points) + int(np.argmin(np.abs(points - params.point)))


def is_new_push(params: PushParams, config: DatasetConfig) -> bool:
    """Whether a push belongs to the ``new_pushes`` test: at a held-out angle or a held-out contact point."""
    at_held_angle = bool(np.any(np.abs(np.radians(NEW_PUSH_TEST_ANGLES_DEG) - params.angle) < 1e-3))
    return at_held_angle or contact_point_id(params) in held_out_contact_points(params.shape, config)


Jobs = dict[str, list[PushJob]]
"""Split name -> the recording jobs of its sequences."""


def _held_out_pushes(config: DatasetConfig, raw_dir: Path) -> Jobs:
    """``data_efficiency``, ``viewpoint``: every object's pushes at 20 mm/s split at random into train, validation
    and test."""
    jobs: Jobs = {"train": [], "validation": [], "test": []}
    for obj in OBJECT_NAMES:
        # The MIT grid of a triangle has 297 distinct pushes per velocity: at paper scale that leaves 7 for validation.
        validations = min(config.test_pushes_per_object, _distinct_pushes(obj) - config.pushes_per_object)
        pool = _pool(obj, TRAIN_VELOCITY, config.pushes_per_object + validations, config, raw_dir)
        rng = np.random.default_rng(_key(config.seed, obj, config.experiment, "split"))
        pool, validation = _split_off(pool, validations / len(pool), rng)
        train, test = _split_off(pool, config.test_fraction, rng)
        for name, split_jobs in (("train", train), ("validation", validation), ("test", test)):
            jobs[name] += split_jobs
    return jobs


def _new_pushes(config: DatasetConfig, raw_dir: Path) -> Jobs:
    """``new_pushes``: pushes at held-out angles or contact points are the test split."""
    jobs: Jobs = {"train": [], "validation": [], "test": []}
    for obj in OBJECT_NAMES:
        pool = _pool(obj, TRAIN_VELOCITY, config.pushes_per_object, config, raw_dir)
        rng = np.random.default_rng(_key(config.seed, obj, config.experiment, "split"))
        is_test = [is_new_push(job.params, config) for job in pool]
        jobs["test"] += [job for job, test in zip(pool, is_test) if test]
        train, validation = _split_off([job for job, test in zip(pool, is_test) if not test],
                                       config.validation_fraction, rng)
        jobs["train"] += train
        jobs["validation"] += validation
    return jobs


def _velocities(config: DatasetConfig, raw_dir: Path) -> Jobs:
    """``velocities``: a test split per velocity, training sets mixing the trained velocities in equal shares."""
    jobs: Jobs = {}
    train_pools: dict[float, dict[str, list]] = {}
    for velocity in TEST_VELOCITIES:
        trained = any(velocity in velocities for velocities in VELOCITY_TRAIN_SETS.values())
        jobs[f"test_{velocity:g}"] = []
        for obj in OBJECT_NAMES:
            if trained:
                pool = _pool(obj, velocity, config.pushes_per_object, config, raw_dir)
                rng = np.random.default_rng(_key(config.seed, obj, velocity, "split"))
                train, test = _split_off(pool, config.test_fraction, rng)
                train_pools.setdefault(velocity, {})[obj] = train
            else:
                test = _pool(obj, velocity, config.test_pushes_per_object, config, raw_dir)
            jobs[f"test_{velocity:g}"] += test
    for name, velocities in VELOCITY_TRAIN_SETS.items():
        jobs[name] = [job for obj in OBJECT_NAMES for job in _equal_shares(
            [train_pools[v][obj] for v in velocities], len(train_pools[TRAIN_VELOCITY][obj]))]
    return jobs


def _objects(config: DatasetConfig, raw_dir: Path) -> Jobs:
    """``objects``: training sets of object groups in equal shares, test sets of seen and unseen objects."""
    jobs: Jobs = {}
    trained = sorted({obj for objects in OBJECT_TRAIN_SETS.values() for obj in objects})
    train_pools = {}
    for name, objects in OBJECT_TEST_SETS.items():
        jobs[name] = []
        for obj in objects:
            if obj in trained:
                pool = _pool(obj, TRAIN_VELOCITY, config.pushes_per_object + config.test_pushes_per_object,
                             config, raw_dir)
                rng = np.random.default_rng(_key(config.seed, obj, config.experiment, "split"))
                train_pools[obj], test = _split_off(pool, config.test_pushes_per_object / len(pool), rng)
            else:
                test = _pool(obj, TRAIN_VELOCITY, config.test_pushes_per_object, config, raw_dir)
            jobs[name] += test
    for obj in trained:
        if obj not in train_pools:
            train_pools[obj] = _pool(obj, TRAIN_VELOCITY, config.pushes_per_object, config, raw_dir)
    size = len(train_pools["butter"])
    for name, objects in OBJECT_TRAIN_SETS.items():
        jobs[name] = _equal_shares([train_pools[obj] for obj in objects], size)
    return {name: jobs[name] for name in (*OBJECT_TRAIN_SETS, *OBJECT_TEST_SETS)}


def _repeated(config: DatasetConfig, raw_dir: Path) -> Jobs:
    """``repeated``: the one repeated push as the test split."""
    return {"test": [PushJob(path=raw_path(raw_dir, REPEATED_PUSH), params=REPEATED_PUSH, effects=Effects(),
                             support="grid", noise_seed=(config.seed,), attributes=None,
                             testbed=config.testbed_profile)]}


SPLIT_PLANS: dict[str, Callable[[DatasetConfig, Path], Jobs]] = {
    "data_efficiency": _held_out_pushes, "viewpoint": _held_out_pushes, "new_pushes": _new_pushes,
    "velocities": _velocities, "objects": _objects, "repeated": _repeated,
}
"""Experiment -> how its sequences are planned and split (one entry per name of `EXPERIMENTS`)."""


_TEST_MEMBERSHIP: dict[str, Callable[[PushParams, DatasetConfig], bool]] = {"new_pushes": is_new_push}
"""Experiment -> which pushes its test splits may hold, where not every push may (default: any)."""


def _pool_of(job: PushJob) -> tuple[str, str, float]:
    """(object, surface, velocity): the pool a push is drawn from."""
    return job.params.shape, job.params.surface, job.params.velocity


def plan_grown_test_splits(config: DatasetConfig, raw_dir: str | Path) -> Jobs:
    """The test splits of ``config``'s experiment, each grown to at least ``config.min_test_sequences`` sequences.

    A test split keeps its sequences and gains, for each (object, surface, velocity) it tests, further draws of
    that pool (the next pushes of `pushjax.sim.dataset.plan_pushes`' deterministic order, at ``new_pushes`` only
    pushes its test admits) until each of these groups holds ``ceil(min_test_sequences / groups)``. No added
    sequence belongs to any split of the experiment's own dataset, so a model trained on that dataset has seen
    none of them.

    Raises:
      ValueError: naming the object, surface and velocity whose MIT grid has too few distinct pushes left.
    """
    own = SPLIT_PLANS[config.experiment](dataclasses.replace(config, min_test_sequences=0), Path(raw_dir))
    planned = collections.Counter(_pool_of(job) for split_jobs in own.values() for job in split_jobs)
    taken = {job.path for split_jobs in own.values() for job in split_jobs}
    admits = _TEST_MEMBERSHIP.get(config.experiment, lambda params, config: True)
    grown: Jobs = {}
    for name, jobs in own.items():
        if not name.startswith("test"):
            continue
        tested = collections.Counter(_pool_of(job) for job in jobs)
        per_group = math.ceil(config.min_test_sequences / len(tested))
        grown[name] = list(jobs)
        for obj, surface, velocity in sorted(tested):
            missing = per_group - tested[obj, surface, velocity]
            draws = missing + planned[obj, surface, velocity]
            while missing > 0:
                draws = min(draws, _distinct_pushes(obj))
                fresh = [job for job in _pool(obj, velocity, draws, config, Path(raw_dir))
                         if job.params.surface == surface and job.path not in taken and admits(job.params, config)]
                if len(fresh) >= missing:
                    grown[name] += fresh[:missing]
                    taken.update(job.path for job in fresh[:missing])
                    break
                if draws == _distinct_pushes(obj):
                    raise ValueError(f"min_test_sequences: {obj} on {surface} at {velocity:g} mm/s has {len(fresh)} "
                                     f"pushes left for {name}, {missing} needed for {config.min_test_sequences}")
                draws += missing - len(fresh)
    return grown


def plan_splits(config: DatasetConfig, raw_dir: str | Path) -> SplitPlan:
    """The sequences of ``config``'s dataset and their assignment to splits; deterministic for the config.

    Args:
      config: the dataset.
      raw_dir: root of the raw (MIT layout) cache of the simulated sequences (of ``config.testbed``).
    """
    per_split = (plan_grown_test_splits(config, raw_dir) if config.min_test_sequences
                 else SPLIT_PLANS[config.experiment](config, Path(raw_dir)))
    by_path = {job.path: job for jobs in per_split.values() for job in jobs}
    paths = sorted(by_path)
    ids = {path: index for index, path in enumerate(paths)}
    splits = {name: tuple(sorted({ids[job.path] for job in jobs})) for name, jobs in per_split.items()}
    return SplitPlan(jobs=tuple(by_path[path] for path in paths), splits=splits)


def _equal_shares(pools: Sequence[list], size: int) -> list:
    """``size`` items taking an equal share (the first ones) from each pool; earlier pools get the remainder."""
    shares = [size // len(pools) + (k < size % len(pools)) for k in range(len(pools))]
    for pool, share in zip(pools, shares):
        if share > len(pool):
            raise ValueError(f"pools: a pool of {len(pool)} sequences cannot give {share}")
    return [item for pool, share in zip(pools, shares) for item in pool[:share]]


def raw_path(raw_dir: str | Path, params: PushParams) -> Path:
    """Where the raw (MIT layout) file of a sequence is cached."""
    return push_file_path(raw_dir, params)
