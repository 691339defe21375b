"""Simulated MIT Push Dataset recording: sample pushes from the MIT grid, simulate them in parallel, write files.

Determinism: the pushes of an (object, surface) pair are drawn one after another, push ``i`` from
``np.random.default_rng([seed, crc32(object), crc32(surface), i])`` (a push whose file name was already drawn is
drawn again from the same generator), in the calling process; each push is then simulated from the same
settled state in whichever worker, with its tracking noise drawn from a generator seeded by
``[seed, crc32(object), crc32(surface), i, repetition]``. So the same arguments give byte-identical files for
any number of workers, and existing files are skipped (the run can be resumed).
"""

from __future__ import annotations

import dataclasses
import math
import multiprocessing
import os
import zlib
from collections.abc import Sequence
from pathlib import Path

import mujoco
import numpy as np
import tqdm

from pushjax.data.mit_push import PushParams, push_file_name, push_file_path, write_push
from pushjax.geometry.objects import OBJECT_NAMES, get_object
from pushjax.sim import scene
from pushjax.sim.effects import Effects
from pushjax.sim.push import MIT_ANGLES, MIT_VELOCITIES, sample_push, side_points, simulate_push
from pushjax.sim.surfaces import SURFACE_NAMES, get_surface

_MAX_DRAWS_PER_PUSH = 1000
"""Draws after which a push that keeps hitting already drawn file names gives up."""


@dataclasses.dataclass(frozen=True)
class PushJob:
    """One file to record.

    Attributes:
      path: the output file.
      params: the push (``repetition`` set when repeats are recorded).
      effects: the effects to simulate.
      support: the support mode.
      noise_seed: entropy of the tracking-noise generator.
      attributes: the HDF5 attributes to write, or None for a file with the three datasets only.
    """

    path: Path
    params: PushParams
    effects: Effects
    support: str
    noise_seed: tuple[int, ...]
    attributes: dict | None


@dataclasses.dataclass(frozen=True)
class RecordSummary:
    """What :func:`record_pushes` did: ``written`` new files and ``skipped`` files that already existed."""

    written: list[Path]
    skipped: list[Path]


def _name_key(name: str) -> int:
    return zlib.crc32(name.encode("utf-8"))


def plan_pushes(
    out_dir: str | os.PathLike,
    objects: Sequence[str],
    surfaces: Sequence[str],
    pushes: int,
    seed: int = 0,
    velocities: Sequence[float] = MIT_VELOCITIES,
    accelerations: Sequence[float] = (0.0,),
    repeats: int = 1,
    effects: Effects = Effects(),
    declare_effects: bool = True,
    support: str = "grid",
) -> list[PushJob]:
    """The files to record, in a deterministic order; arguments as in :func:`record_pushes`."""
    _check_arguments(objects, surfaces, pushes, seed, velocities, accelerations, repeats, effects, support)
    jobs = []
    for obj in objects:
        shape = get_object(obj)
        grid_size = (len(shape.sides) * len(side_points(shape)) * len(MIT_ANGLES) * len(set(velocities))
                     * len(set(accelerations)))
        if pushes > grid_size:
            raise ValueError(f"pushes: {obj} has only {grid_size} distinct pushes on this grid, asked for {pushes}")
        for surface in surfaces:
            taken = set()
            for index in range(pushes):
                key = (seed, _name_key(obj), _name_key(surface), index)
                rng = np.random.default_rng(key)
                for _ in range(_MAX_DRAWS_PER_PUSH):
                    params = sample_push(shape, surface, rng, velocities, accelerations)
                    if push_file_name(params) not in taken:
                        break
                else:
                    raise ValueError(f"pushes: could not draw {pushes} distinct pushes of {obj} on {surface}")
                taken.add(push_file_name(params))
                for repetition in range(repeats):
                    repeated = dataclasses.replace(params, repetition=repetition if repeats > 1 else None)
                    attributes = None
                    if declare_effects:
                        attributes = {
                            "pushjax_effects": effects.to_json(),
                            "pushjax_seed": int(seed),
                            "pushjax_push_index": index,
                            "pushjax_support": support,
                            "pushjax_object_friction": get_surface(surface).object_friction,
                            "pushjax_pusher_friction": scene.pusher_friction(effects),
                            "pushjax_initial_pose": np.zeros(3),
                            "pushjax_simulator": f"mujoco {mujoco.__version__}",
                        }
                    jobs.append(PushJob(
                        path=push_file_path(out_dir, repeated), params=repeated, effects=effects, support=support,
                        noise_seed=key + (repetition,), attributes=attributes))
    return jobs


def record_push(job: PushJob) -> Path:
    """Simulates one planned push and writes its file (atomically)."""
    rng = np.random.default_rng(job.noise_seed)
    recording = simulate_push(dataclasses.replace(job.params, repetition=None), job.effects, job.support, rng=rng)
    return write_push(job.path, job.params, recording.tip_pose, recording.object_pose, recording.ft_wrench,
                      attributes=job.attributes)


def record_pushes(
    out_dir: str | os.PathLike,
    objects: Sequence[str],
    surfaces: Sequence[str],
    pushes: int,
    seed: int = 0,
    velocities: Sequence[float] = MIT_VELOCITIES,
    accelerations: Sequence[float] = (0.0,),
    repeats: int = 1,
    effects: Effects = Effects(),
    declare_effects: bool = True,
    support: str = "grid",
    workers: int | None = None,
    progress: bool = True,
) -> RecordSummary:
    """Records simulated pushes as MIT raw files under ``out_dir/<surface>/<object>/``.

    Args:
      out_dir: dataset root.
      objects: object names (``pushjax.geometry.OBJECT_NAMES``).
      surfaces: surface names (``abs``, ``delrin``, ``plywood``, ``pu``).
      pushes: distinct pushes per (object, surface), drawn from the MIT grid.
      seed: seed of everything random.
      velocities: pusher velocities to draw from, mm/s (> 0).
      accelerations: pusher accelerations to draw from, mm/s² (>= 0; 0 = constant velocity).
      repeats: files per drawn push; more than 1 adds ``_rep=NNNN`` to the names.
      effects: effects of every push.
      declare_effects: write the effects, seed etc. as HDF5 attributes; False writes exactly the three datasets
        of a real MIT file.
      support: support mode (``grid`` or ``hull``).
      workers: worker processes (default: all cores); 1 records in this process.
      progress: show a tqdm progress bar.

    Returns:
      The :class:`RecordSummary`.
    """
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")
    jobs = plan_pushes(out_dir, objects, surfaces, pushes, seed, velocities, accelerations, repeats, effects,
                       declare_effects, support)
    skipped = [job.path for job in jobs if job.path.exists()]
    todo = [job for job in jobs if not job.path.exists()]
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
    return RecordSummary(written=written, skipped=skipped)


def _check_arguments(objects, surfaces, pushes, seed, velocities, accelerations, repeats, effects, support):
    for name, values, known in (("objects", objects, OBJECT_NAMES), ("surfaces", surfaces, SURFACE_NAMES)):
        if isinstance(values, str) or not values:
            raise ValueError(f"{name}: expected a non-empty list of names from {', '.join(known)}, got {values!r}")
        unknown = [value for value in values if value not in known]
        if unknown:
            raise ValueError(f"{name}: unknown {', '.join(map(repr, unknown))}; expected names from {', '.join(known)}")
        if len(set(values)) != len(values):
            raise ValueError(f"{name}: names repeat in {list(values)}")
    for name, value, low in (("pushes", pushes, 1), ("repeats", repeats, 1), ("seed", seed, 0)):
        if not isinstance(value, (int, np.integer)) or isinstance(value, bool) or value < low:
            raise ValueError(f"{name}: expected an integer >= {low}, got {value!r}")
    if not velocities or not all(isinstance(v, (int, float)) and math.isfinite(v) and v > 0 for v in velocities):
        raise ValueError(f"velocities: expected finite velocities > 0 in mm/s, got {list(velocities)}")
    if not accelerations or not all(isinstance(a, (int, float)) and math.isfinite(a) and a >= 0
                                    for a in accelerations):
        raise ValueError(f"accelerations: expected finite accelerations >= 0 in mm/s², got {list(accelerations)}")
    if not isinstance(effects, Effects):
        raise ValueError(f"effects: expected an Effects, got {type(effects).__name__}")
    if support not in scene.SUPPORT_MODES:
        raise ValueError(f"support: expected one of {', '.join(scene.SUPPORT_MODES)}, got {support!r}")
