"""The raw MIT Push Dataset file layout (Yu et al., IROS 2016): file names, writer, reader, cleaning, iteration.

The file names and the parameters they encode are in :mod:`pushjax.mit.file_names`, re-exported here.

Layout: ``<root>/<surface>/<object>/`` holds one HDF5 file per push, named

    motion_surface=<surface>_shape=<object>_a=<acc>_v=<vel>_i=<side>_s=<point>_t=<angle>[_rep=<NNNN>].h5

with the pusher acceleration ``a`` in mm/s², velocity ``v`` in mm/s, the index ``i`` of the object side that is
pushed, the contact point ``s`` on that side in 0..1 and the push angle ``t`` to the side's normal in rad. Each
file holds three datasets of float64 rows, in s, m, rad, N and N·m:

    tip_pose     [N, 4]  [t, x, y, yaw]      pusher tip pose
    object_pose  [M, 4]  [t, x, y, yaw]      object pose (tracked object frame)
    ft_wrench    [K, 4]  [t, fx, fy, torque] force-torque sensor reading

The streams are not synchronised, may hold duplicate time stamps, unsorted rows and yaw jumps of 2π, and are
recorded at about 250 Hz. ``read_raw_push`` returns them as stored; ``load_push`` cleans them the way the
dataset's own preprocessing does and resamples them onto one clock. Files written by the pushjax testbed may
carry extra HDF5 file attributes (e.g. ``pushjax_effects``, a JSON string declaring the physical effects
injected in simulation).
"""

from __future__ import annotations

import collections
import dataclasses
import json
import math
import os
import secrets
from collections.abc import Collection, Iterator, Mapping
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from absl import logging

from pushjax import planar
from pushjax.mit.file_names import (
    _UNPARSEABLE_NAME,
    PushFileError,
    PushParams,
    parse_push_file_name,
    push_file_name,
    push_file_path as push_file_path,  # re-exported: its callers import it from here
)

POSE_DATASETS = ("tip_pose", "object_pose")
WRENCH_DATASET = "ft_wrench"
DATASETS = (*POSE_DATASETS, WRENCH_DATASET)
EFFECTS_ATTRIBUTE = "pushjax_effects"
DEFAULT_FREQUENCY = 250.0  # Hz, the dataset's recording rate.

# Oldest format that holds everything we write, so old readers open the files; a fixed value keeps bytes stable.
_LIBVER = ("earliest", "v110")


def _validated_stream(path: str | os.PathLike, name: str, stream: Any) -> np.ndarray:
    """A read-only float64 [N, 4] copy of one stream; PushFileError naming ``path`` if unusable."""
    try:
        array = np.array(stream, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise PushFileError(path, "not numeric", f"{name} is not numeric: {error}") from error
    if array.ndim != 2 or array.shape[1] != 4:
        raise PushFileError(path, "wrong shape", f"{name} must have shape [N, 4], got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise PushFileError(path, "non-finite values", f"{name} holds NaN or infinite values")
    if np.unique(array[:, 0]).size < 2:
        raise PushFileError(path, "too few time stamps", f"{name} has fewer than 2 distinct time stamps")
    array.setflags(write=False)
    return array


@dataclasses.dataclass(frozen=True, eq=False)
class RawPush:
    """One push file's content as stored: no cleaning, only validation.

    Attributes:
      path: the file.
      params: parameters parsed from the file name, or None if the name does not follow the layout.
      tip_pose: [N, 4] rows [t s, x m, y m, yaw rad], read-only.
      object_pose: [M, 4] rows [t s, x m, y m, yaw rad], read-only.
      ft_wrench: [K, 4] rows [t s, fx N, fy N, torque N·m], read-only.
      attributes: the HDF5 file attributes, by name (empty for real dataset files).
    """

    path: Path
    params: PushParams | None
    tip_pose: np.ndarray
    object_pose: np.ndarray
    ft_wrench: np.ndarray
    attributes: Mapping[str, Any] = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "path", Path(self.path))
        for name in DATASETS:
            object.__setattr__(self, name, _validated_stream(self.path, name, getattr(self, name)))

    @property
    def declared_effects(self) -> Any:
        """The decoded ``pushjax_effects`` JSON attribute, or None when the file declares none."""
        return _decode_effects(self.path, self.attributes)


def _decode_effects(path: Path, attributes: Mapping[str, Any]) -> Any:
    if EFFECTS_ATTRIBUTE not in attributes:
        return None
    try:
        return json.loads(attributes[EFFECTS_ATTRIBUTE])
    except (TypeError, json.JSONDecodeError) as error:
        raise PushFileError(path, "bad attribute", f"{EFFECTS_ATTRIBUTE} is not a JSON string: {error}") from error


def _validated_attribute(name: Any, value: Any) -> Any:
    if not isinstance(name, str) or not name:
        raise ValueError(f"attribute names must be non-empty strings, got {name!r}")
    if isinstance(value, (str, bool, int, float, np.bool_, np.integer, np.floating)):
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "biuf":
        return value
    raise ValueError(
        f"attribute {name!r} must be a str, bool, int, float or numeric numpy array, got {type(value).__name__}"
    )


def write_push(
    path: str | os.PathLike,
    params: PushParams | None,
    tip_pose: Any,
    object_pose: Any,
    ft_wrench: Any,
    attributes: Mapping[str, Any] | None = None,
) -> Path:
    """Writes one push file in the dataset's layout, deterministically (same inputs, same bytes).

    The file is written to a temporary file next to ``path``, named uniquely per call
    (``.<name>.<pid>.<random hex>.partial``), and then renamed onto ``path``: an interrupted write leaves no
    truncated ``.h5``, and concurrent writers of the same file never collide (the last rename wins; with the
    same inputs they write the same bytes). A writer killed outright leaves its hidden ``.partial`` file behind.
    Parent directories are created.

    Args:
      path: the file to write.
      params: if given, ``path``'s file name must be ``push_file_name(params)``; None writes any name.
      tip_pose: [N, 4] rows [t s, x m, y m, yaw rad].
      object_pose: [M, 4] rows [t s, x m, y m, yaw rad].
      ft_wrench: [K, 4] rows [t s, fx N, fy N, torque N·m].
      attributes: extra HDF5 file attributes (str, bool, int, float or numeric array values), written in name
        order; None writes nothing extra, so the file holds exactly what a real dataset file holds.

    Returns:
      ``path`` as a Path.

    Raises:
      ValueError: a stream that is not [N, 4], holds NaN/inf or fewer than 2 distinct time stamps; a file name
        that does not match ``params``; an unsupported attribute.
    """
    path = Path(path)
    if params is not None and path.name != push_file_name(params):
        raise ValueError(f"path {str(path)!r} does not end in the file name of params, {push_file_name(params)!r}")
    streams = {name: _validated_stream(path, name, stream)
               for name, stream in zip(DATASETS, (tip_pose, object_pose, ft_wrench))}
    attributes = {} if attributes is None else attributes
    checked_attributes = {name: _validated_attribute(name, attributes[name]) for name in sorted(attributes)}

    path.parent.mkdir(parents=True, exist_ok=True)
    # A name of this writer's own, so concurrent writers of one file never share (or truncate) a temporary file;
    # "w-" refuses to open a file that already exists. Not ending in .h5, so readers never list it.
    partial = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(8)}.partial")
    try:
        with h5py.File(partial, "w-", libver=_LIBVER) as file:
            for name, stream in streams.items():
                file.create_dataset(name, data=stream, dtype="<f8", track_times=False)
            for name, value in checked_attributes.items():
                file.attrs[name] = value
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)
    return path


def _attribute_value(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_raw_push(path: str | os.PathLike) -> RawPush:
    """Reads one push file as stored (no cleaning).

    Raises:
      FileNotFoundError: no file at ``path``.
      PushFileError (a ValueError) naming the file: corrupt or truncated file, missing dataset, a stream not
        [N, 4], NaN/inf values, or fewer than 2 distinct time stamps in a stream.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no push file at {str(path)!r}")
    try:
        params = parse_push_file_name(path)
    except PushFileError:
        params = None
    try:
        with h5py.File(path, "r") as file:
            streams = {}
            for name in DATASETS:
                dataset = file.get(name)
                if not isinstance(dataset, h5py.Dataset):
                    raise PushFileError(path, "missing dataset", f"no dataset {name!r}")
                streams[name] = dataset[()]
            attributes = {name: _attribute_value(file.attrs[name]) for name in sorted(file.attrs)}
    except PushFileError:
        raise
    except (OSError, RuntimeError, KeyError, TypeError, ValueError) as error:
        # h5py reports damage in headers or attributes through any of these.
        raise PushFileError(path, "unreadable file", f"corrupt or truncated HDF5 file ({error})") from error
    return RawPush(path=path, params=params, attributes=attributes, **streams)


@dataclasses.dataclass(frozen=True, eq=False)
class Push:
    """One cleaned push, all streams on one clock.

    Attributes:
      path: the file it was read from.
      params: parameters parsed from the file name, or None if the name does not follow the layout.
      time: [T] s, starting at 0, spaced 1 / frequency.
      tip: [T, 3] pusher tip pose (x m, y m, yaw rad); yaw unwrapped (continuous, not wrapped to [-π, π]).
      object: [T, 3] object pose (x m, y m, yaw rad); yaw unwrapped.
      wrench: [T, 3] (fx N, fy N, torque N·m).
      attributes: the HDF5 file attributes, by name.
    """

    path: Path
    params: PushParams | None
    time: np.ndarray
    tip: np.ndarray
    object: np.ndarray
    wrench: np.ndarray
    attributes: Mapping[str, Any]

    @property
    def declared_effects(self) -> Any:
        """The decoded ``pushjax_effects`` JSON attribute, or None when the file declares none."""
        return _decode_effects(self.path, self.attributes)


def _clean_stream(stream: np.ndarray, unwrap_yaw: bool) -> np.ndarray:
    """Drops rows with an already-seen time stamp (keeping the first in file order), sorts by time and
    optionally unwraps the yaw column (index 3)."""
    _, first_rows = np.unique(stream[:, 0], return_index=True)
    cleaned = stream[first_rows]  # np.unique sorts by time stamp.
    if unwrap_yaw:
        cleaned[:, 3] = np.unwrap(cleaned[:, 3])
    return cleaned


def _check_frequency(frequency: float) -> None:
    if not (isinstance(frequency, (int, float, np.integer, np.floating)) and math.isfinite(frequency)
            and frequency > 0):
        raise ValueError(f"frequency must be a positive number of Hz, got {frequency!r}")


def clean_push(raw: RawPush, frequency: float = DEFAULT_FREQUENCY, zero_initial_pose: bool = False) -> Push:
    """Cleans the streams of a raw push and resamples them onto one clock.

    Per stream: rows repeating an earlier time stamp are dropped (the first in file order is kept), rows are
    sorted by time, and the yaw of the two pose streams is unwrapped. All streams are then linearly
    interpolated onto ``t0 + k / frequency`` for ``t0 <= t <= t1``, where ``[t0, t1]`` is the overlap of the
    three streams' time ranges; the returned time is shifted to start at 0.

    Args:
      raw: the push as stored.
      frequency: rate of the common clock, Hz (> 0).
      zero_initial_pose: express tip and object poses in the object's initial frame (object starts at the
        origin with yaw 0) and rotate the wrench's force into that frame; the torque about the vertical axis is
        unchanged by the rotation.

    Raises:
      ValueError: a non-positive frequency.
      PushFileError (a ValueError) naming the file: the streams' time ranges overlap on fewer than 2 samples.
    """
    _check_frequency(frequency)
    streams = {name: _clean_stream(getattr(raw, name), unwrap_yaw=name in POSE_DATASETS) for name in DATASETS}
    start = max(stream[0, 0] for stream in streams.values())
    end = min(stream[-1, 0] for stream in streams.values())
    # The tolerance keeps a sample that lands on `end` up to rounding.
    n_samples = math.floor((end - start) * frequency + 1e-9) + 1 if end >= start else 0
    if n_samples < 2:
        raise PushFileError(
            raw.path, "no time overlap",
            f"streams overlap on [{start:.6f}, {end:.6f}] s, fewer than 2 samples at {frequency} Hz",
        )
    time = np.arange(n_samples) / frequency
    query = np.minimum(start + time, end)
    tip, object_pose, wrench = (
        np.stack([np.interp(query, stream[:, 0], stream[:, column]) for column in (1, 2, 3)], axis=-1)
        for stream in streams.values()
    )
    if zero_initial_pose:
        origin, yaw0 = object_pose[0, :2].copy(), object_pose[0, 2]
        to_object_frame = planar.rotation_matrix(-yaw0)
        for pose in (tip, object_pose):
            pose[:, :2] = (pose[:, :2] - origin) @ to_object_frame.T
            pose[:, 2] -= yaw0
        wrench[:, :2] = wrench[:, :2] @ to_object_frame.T
    for array in (time, tip, object_pose, wrench):
        array.setflags(write=False)
    return Push(
        path=raw.path, params=raw.params, time=time, tip=tip, object=object_pose, wrench=wrench,
        attributes=raw.attributes,
    )


def load_push(
    path: str | os.PathLike, frequency: float = DEFAULT_FREQUENCY, zero_initial_pose: bool = False
) -> Push:
    """Reads one push file and cleans it: ``clean_push(read_raw_push(path), frequency, zero_initial_pose)``."""
    return clean_push(read_raw_push(path), frequency=frequency, zero_initial_pose=zero_initial_pose)


def _matches(value: float, targets: tuple[float, ...] | None) -> bool:
    return targets is None or any(math.isclose(value, target, rel_tol=1e-9, abs_tol=1e-6) for target in targets)


def _as_name_set(argument: str, names: Collection[str] | None) -> frozenset[str] | None:
    if names is None:
        return None
    if isinstance(names, str):
        raise ValueError(f"{argument} must be a collection of names, not the single string {names!r}")
    return frozenset(names)


def _as_number_tuple(argument: str, values: Collection[float] | None) -> tuple[float, ...] | None:
    if values is None:
        return None
    numbers = tuple(float(value) for value in values)
    if not all(math.isfinite(number) for number in numbers):
        raise ValueError(f"{argument} must hold finite numbers, got {values!r}")
    return numbers


class PushIterator:
    """Iterable over the cleaned pushes below a dataset root, reporting every file it does not yield.

    The file list is fixed at construction (sorted, so iteration order is deterministic). Files whose name does
    not parse are skipped under ``"unparseable file name"``; files that fail to load are skipped under their
    ``PushFileError.reason``. Files not ending in ``.h5`` are ignored, and files excluded by the filters are
    counted in ``n_filtered``. ``skipped`` reflects the latest pass; after each (complete or abandoned) pass a
    summary is logged with absl.logging.

    Args:
      root: dataset root directory, laid out as ``<root>/<surface>/<object>/<file>.h5``.
      objects: object names to keep (e.g. ``{"rect1"}``), or None for all.
      surfaces: surface names to keep (e.g. ``{"abs"}``), or None for all.
      velocities: pusher velocities to keep, mm/s (compared with 1e-6 tolerance), or None for all.
      accelerations: pusher accelerations to keep, mm/s² (compared with 1e-6 tolerance), or None for all.
      frequency: rate of each push's common clock, Hz.
      zero_initial_pose: see ``clean_push``.

    Filters select on the parsed file-name fields. Iterate it for ``Push`` values; ``skipped``, ``n_skipped``,
    ``n_filtered`` and ``summary()`` report the files not yielded.
    """

    def __init__(
        self,
        root: str | os.PathLike,
        objects: Collection[str] | None = None,
        surfaces: Collection[str] | None = None,
        velocities: Collection[float] | None = None,
        accelerations: Collection[float] | None = None,
        frequency: float = DEFAULT_FREQUENCY,
        zero_initial_pose: bool = False,
    ):
        self.root = Path(root)
        if not self.root.is_dir():
            raise ValueError(f"root {str(self.root)!r} is not a directory")
        _check_frequency(frequency)
        self.frequency = frequency
        self.zero_initial_pose = zero_initial_pose
        objects = _as_name_set("objects", objects)
        surfaces = _as_name_set("surfaces", surfaces)
        velocities = _as_number_tuple("velocities", velocities)
        accelerations = _as_number_tuple("accelerations", accelerations)

        self.paths: list[Path] = []
        self.n_filtered = 0
        self._unparseable: list[Path] = []
        candidates = sorted(
            (path for path in self.root.rglob("*.h5") if path.is_file()),
            key=lambda path: path.relative_to(self.root).as_posix(),
        )
        for path in candidates:
            try:
                params = parse_push_file_name(path)
            except PushFileError:
                self._unparseable.append(path)
                continue
            if (
                (objects is None or params.shape in objects)
                and (surfaces is None or params.surface in surfaces)
                and _matches(params.velocity, velocities)
                and _matches(params.acceleration, accelerations)
            ):
                self.paths.append(path)
            else:
                self.n_filtered += 1
        self._unloadable: dict[str, list[Path]] = {}
        self._first_unloadable: PushFileError | None = None
        self.n_yielded = 0

    def __iter__(self) -> Iterator[Push]:
        self._unloadable = collections.defaultdict(list)
        self._first_unloadable = None
        self.n_yielded = 0
        try:
            for path in self.paths:
                try:
                    push = load_push(path, frequency=self.frequency, zero_initial_pose=self.zero_initial_pose)
                except PushFileError as error:
                    self._unloadable[error.reason].append(path)
                    self._first_unloadable = self._first_unloadable or error
                    continue
                self.n_yielded += 1
                yield push
        finally:
            (logging.warning if self.n_skipped else logging.info)("%s", self.summary())

    @property
    def skipped(self) -> dict[str, list[Path]]:
        """Skipped files by reason (sorted by reason), for the latest pass."""
        skipped = dict(self._unloadable)
        if self._unparseable:
            skipped[_UNPARSEABLE_NAME] = list(self._unparseable)
        return {reason: skipped[reason] for reason in sorted(skipped)}

    @property
    def n_skipped(self) -> int:
        return sum(len(paths) for paths in self.skipped.values())

    def summary(self) -> str:
        """One line: pushes yielded, files filtered out, files skipped (count per reason), and the first file that
        failed to load, with what is wrong in it."""
        reasons = ", ".join(f"{reason}: {len(paths)}" for reason, paths in self.skipped.items())
        first = f"; the first that failed to load: {self._first_unloadable}" if self._first_unloadable else ""
        return (
            f"MIT push files under {str(self.root)!r}: {self.n_yielded} pushes yielded, "
            f"{self.n_filtered} filtered out, {self.n_skipped} skipped" + (f" ({reasons})" if reasons else "") + first
        )


iter_pushes = PushIterator
"""The cleaned pushes of every ``*.h5`` file below a dataset root (any depth), in sorted path order; see
:class:`PushIterator` for the arguments and the report of the files not yielded."""
