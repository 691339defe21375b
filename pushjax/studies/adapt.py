"""Learn while pushing: the controller closes the loop on the pushes it makes (``python -m experiments.adapt``).

A **world** (:func:`pushjax.studies.worlds.draw_world`) is the realistic testbed with one effect the controller's model
does not declare (:data:`pushjax.studies.worlds.EFFECTS`: ``tilt``, ``com_offset``, ``pusher_friction``,
``friction_variability``), its magnitude drawn from the world's seed.

In each world the controller (:func:`pushjax.studies.episode.run_episode`: motion capture and the EKF) pushes
the objects to a sequence of ``first_block + (blocks - 1) * per_block`` goals (:func:`pushjax.control.goals.draw_goals`
with the world's seed, the objects taking turns) four ways, the **arms** (:data:`ARMS`), on the same goals with the
same testbed draws (paired by goal):

``adaptive``  records every episode as a push file in the MIT layout (:func:`episode_push_path`); after every block of
              episodes (the first of ``first_block``, the others of ``per_block``) the loop
              (:func:`pushjax.loop.close_loop`) runs on ALL the pushes it recorded so far (its own pushes, not protocol
              pushes) and the next block plans with the model it selected (its ``model.json``: effects, parameters
              and the pusher friction the force sensor measured). Until the loop can run (it needs
              :func:`pushjax.loop.splits.minimum_sequences` push sequences, one per episode) the controller plans with
              plain Lynch, and the reason is recorded;
``plain``     plain Lynch with the nominal pusher friction throughout (no adaptation);
``oracle``    the model that knows the world's effect and magnitude (``World.oracle``): ``table_tilt`` with the
              drift force ``tan(tilt) / mu_surface`` downhill, ``cof_offset`` at the moved centre of mass, the true
              pusher friction, or for the variability its mean ``0.25 exp(sigma^2 / 2)``;
``filtered``  plain Lynch whose pusher friction follows, within each episode, what the EKF infers of it (its latent
              ``log_mu_scale``, :attr:`pushjax.studies.episode.EpisodeConfig.filtered_friction`), updated before
              every plan: learning within a push instead of across pushes.

An episode is a function of the world, the goal and the planned-with model, so an arm that plans with the same model as
another on a goal (``adaptive`` before the loop can run, and wherever the loop's model is plain Lynch's) reuses that
episode instead of simulating it again.

Per arm and block: the success rate (:func:`pushjax.control.goals.succeeded`: within 5 mm and 5 degrees), the time to
goal (the simulated seconds of a success; a failure counts as ``max_time``, as in
:func:`pushjax.studies.push_to_goal.compare`) and the pusher's path length; for ``adaptive`` what the loop selected
after each block. The comparison rules, fixed before any run, are :data:`COMPARISON_RULE` (does the loop close the
gap) and :data:`FILTER_RULE` (does the filter's friction within an episode beat plain Lynch).

Outputs (:func:`write`): ``results.json``, ``results.md`` and ``time_to_goal.png`` in the work folder; below it
``<effect>/world=<seed>/pushes`` (the adaptive arm's push files) and ``<effect>/world=<seed>/loop/block=<b>`` (the
loop's reports), ``<effect>/world=<seed>/episodes`` (every arm's finished episodes, so that a run over the same work
folder resumes where an interrupted one stopped: :func:`run`). Same config, same bytes (wall-clock times are not
recorded), whether the run was interrupted or not.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import shutil
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import tqdm

from pushjax import outputs, stats
from pushjax.control import goals, gradient, mpc
from pushjax.control.model import make_model
from pushjax.geometry.objects import OBJECT_NAMES
from pushjax.loop import LoopConfig, close_loop
from pushjax.loop.correction import CorrectionConfig
from pushjax.loop.fit import FitConfig
from pushjax.mit.files import PushParams, push_file_name, write_push
from pushjax.physics.model_file import AugmentedModel
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION, SURFACE_NAMES
from pushjax.sim.testbed import REALISTIC, Testbed
from pushjax.studies import adapt_report, episode
from pushjax.studies.worlds import EFFECTS, World, draw_world

__all__ = ["ARMS", "AdaptConfig", "COMPARISON_RULE", "FILTER_RULE", "GAP_SHARE", "SCALES", "STANDARD_ERRORS", "compare",
           "compare_filtered",
           "episode_push_path", "make_config", "run", "write"]

ARMS = ("adaptive", "plain", "oracle", "filtered")
"""The controllers compared on every goal."""

GAP_SHARE = 0.5
"""Share of the plain-oracle gap in time to goal that the adaptive controller must close."""
STANDARD_ERRORS = stats.DECISION_STANDARD_ERRORS
"""Standard errors (over world seeds) by which the decision must clear zero (:func:`pushjax.stats.decide`)."""
COMPARISON_RULE = (
    f"Fixed before any run. Per effect, in the LAST block, on the same goals (paired by goal): for every world seed w, "
    f"d_w = mean over the block's goals of (t_plain - t_adaptive) - {GAP_SHARE:g} (t_plain - t_oracle), t the time to "
    f"goal in s (a failed goal counts as max_time). The adaptive controller closes at least {GAP_SHARE:.0%} of the "
    f"plain-oracle gap when mean_w d_w > {STANDARD_ERRORS:g} standard errors of that mean over world seeds (the "
    f"resampling unit: a world's effect magnitude, goals and testbed draws are drawn together, and its goals share "
    f"the adaptive model, so goals within a world are not independent); it falls short when mean_w d_w < "
    f"-{STANDARD_ERRORS:g} standard errors; otherwise (or with one world seed, which gives no standard error) it is "
    f"not decided. This is the project's decision rule (pushjax.stats.decide) on the paired difference -d_w.")
"""The comparison rule (:func:`compare`), committed before any run."""
FILTER_RULE = (
    f"Fixed before any run. Per effect, over every block's goals (the filter learns within an episode, whatever the "
    f"block), paired by goal: for every world seed w, e_w = mean over the world's goals of (t_filtered - t_plain), t "
    f"the time to goal in s (a failed goal counts as max_time). Planning with the filter's friction helps when mean_w "
    f"e_w < -{STANDARD_ERRORS:g} standard errors of that mean over world seeds, hurts when it is > "
    f"+{STANDARD_ERRORS:g}, else (or with one world seed) not decided: pushjax.stats.decide on e_w.")
"""The rule of :func:`compare_filtered`, committed before any run."""

EPISODE_FOLDER = "episode={:04d}"
"""The folder of an episode's push file below its object's folder: one push sequence per episode
(:func:`pushjax.loop.windows.build_examples`)."""


@dataclasses.dataclass(frozen=True)
class AdaptConfig:
    """What a run of the study does.

    Attributes:
      effects: the worlds' effects, from :data:`pushjax.studies.worlds.EFFECTS`, no repeats.
      objects: the pushed objects (taking turns through the goals), from ``OBJECT_NAMES``, no repeats.
      worlds: world seeds per effect: ``seed, seed + 1, ...``.
      blocks: blocks of episodes per world.
      per_block: episodes per block (K): the loop runs after every block.
      first_block: episodes in the first block (None: ``per_block``): the loop first runs after them, so a first block
        of :func:`pushjax.loop.splits.minimum_sequences` episodes (one push sequence each) lets the second block
        plan with what the loop selected.
      max_time: simulated seconds per goal (a failed goal's time to goal).
      controller: the controller's settings (:class:`pushjax.control.mpc.ControllerConfig`).
      loop: the loop's settings (:class:`pushjax.loop.LoopConfig`).
      surface: the table's surface.
      testbed: the testbed profile the effect is added to.
      seed: the first world seed.
    """

    effects: tuple[str, ...]
    objects: tuple[str, ...]
    worlds: int
    blocks: int
    per_block: int
    max_time: float
    controller: mpc.ControllerConfig
    loop: LoopConfig
    first_block: int | None = None
    surface: str = "abs"
    testbed: Testbed = REALISTIC
    seed: int = 0

    def __post_init__(self):
        object.__setattr__(self, "effects", tuple(self.effects))
        object.__setattr__(self, "objects", tuple(self.objects))
        for name, values, known in (("effects", self.effects, EFFECTS), ("objects", self.objects, OBJECT_NAMES)):
            if not values or len(set(values)) != len(values) or not set(values) <= set(known):
                raise ValueError(f"{name}: expected a non-empty list from {','.join(known)}, no repeats, got "
                                 f"{','.join(values) or 'none'}")
        for name in ("worlds", "blocks", "per_block", "first_block"):
            value = getattr(self, name)
            if name == "first_block" and value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"{name}: expected a whole number >= 1, got {value!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ValueError(f"seed: expected a whole number >= 0, got {self.seed!r}")
        if not (math.isfinite(self.max_time) and self.max_time >= 1):
            raise ValueError(f"max_time: expected a finite number of seconds >= 1, got {self.max_time!r}")
        if self.surface not in SURFACE_NAMES:
            raise ValueError(f"surface: expected one of {','.join(SURFACE_NAMES)}, got {self.surface!r}")
        if self.testbed.ideal:
            raise ValueError("testbed: expected a testbed with motion capture and draws (not the ideal profile), "
                             "whose pusher_friction_sigma the friction_variability effect replaces")

    @property
    def world_seeds(self) -> tuple[int, ...]:
        return tuple(range(self.seed, self.seed + self.worlds))

    @property
    def episodes(self) -> int:
        """Episodes per world and arm."""
        return self.block_start(self.blocks)

    def block_start(self, block: int) -> int:
        """The number of the first episode of block `block` (0-based; ``blocks``: the episodes in all)."""
        first = self.per_block if self.first_block is None else self.first_block
        return 0 if block == 0 else first + (block - 1) * self.per_block

    def as_dict(self) -> dict:
        """The settings as JSON-able values."""
        return {"effects": list(self.effects), "objects": list(self.objects), "worlds": self.worlds,
                "world_seeds": list(self.world_seeds), "blocks": self.blocks, "per_block": self.per_block,
                "first_block": self.block_start(1), "max_time": self.max_time, "controller": repr(self.controller),
                "loop": dataclasses.asdict(self.loop), "surface": self.surface, "testbed": self.testbed.to_dict(),
                "seed": self.seed}


_SMOKE_CONTROLLER = mpc.ControllerConfig(horizon=8, gradient=gradient.GradientConfig(iterations=15), candidates=16)
SCALES = {
    # A test of the whole path: one object and world; a first block of 16 episodes of 6 s (the loop needs 12 push
    # sequences, and the force sensor 8 sliding ones among the 12 it does not test on: 10 slide), after which the loop
    # runs on the controller's own pushes and the second block (2 episodes) plans with its model. The pusher friction
    # is the world's effect and the loop's one candidate: the force sensor measures it, so the loop's model plans with
    # the measured coefficient instead of the nominal 0.25, and the arms share one compiled controller (the friction
    # only changes the model's mu). A reduced fit, bootstrap and learned error term.
    "smoke": AdaptConfig(effects=("pusher_friction",), objects=("rect1",), worlds=1, blocks=2, per_block=2,
                         first_block=16, max_time=6.0, controller=_SMOKE_CONTROLLER,
                         loop=LoopConfig(stride=0.5, n_bootstrap=100, effects=("pusher_friction",),
                                           fit=FitConfig(steps=20, warm_steps=10),
                                           correction=CorrectionConfig(steps=100, eval_every=50, hidden=(16,)))),
    # Every effect in 3 worlds; 4 blocks of 6 goals: the loop first runs after 12 episodes (block 2), so blocks 3 and
    # 4 plan with what it selected. About 3 x 24 episodes of at most 30 s per world, and 4 loop runs.
    "cpu": AdaptConfig(effects=EFFECTS, objects=("rect1",), worlds=3, blocks=4, per_block=6, max_time=30.0,
                       controller=mpc.ControllerConfig(), loop=LoopConfig()),
}
"""The study's scales, defined here and only here."""


def make_config(scale: str, **overrides) -> AdaptConfig:
    """``SCALES[scale]`` with the fields in `overrides` that are not None replaced (validated: ValueError naming the
    field)."""
    if scale not in SCALES:
        raise ValueError(f"scale: expected one of {','.join(SCALES)}, got {scale!r}")
    return dataclasses.replace(SCALES[scale], **{key: value for key, value in overrides.items() if value is not None})


def episode_push_path(data_dir: str | Path, surface: str, obj: str, episode: int, speed_limit: float) -> Path:
    """The push file of episode `episode` (its number in the world's sequence) in the MIT layout, one folder per
    episode so that each is a push sequence of its own (:func:`pushjax.loop.windows.build_examples`):
    ``<data_dir>/<surface>/<obj>/episode=<NNNN>/motion_surface=<surface>_shape=<obj>_a=0_v=<speed limit, mm/s>_i=0_
    s=0.000_t=0.000.h5``. The file-name fields of an episode: ``a=0`` (no protocol acceleration), ``v`` the
    controller's speed limit in mm/s, and ``i``, ``s``, ``t`` 0, since the controller chooses its contacts (side,
    point and angle) anew every plan; fields equal in every push are no candidate variables of the loop's
    diagnosis."""
    params = PushParams(surface=surface, shape=obj, acceleration=0.0, velocity=round(speed_limit * 1e3, 6), side=0,
                        point=0.0, angle=0.0)
    return Path(data_dir) / surface / obj / EPISODE_FOLDER.format(episode) / push_file_name(params)


def _tasks(objects: Sequence[str], count: int, seed: int) -> list[goals.Goal]:
    """The world's first `count` goals, the objects taking turns (goal index first, then object order)."""
    drawn = goals.draw_goals(objects, math.ceil(count / len(objects)), seed)
    order = {obj: k for k, obj in enumerate(objects)}
    return sorted(drawn, key=lambda task: (task.index, order[task.obj]))[:count]


EPISODE_RECORD = "episodes/" + EPISODE_FOLDER + "/{}.json"
"""An arm's finished episode below its world's folder (:func:`run`): ``episodes/episode=<NNNN>/<arm>.json``."""
LOOP_RECORD = "adapt_record.json"
"""What the next block plans with, in the loop's report folder of the block (:func:`run`)."""


def _digest(inputs: dict) -> str:
    return hashlib.sha256(json.dumps(inputs, sort_keys=True, default=repr).encode("utf-8")).hexdigest()


def _read_record(path: Path, key: str) -> dict | None:
    """The record in `path` when it is finished and was made from the inputs whose digest is `key`; else None."""
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return record if isinstance(record, dict) and record.get("key") == key else None


def _write_record(path: Path, record: dict) -> dict:
    """Writes `record` as JSON to `path` through a temporary file renamed into place (an interrupted write leaves no
    record, only a hidden ``.partial`` file); returns the record as it reads back."""
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(record, indent=1, sort_keys=True) + "\n"
    partial = path.with_name(f".{path.name}.{os.getpid()}.partial")
    partial.write_text(text)
    os.replace(partial, path)
    return json.loads(text)


def _episode_inputs(config: AdaptConfig, world: World, task: goals.Goal, spec: AugmentedModel,
                    filtered_friction: bool = False) -> dict:
    """Everything an episode is a function of (the world, the goal, the planned-with model and whether its friction
    follows the filter, the settings)."""
    return {**({"filtered_friction": True} if filtered_friction else {}), "effect": world.effect, "world": world.seed, "magnitude": world.magnitude,
            "testbed": world.testbed.to_dict(), "effects": repr(world.effects[task.obj]), "object": task.obj,
            "index": task.index, "start": [float(value) for value in task.start],
            "goal": [float(value) for value in task.goal], "model": spec.as_dict(),
            "controller": repr(config.controller), "max_time": config.max_time, "surface": config.surface}


def _outcome(result: episode.EpisodeResult) -> dict:
    """What the rows need of an episode (JSON values)."""
    return {"time_s": float(result.time), "position_error_m": float(result.position_error),
            "yaw_error_rad": float(result.yaw_error), "path_length_m": float(result.path_length),
            "stop": str(result.stop), "plans": int(result.plans), "repositions": int(result.repositions)}


def _model(summary: dict) -> AugmentedModel:
    return AugmentedModel.create(summary["effects"], summary["params"], summary["pusher_friction"])


def _remove_pushes_from(data_dir: Path, first: int) -> None:
    """Removes the push folders of episodes `first` and later below `data_dir` (a former run's, which the loop of an
    earlier block must not see)."""
    for folder in sorted(data_dir.glob("*/*/episode=*")):
        number = folder.name.removeprefix("episode=")
        if folder.is_dir() and number.isdigit() and int(number) >= first:
            shutil.rmtree(folder)


@dataclasses.dataclass
class _Tally:
    """What a run simulated, read back and ran, and its wall time (printed only: the records stay byte-identical)."""

    counts: dict = dataclasses.field(default_factory=lambda: dict.fromkeys(
        ("simulated", "read back", "loop runs", "loop runs read back"), 0))
    seconds: dict = dataclasses.field(default_factory=lambda: dict.fromkeys(("episodes", "loop"), 0.0))

    def report(self, workdir: Path) -> None:
        counts, seconds = self.counts, self.seconds
        tqdm.tqdm.write(f"adapt: {counts['simulated']} episodes simulated, {counts['read back']} read back; the loop "
                        f"ran {counts['loop runs']} times, {counts['loop runs read back']} read back ({workdir})")
        if counts["simulated"] or counts["loop runs"]:
            tqdm.tqdm.write(f"adapt: {seconds['episodes']:.1f} s simulating and planning "
                            f"({60 * counts['simulated'] / max(seconds['episodes'], 1e-9):.1f} episodes a minute), "
                            f"{seconds['loop']:.1f} s in the loop ({seconds['loop'] / max(counts['loop runs'], 1):.1f} "
                            "s an update), compilation included")


@dataclasses.dataclass
class _WorldRun:
    """One world of a run (:func:`run`): its goals block by block, every arm on each, the loop after every block;
    finished episodes and loop runs read back from the records below `folder`."""

    config: AdaptConfig
    world: World
    folder: Path
    tally: _Tally
    bar: tqdm.tqdm
    plain: AugmentedModel
    outcomes: dict[str, dict] = dataclasses.field(default_factory=dict)
    """Digest of an episode's inputs -> its outcome (simulated or read)."""
    recordings: dict[str, episode.EpisodeResult] = dataclasses.field(default_factory=dict)
    """Digest of an episode's inputs -> the episode, simulated in this run."""
    pushed: list[str] = dataclasses.field(default_factory=list)
    """The digests of the adaptive arm's episodes so far."""
    adaptive: AugmentedModel | None = None
    """The loop's model; None: plain Lynch."""

    @property
    def data_dir(self) -> Path:
        return self.folder / "pushes"

    def run(self) -> tuple[list[dict], list[dict]]:
        """(the episodes' rows, the loop's rows) of the world."""
        config = self.config
        tasks = _tasks(config.objects, config.episodes, self.world.seed)
        episodes, loops = [], []
        for block in range(config.blocks):
            for number in range(config.block_start(block), config.block_start(block + 1)):
                episodes += [self.arm_episode(arm, block, number, tasks[number]) for arm in ARMS]
            loops.append(self.close_loop(block))
        return episodes, loops

    def arm_episode(self, arm: str, block: int, number: int, task: goals.Goal) -> dict:
        """The row of `arm` on goal `number` (`task`), read back or simulated (its record, and the adaptive arm's push
        file, written)."""
        config, world, counts = self.config, self.world, self.tally.counts
        spec = {"adaptive": self.adaptive or self.plain, "plain": self.plain, "oracle": world.oracle[task.obj],
                "filtered": self.plain}[arm]
        inputs = _episode_inputs(config, world, task, spec, filtered_friction=arm == "filtered")
        key = _digest(inputs)
        path = self.folder / EPISODE_RECORD.format(number, arm)
        push_path = (episode_push_path(self.data_dir, config.surface, task.obj, number, config.controller.speed_limit)
                     if arm == "adaptive" else None)
        self.bar.set_postfix_str(f"{world.effect} world {world.seed} block {block + 1} {arm}")
        record = _read_record(path, key)
        if record is not None and (push_path is None or push_path.is_file()):
            counts["read back"] += 1
        else:
            # An arm that plans with the same model on this goal as another pushes as it did.
            if key not in (self.outcomes if push_path is None else self.recordings):
                model = make_model(task.obj, mu=spec.mu, effects=spec.effects, params=spec.params)
                setup = episode.EpisodeConfig(max_time=config.max_time, surface=config.surface,
                                              testbed=world.testbed, effects=world.effects[task.obj],
                                              filtered_friction=arm == "filtered")
                began = time.perf_counter()
                self.recordings[key] = episode.run_episode(mpc, model, config.controller, task, seed=world.seed,
                                                           setup=setup)
                self.tally.seconds["episodes"] += time.perf_counter() - began
                self.outcomes[key] = _outcome(self.recordings[key])
                counts["simulated"] += 1
            if push_path is not None:
                recording = self.recordings[key].recording
                write_push(push_path, None, recording.tip_pose, recording.object_pose, recording.ft_wrench)
            record = _write_record(path, {"key": key, "inputs": inputs, "outcome": self.outcomes[key]})
        self.outcomes.setdefault(key, record["outcome"])
        if arm == "adaptive":
            self.pushed.append(key)
        self.bar.update()
        return _episode_row(world.effect, world.seed, arm, block, number, task, record["outcome"], spec,
                            config.max_time)

    def close_loop(self, block: int) -> dict:
        """The loop's row after `block` (run on the adaptive arm's pushes so far, or read back); sets the model the
        next block plans with."""
        config, seed = self.config, self.world.seed
        end = config.block_start(block + 1)
        self.bar.set_postfix_str(f"{self.world.effect} world {seed}: closing the loop on {end} pushes")
        inputs = {"loop": dataclasses.asdict(config.loop), "seed": seed, "pushes": self.pushed}
        key = _digest(inputs)
        report_dir = self.folder / "loop" / f"block={block}"
        record = _read_record(report_dir / LOOP_RECORD, key)
        if record is not None:
            self.tally.counts["loop runs read back"] += 1
        else:
            _remove_pushes_from(self.data_dir, end)
            began = time.perf_counter()
            record = _write_record(report_dir / LOOP_RECORD, {
                "key": key, "inputs": inputs, "row": _loop_row(self.data_dir, report_dir, config.loop, seed)})
            self.tally.seconds["loop"] += time.perf_counter() - began
            self.tally.counts["loop runs"] += 1
        row = record["row"]
        self.adaptive = _model(row["model"]) if row["ran"] else None
        return {"effect": self.world.effect, "world": seed, "block": block, "pushes": end, **row}


def run(config: AdaptConfig, workdir: str | Path) -> dict:
    """Runs the study (see the module docstring); writes the push files, the loop's reports and the records below
    `workdir`.

    Resuming: every arm's finished episode is recorded (:data:`EPISODE_RECORD`, written after the adaptive arm's push
    file, renamed into place) with the digest of what it is a function of (the world, the goal, the planned-with
    model, the controller, ``max_time``, the surface), and so is every loop run (:data:`LOOP_RECORD`: the loop's
    settings and the digests of the pushes it ran on). A run over a workdir that holds them reads them back instead of
    simulating or running the loop again (the adaptive arm's push file must be there too), so an interrupted run
    continues where it stopped and gives the bytes an uninterrupted run gives. A record of other inputs is made
    again; before the loop runs, any push files of later episodes (a former run's) are removed. The records do not
    know the code: after changing it, start from an empty workdir.

    Returns:
      ``{"study", "settings", "comparison_rule", "worlds", "episodes", "loop", "rows", "comparison"}``: ``episodes``
      one row per arm and goal (``effect, world, arm, block, episode, object, index, success, time_to_goal_s, time_s,
      position_error_mm, yaw_error_deg, path_length_m, stop, plans, repositions, model``), ``loop`` one row per world
      and block (``effect, world, block, pushes, ran, selected, model, reason``: what the next block plans with and
      why), ``rows`` per effect, arm and block (:func:`_block_rows`), ``comparison`` per effect (:func:`compare`),
      ``filter_rule`` and ``filter_comparison`` per effect (:func:`compare_filtered`).
    """
    workdir = Path(workdir)
    episodes, loops, worlds = [], [], []
    tally = _Tally()
    plain = AugmentedModel.create((), {}, PUSHER_OBJECT_FRICTION)
    total = len(config.effects) * config.worlds * config.episodes * len(ARMS)
    with tqdm.tqdm(total=total, desc="adapt: pushing to goals", unit="episode") as bar:
        for effect in config.effects:
            for seed in config.world_seeds:
                world = draw_world(effect, seed, config.objects, config.surface, config.testbed)
                worlds.append({"effect": effect, "seed": seed, "magnitude": world.magnitude,
                               "oracle": {obj: spec.as_dict() for obj, spec in world.oracle.items()}})
                world_episodes, world_loops = _WorldRun(config, world, workdir / effect / f"world={seed}", tally, bar,
                                                        plain).run()
                episodes += world_episodes
                loops += world_loops
    tally.report(workdir)
    results = {"study": "adapt", "settings": config.as_dict(), "comparison_rule": COMPARISON_RULE, "worlds": worlds,
               "episodes": episodes, "loop": loops, "rows": _block_rows(episodes),
               "comparison": {effect: compare([row for row in episodes if row["effect"] == effect],
                                              config.blocks - 1) for effect in config.effects},
               "filter_rule": FILTER_RULE,
               "filter_comparison": {effect: compare_filtered([row for row in episodes if row["effect"] == effect])
                                     for effect in config.effects}}
    return outputs.compact(results)


def _loop_row(data_dir: Path, report_dir: Path, settings: LoopConfig, seed: int) -> dict:
    """Runs the loop on the pushes in `data_dir` (reports in `report_dir`): ``ran, selected, model, reason``, what the
    next block plans with (``model``: the loop's, :meth:`AugmentedModel.as_dict`; None: plain Lynch) and why."""
    try:
        found = close_loop(data_dir, report_dir, settings, seed=seed, progress=False)
    except ValueError as error:
        return {"ran": False, "selected": [], "model": None,
                "reason": f"plain Lynch: the loop cannot run yet ({' '.join(str(error).split())})"}
    selected = list(found.report.selected)
    return {"ran": True, "selected": selected, "model": found.model.as_dict(),
            "reason": ("the loop's model: " + (" + ".join(selected) if selected else "nothing selected (Lynch)")
                       + f", pusher friction {found.model.mu:.3f}")}


def _episode_row(effect: str, world: int, arm: str, block: int, number: int, task: goals.Goal, outcome: dict,
                 spec: AugmentedModel, max_time: float) -> dict:
    success = goals.succeeded(outcome["position_error_m"], outcome["yaw_error_rad"])
    return {"effect": effect, "world": world, "arm": arm, "block": block, "episode": number, "object": task.obj,
            "index": task.index, "goal": list(task.goal), "success": success,
            "time_to_goal_s": outcome["time_s"] if success else max_time, "time_s": outcome["time_s"],
            "position_error_mm": 1e3 * outcome["position_error_m"],
            "yaw_error_deg": math.degrees(outcome["yaw_error_rad"]), "path_length_m": outcome["path_length_m"],
            "stop": outcome["stop"], "plans": outcome["plans"], "repositions": outcome["repositions"],
            "model": {"effects": list(spec.effects), "pusher_friction": spec.mu}}


def _mean_and_error(values: Sequence[float]) -> tuple[float, float | None]:
    """(mean, standard error of the mean; None for fewer than 2 values: no spread to estimate it from)."""
    values = np.asarray(values, np.float64)
    error = float(np.std(values, ddof=1) / math.sqrt(len(values))) if len(values) > 1 else None
    return float(np.mean(values)), error


def _block_rows(episodes: Sequence[dict]) -> list[dict]:
    """Per effect, arm and block: ``episodes``, ``worlds``, ``success_rate``, ``time_to_goal_s`` (mean over world
    seeds of the worlds' block means) with ``time_to_goal_se_s`` (its standard error over world seeds; None with one),
    ``path_length_m`` (mean, m)."""
    rows = []
    keys = sorted({(row["effect"], row["arm"], row["block"]) for row in episodes},
                  key=lambda key: (key[0], ARMS.index(key[1]), key[2]))
    for effect, arm, block in keys:
        chosen = [row for row in episodes if (row["effect"], row["arm"], row["block"]) == (effect, arm, block)]
        worlds = sorted({row["world"] for row in chosen})
        mean, error = _mean_and_error([np.mean([row["time_to_goal_s"] for row in chosen if row["world"] == world])
                                       for world in worlds])
        rows.append({"effect": effect, "arm": arm, "block": block, "episodes": len(chosen), "worlds": len(worlds),
                     "success_rate": float(np.mean([row["success"] for row in chosen])), "time_to_goal_s": mean,
                     "time_to_goal_se_s": error,
                     "path_length_m": float(np.mean([row["path_length_m"] for row in chosen]))})
    return rows


VERDICTS = {stats.HOLDS: "closes the gap", stats.FAILS: "falls short", stats.UNDECIDED: "not decided"}
"""The comparison's verdict for each of :func:`pushjax.stats.decide`'s on the claim "the adaptive controller's time to
goal beats the midpoint of plain's and the oracle's" (that is, it closes :data:`GAP_SHARE` of the gap)."""


def compare(episodes: Sequence[dict], block: int) -> dict:
    """The comparison rule (:data:`COMPARISON_RULE`) on one effect's episode rows, in block `block` (0-based).

    The decision is :func:`pushjax.stats.decide` (the project's one rule) on the paired difference ``-d`` (the
    adaptive arm's time minus the plain-oracle midpoint's, lower is better) and its standard error over world seeds.

    Returns:
      ``{"block", "worlds", "goals", "plain_minus_oracle_s", "plain_minus_adaptive_s", "gap_closed_share",
      "criterion_s": {"mean", "standard_error"}, "verdict", "reason"}``: times in s (means over world seeds), the share
      of the gap closed (None without a gap), the standard error None with one world seed, the verdict
      (:data:`VERDICTS`) and why.
    """
    times = {(row["world"], row["arm"], row["object"], row["index"]): row["time_to_goal_s"] for row in episodes
             if row["block"] == block}
    goals_by_world = {}
    for world, arm, obj, index in times:
        if arm == "plain" and all((world, other, obj, index) in times for other in ("adaptive", "oracle")):
            goals_by_world.setdefault(world, []).append((obj, index))
    per_world = {"criterion": [], "gap": [], "closed": []}
    for world, tasks in sorted(goals_by_world.items()):
        plain = np.array([times[(world, "plain", *task)] for task in tasks])
        adaptive = np.array([times[(world, "adaptive", *task)] for task in tasks])
        oracle = np.array([times[(world, "oracle", *task)] for task in tasks])
        per_world["criterion"].append(float(np.mean((plain - adaptive) - GAP_SHARE * (plain - oracle))))
        per_world["gap"].append(float(np.mean(plain - oracle)))
        per_world["closed"].append(float(np.mean(plain - adaptive)))
    if not per_world["criterion"]:
        return {"block": block, "worlds": 0, "goals": 0, "verdict": VERDICTS[stats.UNDECIDED],
                "reason": "no goal of the block was pushed by every arm"}
    mean, error = _mean_and_error(per_world["criterion"])
    verdict = VERDICTS[stats.decide(-mean, error)]
    if error is None:
        reason = "one world seed: no standard error over world seeds"
    elif verdict == VERDICTS[stats.UNDECIDED]:
        reason = f"the criterion is within {STANDARD_ERRORS:g} standard errors of zero"
    else:
        reason = f"the criterion is {abs(mean) / error:.1f} standard errors from zero" if error > 0 else (
            "the criterion is the same in every world")
    gap, closed = float(np.mean(per_world["gap"])), float(np.mean(per_world["closed"]))
    return {"block": block, "worlds": len(goals_by_world), "goals": sum(map(len, goals_by_world.values())),
            "plain_minus_oracle_s": gap, "plain_minus_adaptive_s": closed,
            "gap_closed_share": closed / gap if gap != 0 else None,
            "criterion_s": {"mean": mean, "standard_error": error}, "verdict": verdict, "reason": reason}


FILTER_VERDICTS = {stats.HOLDS: "helps", stats.FAILS: "hurts", stats.UNDECIDED: "not decided"}
""":func:`compare_filtered`'s verdict for each of :func:`pushjax.stats.decide`'s on "the filtered arm beats plain"."""


def compare_filtered(episodes: Sequence[dict]) -> dict:
    """:data:`FILTER_RULE` on one effect's episode rows: ``{"worlds", "goals", "filtered_minus_plain_s": {"mean",
    "standard_error"}, "verdict", "reason"}`` (s; the standard error None with one world seed; :data:`FILTER_VERDICTS`).
    """
    times = {(row["world"], row["arm"], row["object"], row["index"]): row["time_to_goal_s"] for row in episodes}
    per_world = {}
    for world, arm, obj, index in sorted(times):
        if arm == "plain" and (world, "filtered", obj, index) in times:
            per_world.setdefault(world, []).append(times[(world, "filtered", obj, index)] - times[(world, arm, obj,
                                                                                                   index)])
    if not per_world:
        return {"worlds": 0, "goals": 0, "verdict": FILTER_VERDICTS[stats.UNDECIDED],
                "reason": "no goal was pushed by both the plain and the filtered arm"}
    mean, error = _mean_and_error([float(np.mean(differences)) for differences in per_world.values()])
    verdict = FILTER_VERDICTS[stats.decide(mean, error)]
    reason = ("one world seed: no standard error over world seeds" if error is None else
              f"the difference is {abs(mean) / error:.1f} standard errors from zero" if error > 0 else
              "the difference is the same in every world")
    return {"worlds": len(per_world), "goals": sum(map(len, per_world.values())),
            "filtered_minus_plain_s": {"mean": mean, "standard_error": error}, "verdict": verdict, "reason": reason}


def write(results: dict, workdir: str | Path, tables_only: bool = False) -> list[Path]:
    """Writes ``results.json``, ``results.md`` and ``time_to_goal.png`` (time to goal by block, per effect and arm)
    to `workdir`; returns their paths. ``tables_only``: ``results.md`` and the figure alone, from a run's recorded
    ``results.json`` (left as it is, with its provenance)."""
    write = outputs.write_tables if tables_only else outputs.write_results
    return write(workdir, results, adapt_report.markdown(results), "time_to_goal.png", adapt_report.figure)
