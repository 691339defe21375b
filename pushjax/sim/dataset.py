"""Simulated MIT Push Dataset recording: sample pushes from the MIT grid, simulate them in parallel, write files.

Determinism: the pushes of an (object, surface) pair are drawn one after another, push ``i`` from
``np.random.default_rng([seed, crc32(object), crc32(surface), i])`` (a push whose file name was already drawn is
drawn again from the same generator), in the calling process; each push is then simulated from the same
settled state in whichever worker, with its tracking noise drawn from a generator seeded by
``[seed, crc32(object), crc32(surface), i, repetition]``. A non-ideal testbed (:mod:`pushjax.sim.testbed`) draws
its per-surface, per-object and per-push conditions from generators seeded by the same seed, names and key
(:func:`pushjax.sim.testbed.draw_conditions`). So the same arguments give byte-identical files for any number of
workers.

Resuming: :func:`record_pushes` keeps the settings that determine every file's bytes (seed, velocities,
accelerations, repeats, effects, declare_effects, support, testbed and the MuJoCo version) in ``<out_dir>/``
:data:`MANIFEST_NAME`, written before the first file. A later call into the same folder must have the same
settings (it may ask for other objects, surfaces or push counts: under the same settings a file's name fixes its
bytes), else it is refused with :class:`OutDirConflictError`; a folder that holds ``.h5`` files but no manifest
(e.g. real MIT files) is refused too. Existing files that read as valid pushes are reused, invalid ones (truncated,
corrupt) are recorded again and counted. Several calls with the same settings may record into one folder at once.
"""

from __future__ import annotations

import dataclasses
import json
import math
import multiprocessing
import os
import secrets
import zlib
from collections.abc import Sequence
from pathlib import Path

import mujoco
import numpy as np
import tqdm
from absl import logging

from pushjax.geometry.objects import OBJECT_NAMES, get_object
from pushjax.mit.files import PushFileError, PushParams, push_file_name, push_file_path, read_raw_push, write_push
from pushjax.mit.protocol import MIT_ANGLES, MIT_VELOCITIES, sample_push, side_points
from pushjax.sim import scene
from pushjax.sim.effects import Effects
from pushjax.sim.push import Recording, implausible_speed, simulate_push
from pushjax.sim.surfaces import SURFACE_NAMES, get_surface
from pushjax.sim.testbed import IDEAL, REALISTIC, PushConditions, Testbed, draw_conditions

_MAX_DRAWS_PER_PUSH = 1000
"""Draws after which a push that keeps hitting already drawn file names gives up."""

START_POSES = ("fixed", "scattered")
"""Where pushes start: ``fixed`` is the MIT protocol (the object's tracked frame at the table origin, yaw 0, for
every push); ``scattered`` draws each push's start pose uniformly, the position within
:data:`START_SCATTER_M` of the origin along each table axis and the yaw over a whole turn, from the push's own
generator. Scattered starts tell effects fixed to the table (a friction field) from effects fixed to the object
(a moved centre of mass), which pushes from one pose cannot."""

START_SCATTER_M = 0.1
"""Half-width (m) of the square of start positions under ``start_poses="scattered"``."""

_START_POSE_STREAM = 1
"""Appended to a push's key to seed its start-pose generator apart from its push and noise draws."""

MANIFEST_NAME = "pushjax_manifest.json"
"""The file in a :func:`record_pushes` folder that holds the settings its files were recorded with."""


class OutDirConflictError(ValueError):
    """An ``out_dir`` that :func:`record_pushes` must not record into: its manifest holds other settings, the
    manifest is unreadable, or the folder holds push files but no manifest. The message names the folder."""


@dataclasses.dataclass(frozen=True)
class RecordingConfig:
    """The settings that fix the bytes of every file recorded with them (the push counts, objects and surfaces
    choose which files).

    Attributes:
      seed: seed of everything random (an integer >= 0).
      velocities: pusher velocities to draw from, mm/s (> 0), in draw order.
      accelerations: pusher accelerations to draw from, mm/s² (>= 0; 0 = constant velocity), in draw order.
      repeats: files per drawn push; more than 1 adds ``_rep=NNNN`` to the names.
      effects: effects of every push.
      declare_effects: write the effects, seed etc. as HDF5 attributes; False writes exactly the three datasets
        of a real MIT file.
      support: support mode (:data:`pushjax.sim.scene.SUPPORT_MODES`).
      testbed: the testbed profile (:mod:`pushjax.sim.testbed`); :data:`~pushjax.sim.testbed.REALISTIC` as in every
        command and dataset config, :data:`~pushjax.sim.testbed.IDEAL` gives the files recorded before testbeds
        existed.
      start_poses: where each push starts, one of :data:`START_POSES` (``fixed``: the MIT protocol).

    Raises:
      ValueError: an invalid field, naming it.
    """

    seed: int = 0
    velocities: tuple[float, ...] = MIT_VELOCITIES
    accelerations: tuple[float, ...] = (0.0,)
    repeats: int = 1
    effects: Effects = Effects()
    declare_effects: bool = True
    support: str = "grid"
    testbed: Testbed = REALISTIC
    start_poses: str = "fixed"

    def __post_init__(self):
        for name, value, low in (("repeats", self.repeats, 1), ("seed", self.seed, 0)):
            if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < low:
                raise ValueError(f"{name}: expected an integer >= {low}, got {value!r}")
        if not self.velocities or not all(isinstance(v, (int, float)) and math.isfinite(v) and v > 0
                                          for v in self.velocities):
            raise ValueError(f"velocities: expected finite velocities > 0 in mm/s, got {list(self.velocities)}")
        if not self.accelerations or not all(isinstance(a, (int, float)) and math.isfinite(a) and a >= 0
                                             for a in self.accelerations):
            raise ValueError(f"accelerations: expected finite accelerations >= 0 in mm/s², got "
                             f"{list(self.accelerations)}")
        if not isinstance(self.effects, Effects):
            raise ValueError(f"effects: expected an Effects, got {type(self.effects).__name__}")
        if self.support not in scene.SUPPORT_MODES:
            raise ValueError(f"support: expected one of {', '.join(scene.SUPPORT_MODES)}, got {self.support!r}")
        if not isinstance(self.testbed, Testbed):
            raise ValueError(f"testbed: expected a Testbed, got {type(self.testbed).__name__}")
        if self.start_poses not in START_POSES:
            raise ValueError(f"start_poses: expected one of {', '.join(START_POSES)}, got {self.start_poses!r}")
        object.__setattr__(self, "velocities", tuple(self.velocities))
        object.__setattr__(self, "accelerations", tuple(self.accelerations))

    def to_dict(self) -> dict:
        """The settings as JSON values, as the manifest holds them; ``simulator`` adds the MuJoCo version.

        A manifest written before testbeds (or start poses) existed has no ``testbed`` (``start_poses``); it counts
        as the ideal testbed (fixed starts): :data:`_LEGACY_SETTINGS`.
        """
        return {
            "seed": int(self.seed),
            "velocities": [float(velocity) for velocity in self.velocities],
            "accelerations": [float(acceleration) for acceleration in self.accelerations],
            "repeats": int(self.repeats),
            "effects": self.effects.to_dict(),
            "declare_effects": bool(self.declare_effects),
            "support": self.support,
            "testbed": self.testbed.to_dict(),
            "start_poses": self.start_poses,
            "simulator": f"mujoco {mujoco.__version__}",
        }


@dataclasses.dataclass(frozen=True)
class PushJob:
    """One file to record.

    Attributes:
      path: the output file.
      params: the push (``repetition`` set when repeats are recorded).
      effects: the effects to simulate.
      support: the support mode.
      noise_seed: entropy of the tracking-noise generator; under a non-ideal testbed also the push's key of
        :func:`pushjax.sim.testbed.draw_conditions`, whose first element is the data set's seed.
      attributes: the HDF5 attributes to write, or None for a file with the three datasets only.
      testbed: the testbed profile (:mod:`pushjax.sim.testbed`).
      initial_pose: (x m, y m, yaw rad) of the object's tracked frame when the push starts.
    """

    path: Path
    params: PushParams
    effects: Effects
    support: str
    noise_seed: tuple[int, ...]
    attributes: dict | None
    testbed: Testbed = IDEAL
    initial_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclasses.dataclass(frozen=True)
class RecordSummary:
    """What :func:`record_pushes` did.

    Attributes:
      written: the files recorded by this call, in plan order.
      skipped: existing files that read as valid pushes and were kept, in plan order.
      rerecorded: the written files that replaced an existing invalid (truncated, corrupt) file.
    """

    written: list[Path]
    skipped: list[Path]
    rerecorded: list[Path]


def _name_key(name: str) -> int:
    return zlib.crc32(name.encode("utf-8"))


def plan_pushes(
    out_dir: str | os.PathLike,
    objects: Sequence[str],
    surfaces: Sequence[str],
    pushes: int,
    settings: RecordingConfig = RecordingConfig(),
) -> list[PushJob]:
    """The files to record, in a deterministic order; arguments as in :func:`record_pushes`."""
    _check_selection(objects, surfaces, pushes)
    if not isinstance(settings, RecordingConfig):
        raise ValueError(f"settings: expected a RecordingConfig, got {type(settings).__name__}")
    seed, effects, support, testbed = settings.seed, settings.effects, settings.support, settings.testbed
    jobs = []
    for obj in objects:
        shape = get_object(obj)
        grid_size = (len(shape.sides) * len(side_points(shape)) * len(MIT_ANGLES) * len(set(settings.velocities))
                     * len(set(settings.accelerations)))
        if pushes > grid_size:
            raise ValueError(f"pushes: {obj} has only {grid_size} distinct pushes on this grid, asked for {pushes}")
        for surface in surfaces:
            taken = set()
            for index in range(pushes):
                key = (seed, _name_key(obj), _name_key(surface), index)
                rng = np.random.default_rng(key)
                for _ in range(_MAX_DRAWS_PER_PUSH):
                    params = sample_push(shape, surface, rng, settings.velocities, settings.accelerations)
                    if push_file_name(params) not in taken:
                        break
                else:
                    raise ValueError(f"pushes: could not draw {pushes} distinct pushes of {obj} on {surface}")
                taken.add(push_file_name(params))
                initial_pose = _start_pose(settings.start_poses, key)
                for repetition in range(settings.repeats):
                    repeated = dataclasses.replace(params, repetition=repetition if settings.repeats > 1 else None)
                    attributes = None
                    if settings.declare_effects:
                        attributes = {
                            "pushjax_effects": effects.to_json(),
                            "pushjax_seed": int(seed),
                            "pushjax_push_index": index,
                            "pushjax_support": support,
                            "pushjax_object_friction": get_surface(surface).object_friction,
                            "pushjax_pusher_friction": scene.pusher_friction(effects),
                            "pushjax_initial_pose": np.asarray(initial_pose),
                            "pushjax_simulator": f"mujoco {mujoco.__version__}",
                        }
                        if not testbed.ideal:
                            attributes["pushjax_testbed"] = testbed.to_json()
                    jobs.append(PushJob(
                        path=push_file_path(out_dir, repeated), params=repeated, effects=effects, support=support,
                        noise_seed=key + (repetition,), attributes=attributes, testbed=testbed,
                        initial_pose=initial_pose))
    return jobs


def _start_pose(start_poses: str, key: tuple[int, ...]) -> tuple[float, float, float]:
    if start_poses == "fixed":
        return (0.0, 0.0, 0.0)
    rng = np.random.default_rng(key + (_START_POSE_STREAM,))
    x, y = rng.uniform(-START_SCATTER_M, START_SCATTER_M, size=2)
    return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))


def job_conditions(job: PushJob) -> PushConditions | None:
    """The testbed's draw for a planned push (:func:`pushjax.sim.testbed.draw_conditions`); None if ideal."""
    if job.testbed.ideal:
        return None
    supports = len(scene.support_points(job.params.shape, job.support)[0])
    return draw_conditions(job.testbed, job.noise_seed[0], job.params.shape, job.params.surface, job.noise_seed,
                           supports)


def drawn_relative_sd(jobs: Sequence[PushJob], draw: str = "pusher_friction_factor") -> float:
    """Sample relative standard deviation (sd over mean, ddof 1) of one scalar testbed draw
    (:meth:`pushjax.sim.testbed.PushConditions.draws`'s key ``draw``) over planned pushes; 0 on the ideal testbed or
    for fewer than two pushes. Read from the plan, so it holds for files that do not declare their draws too."""
    factors = [conditions.draws()[draw] for job in jobs if (conditions := job_conditions(job)) is not None]
    return float(np.std(factors, ddof=1) / np.mean(factors)) if len(factors) > 1 else 0.0


def simulate_job(job: PushJob) -> Recording:
    """Simulates one planned push, with its tracking noise and testbed draw, without writing it."""
    rng = np.random.default_rng(job.noise_seed)
    return simulate_push(dataclasses.replace(job.params, repetition=None), job.effects, job.support,
                         initial_pose=job.initial_pose, rng=rng, conditions=job_conditions(job))


def record_push(job: PushJob) -> Path:
    """Simulates one planned push (:func:`simulate_job`) and writes its file (atomically).

    Under a non-ideal testbed a declaring file also gets ``pushjax_testbed_draw``, the JSON of the push's scalar
    draws (:meth:`pushjax.sim.testbed.PushConditions.draws`).
    """
    attributes = job.attributes
    if attributes is not None and not job.testbed.ideal:
        attributes = {**attributes, "pushjax_testbed_draw": json.dumps(job_conditions(job).draws(), sort_keys=True)}
    recording = simulate_job(job)
    if recording.line_shift:
        logging.warning("%s: simulated again with the pusher's line %g mm along the side (a degenerate corner "
                        "contact flung the plate)", job.path, recording.line_shift * 1000)
        if attributes is not None:
            attributes = {**attributes, "pushjax_line_shift_m": recording.line_shift}
    return write_push(job.path, job.params, recording.tip_pose, recording.object_pose, recording.ft_wrench,
                      attributes=attributes)


def record_pushes(
    out_dir: str | os.PathLike,
    objects: Sequence[str],
    surfaces: Sequence[str],
    pushes: int,
    settings: RecordingConfig = RecordingConfig(),
    workers: int | None = None,
    progress: bool = True,
) -> RecordSummary:
    """Records simulated pushes as MIT raw files under ``out_dir/<surface>/<object>/``.

    Resumable: files that already exist and read as valid pushes (``pushjax.mit.read_raw_push``) are kept, invalid
    ones are recorded again. ``out_dir/pushjax_manifest.json`` (:data:`MANIFEST_NAME`) records the settings that fix
    the files' bytes (:meth:`RecordingConfig.to_dict`); a call whose settings differ from it is refused (see the
    module docstring).

    Args:
      out_dir: dataset root; new, empty, or recorded by earlier calls with the same settings.
      objects: object names (``pushjax.geometry.OBJECT_NAMES``).
      surfaces: surface names (``abs``, ``delrin``, ``plywood``, ``pu``).
      pushes: distinct pushes per (object, surface), drawn from the MIT grid.
      settings: the settings that fix the files' bytes (default: the realistic testbed).
      workers: worker processes (default: all cores); 1 records in this process.
      progress: show a tqdm progress bar.

    Returns:
      The :class:`RecordSummary`.

    Raises:
      OutDirConflictError: ``out_dir``'s manifest holds other settings (the message names each differing
        setting), or ``out_dir`` holds ``.h5`` files but no manifest; nothing is written then.
      ValueError: an invalid argument, naming it.
    """
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")
    jobs = plan_pushes(out_dir, objects, surfaces, pushes, settings)
    _claim_out_dir(Path(out_dir), settings.to_dict())
    skipped, todo, invalid = [], [], {}
    for job in jobs:
        if not job.path.exists():
            todo.append(job)
        elif problem := recorded_file_problem(job):
            invalid[job.path] = problem
            todo.append(job)
        else:
            skipped.append(job.path)
    if invalid:
        logging.warning("recording again %d invalid existing files under %s (first: %s)", len(invalid),
                        out_dir, next(iter(invalid.values())))
    workers = min(workers or os.cpu_count() or 1, max(1, len(todo)))
    written = []
    with tqdm.tqdm(total=len(todo), disable=not progress, unit="push", desc="recording") as bar:
        if workers == 1:
            for job in todo:
                written.append(record_push(job))
                bar.update()
        else:
            context = multiprocessing.get_context("spawn")
            chunk = max(1, min(8, math.ceil(len(todo) / (4 * workers))))
            with context.Pool(workers) as pool:
                for path in pool.imap(record_push, todo, chunksize=chunk):
                    written.append(path)
                    bar.update()
    return RecordSummary(written=written, skipped=skipped,
                         rerecorded=[path for path in written if path in invalid])


def recorded_file_problem(job: PushJob) -> str | None:
    """Why the existing file of a recorded push must be recorded again, or None if it may be kept.

    A file must be recorded again when it does not read as a valid push, or when its object moves implausibly
    fast (:func:`pushjax.sim.push.implausible_speed`: recorded before that check existed).
    """
    try:
        push = read_raw_push(job.path)
    except PushFileError as error:
        return str(error)
    if (speed := implausible_speed(push.object_pose, job.params)) is not None:
        return (f"{job.path}: the object moves at {speed * 1000:.0f} mm/s behind a pusher at "
                f"{job.params.velocity_si * 1000:.0f} mm/s")
    return None


_LEGACY_SETTINGS = {"testbed": IDEAL.to_dict(), "start_poses": "fixed"}
"""Settings that manifests written before they existed hold implicitly."""


def _claim_out_dir(out_dir: Path, settings: dict) -> None:
    """Writes ``out_dir``'s manifest if it has none, then checks that it holds ``settings``.

    The manifest is published with ``os.link`` from a temporary file of this call's own: it appears complete or
    not at all, and an existing one is never replaced, so concurrent calls all check against the first one's.

    Raises:
      OutDirConflictError: see :func:`record_pushes`.
    """
    manifest = out_dir / MANIFEST_NAME
    if not manifest.exists():
        push_files = sum(1 for _ in out_dir.rglob("*.h5")) if out_dir.is_dir() else 0
        # A concurrent call publishes its manifest before its first file, so files seen without one are foreign.
        if push_files and not manifest.exists():
            raise OutDirConflictError(
                f"out_dir: {out_dir} holds {push_files} .h5 file(s) but no {MANIFEST_NAME}, so record_pushes did "
                "not make it; record into a new or empty folder")
        if not push_files:
            out_dir.mkdir(parents=True, exist_ok=True)
            text = json.dumps({"generator": "pushjax.sim.dataset.record_pushes", "settings": settings},
                              indent=2, sort_keys=True) + "\n"
            partial = out_dir / f".{MANIFEST_NAME}.{os.getpid()}.{secrets.token_hex(8)}.partial"
            partial.write_text(text, encoding="utf-8")
            try:
                os.link(partial, manifest)
            except FileExistsError:
                pass  # a concurrent call published first; its manifest is checked below
            finally:
                partial.unlink()
    try:
        recorded = json.loads(manifest.read_text(encoding="utf-8"))["settings"]
        if not isinstance(recorded, dict):
            raise TypeError(f"settings must be a JSON object, got {type(recorded).__name__}")
        recorded = {**_LEGACY_SETTINGS, **recorded}
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError) as error:
        raise OutDirConflictError(
            f"out_dir: {manifest} is not a readable record_pushes manifest ({error!r}); record into a new folder"
        ) from None
    differing = [_difference(name, recorded.get(name), value)
                 for name, value in settings.items() if recorded.get(name) != value]
    if differing:
        raise OutDirConflictError(
            f"out_dir: {out_dir} was recorded with other settings ({MANIFEST_NAME}): {'; '.join(differing)}; "
            "record into another folder or use the recorded settings")


def _check_selection(objects, surfaces, pushes):
    for name, values, known in (("objects", objects, OBJECT_NAMES), ("surfaces", surfaces, SURFACE_NAMES)):
        if isinstance(values, str) or not values:
            raise ValueError(f"{name}: expected a non-empty list of names from {', '.join(known)}, got {values!r}")
        unknown = [value for value in values if value not in known]
        if unknown:
            raise ValueError(f"{name}: unknown {', '.join(map(repr, unknown))}; expected names from {', '.join(known)}")
        if len(set(values)) != len(values):
            raise ValueError(f"{name}: names repeat in {list(values)}")
    if not isinstance(pushes, (int, np.integer)) or isinstance(pushes, bool) or pushes < 1:
        raise ValueError(f"pushes: expected an integer >= 1, got {pushes!r}")


def _difference(name: str, recorded, requested) -> str:
    """``name recorded there, requested now``; for two dicts (effects) only their differing fields."""
    if isinstance(recorded, dict) and isinstance(requested, dict):
        fields = [field for field in sorted(set(recorded) | set(requested))
                  if recorded.get(field) != requested.get(field)]
        parts = [_difference(field, recorded.get(field), requested.get(field)) for field in fields]
        return f"{name} ({', '.join(parts)})"
    return f"{name} {json.dumps(recorded)} there, {json.dumps(requested)} now"
