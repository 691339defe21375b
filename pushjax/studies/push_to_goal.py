"""The push-to-goal experiment (``python -m experiments.push_to_goal``): every model and planner pushes every
object to its goals on the testbed, closed loop; and its report.

Models are named ``lynch`` (plain Lynch) or ``lynch+<effect>+...`` (Lynch with effects of
:data:`pushjax.physics.effects.EFFECTS`), their parameters set by ``effect.parameter=value`` items
(:func:`parse_effect_params`; unset parameters keep their "no effect" values), planning with the testbed's nominal
pusher friction; or ``loop``: the model in a pushing model file (:mod:`pushjax.physics.model_file`, e.g. the
``model.json`` that ``experiments.close_loop`` selected), with its effects, parameters and pusher friction. Every
model plans with the uniform-pressure limit-surface ratio.

Each model runs with each state source of :data:`pushjax.studies.episode.STATE_SOURCES`: ``mocap`` (motion capture
through the EKF), ``mocap+perception`` (and a :class:`~pushjax.studies.episode.PositionSource`'s readings, e.g. a
trained hybrid's perception of the rendered depth image, wired by ``experiments.push_to_goal``), ``perception`` (the
readings alone). With the default, motion capture alone, rows are named by the model; otherwise by the model and its
state source, e.g. ``lynch (mocap + perception)`` (:func:`label`), so that :func:`compare` pairs them on the same
goals. Episodes are appended to ``episodes.jsonl`` in the work folder as they finish, keyed by the run's settings, so
an interrupted run resumes where it stopped.

A run is a :class:`PushToGoalConfig` (its scales :data:`SCALES`, :meth:`PushToGoalConfig.from_scale`), validated
when made; :func:`run` runs it in a work folder. The report: per episode rows (:func:`episode_row`), summaries per
model and planner (and per object) with Wilson intervals and the paired comparisons over goals (:func:`summarise`,
:func:`compare`), runs in several worlds pooled into one comparison (:func:`pool_worlds`); :func:`write` turns them
into ``results.json``, a markdown table and a figure of trajectories. Units in the report: mm and degrees for errors, m for the pusher's path, s for times.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import tqdm

from pushjax import outputs, planar, stats
from pushjax.control import goals, gradient, mpc
from pushjax.control.model import make_model
from pushjax.geometry.objects import OBJECT_NAMES, PUSHER_RADIUS, get_object
from pushjax.physics import effects as effects_lib
from pushjax.physics import model_file
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION
from pushjax.studies import episode

__all__ = ["LOOP_MODEL", "SCALES", "ModelFileError", "PushToGoalConfig", "compare", "episode_row", "figure", "label",
           "model_effects", "parse_effect_params", "pool_worlds", "run", "summarise", "table", "write"]

TRAJECTORY_STRIDE = 5
"""Control periods between the poses kept for the figure."""


class ModelFileError(ValueError):
    """The pushing model file of the ``loop`` model cannot be read as one."""


LOOP_MODEL = "loop"
"""The name of the model read from a pushing model file."""


def model_effects(name: str) -> tuple[str, ...]:
    """The effects of the model called `name` (``lynch`` or ``lynch+effect+...``; () for ``loop``, whose effects
    are in its file).

    Raises:
      ValueError: not of that form, an unknown effect or effects that do not compose; one line.
    """
    if name == LOOP_MODEL:
        return ()
    parts = name.split("+")
    if parts[0] != "lynch" or any(not part for part in parts):
        raise ValueError(f"model {name!r}: expected 'lynch', 'lynch+<effect>+...' or '{LOOP_MODEL}'")
    effects = tuple(parts[1:])
    effects_lib.init_params(effects)
    return effects


def parse_effect_params(spec: str) -> dict[str, dict[str, np.ndarray]]:
    """{effect: {parameter: value}} from ``effect.parameter=value[,value];...`` (vectors comma-separated).

    Raises:
      ValueError: a malformed item, an unknown effect or parameter, or a value of the wrong size; one line.
    """
    params: dict[str, dict[str, np.ndarray]] = {}
    for item in filter(None, (part.strip() for part in spec.split(";"))):
        target, equals, value = item.partition("=")
        effect, dot, parameter = target.strip().partition(".")
        if not (equals and dot and effect and parameter):
            raise ValueError(f"{item!r}: expected effect.parameter=value")
        if effect not in effects_lib.EFFECTS:
            raise ValueError(f"{item!r}: unknown effect {effect!r}; known: {', '.join(effects_lib.EFFECT_NAMES)}")
        init = effects_lib.EFFECTS[effect].init()
        if parameter not in init:
            raise ValueError(f"{item!r}: {effect} has no parameter {parameter!r}; it has {', '.join(init)}")
        try:
            number = np.array([float(v) for v in value.split(",")], np.float64)
        except ValueError:
            raise ValueError(f"{item!r}: expected numbers, got {value!r}") from None
        expected = np.shape(init[parameter])
        number = number.reshape(()) if expected == () and number.size == 1 else number
        if number.shape != expected or not np.all(np.isfinite(number)):
            raise ValueError(f"{item!r}: expected {max(1, int(np.prod(expected)))} finite number(s)")
        params.setdefault(effect, {})[parameter] = number
    return params


def _whole(name: str, value, least: int) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ValueError(f"{name}: expected a whole number >= {least}, got {value!r}")


def _names(name: str, values: tuple[str, ...], known: Sequence[str]) -> None:
    if not values or len(set(values)) != len(values) or not set(values) <= set(known):
        raise ValueError(f"{name}: expected a non-empty list from {','.join(known)}, no repeats, got "
                         f"{','.join(values) or 'none'}")


@dataclasses.dataclass(frozen=True)
class PushToGoalConfig:
    """What a run of the experiment does (:func:`run`); the scales' are :data:`SCALES` (:meth:`from_scale`).

    Attributes:
      objects: object names, from ``OBJECT_NAMES``, no repeats.
      goals_per_object: goals per object (:func:`pushjax.control.goals.draw_goals`).
      models: model names (:func:`model_effects`).
      planners: planner names (:data:`pushjax.control.mpc.PLANNERS`), no repeats.
      seed: seed of the goals, the testbed's draws and the controllers' keys.
      setup: the :class:`~pushjax.studies.episode.EpisodeConfig` (testbed, world, surface, limits; ``max_time`` a
        finite number of seconds >= 1).
      effect_params: the models' effect parameters (:func:`parse_effect_params`).
      controller: the controller's settings (``planner`` replaced by each of `planners`).
      loop_model: the pushing model file of the ``loop`` model (needed when `models` has it; read by :func:`run`).
      states: state sources from :data:`pushjax.studies.episode.STATE_SOURCES`, no repeats.
      position: the position source of the states with ``perception`` (needed when `states` has one).
      position_settings: what identifies `position` in the results' settings and the episodes' fingerprint (e.g. the
        trained model, its dataset and the noise estimate; JSON-able).
      looks: which look at the models' comparison this run is (:func:`pushjax.stats.decide`; not part of the
        episodes' fingerprint, so a second look resumes the first's episodes).
      scale: the name of the scale the config was made from (:meth:`from_scale`; recorded in the results' settings,
        not part of the episodes' fingerprint), or None.

    Raises:
      ValueError: a field out of its range, naming it (``<field>: <what was expected>``; the setup's maximum time as
        ``setup.max_time``); one line.
    """

    objects: tuple[str, ...]
    goals_per_object: int
    models: tuple[str, ...]
    planners: tuple[str, ...]
    seed: int
    setup: episode.EpisodeConfig
    effect_params: str = ""
    controller: mpc.ControllerConfig = mpc.ControllerConfig()
    loop_model: str | Path | None = None
    states: tuple[str, ...] = ("mocap",)
    position: episode.PositionSource | None = None
    position_settings: dict | None = None
    looks: int = 1
    scale: str | None = None

    def __post_init__(self):
        for name in ("objects", "models", "planners", "states"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        _names("objects", self.objects, OBJECT_NAMES)
        _whole("goals_per_object", self.goals_per_object, 1)
        if not self.models:
            raise ValueError("models: expected at least one model")
        for name in self.models:
            try:
                model_effects(name)
            except ValueError as error:
                raise ValueError(f"models: {error}") from None
        _names("planners", self.planners, tuple(mpc.PLANNERS))
        _whole("seed", self.seed, 0)
        max_time = self.setup.max_time
        if not (isinstance(max_time, (int, float)) and math.isfinite(max_time) and max_time >= 1):
            raise ValueError(f"setup.max_time: expected a finite number of seconds >= 1, got {max_time!r}")
        try:
            parse_effect_params(self.effect_params)
        except ValueError as error:
            raise ValueError(f"effect_params: {error}") from None
        if LOOP_MODEL in self.models and self.loop_model is None:
            raise ValueError(f"loop_model: the model {LOOP_MODEL!r} needs a pushing model file")
        _names("states", self.states, episode.STATE_SOURCES)
        if any("perception" in state for state in self.states) and self.position is None:
            raise ValueError("position: the state sources with perception need a position source")
        if self.looks not in stats.SEQUENTIAL_STANDARD_ERRORS:
            raise ValueError(f"looks: expected one of {','.join(map(str, stats.SEQUENTIAL_STANDARD_ERRORS))}, got "
                             f"{self.looks!r}")

    @classmethod
    def from_scale(cls, scale: str, **overrides) -> PushToGoalConfig:
        """``SCALES[scale]`` named `scale`, with the fields in `overrides` that are not None replaced; an override
        named as a field of the setup (``max_time``, ``surface``, ``testbed``, ``effects``, ...) replaces the setup's
        (validated: ValueError naming the field)."""
        if scale not in SCALES:
            raise ValueError(f"scale: expected one of {','.join(SCALES)}, got {scale!r}")
        changes = {key: value for key, value in overrides.items() if value is not None}
        setup_fields = {field.name for field in dataclasses.fields(episode.EpisodeConfig)}
        setup = {key: changes.pop(key) for key in list(changes) if key in setup_fields}
        if setup:
            changes["setup"] = dataclasses.replace(changes.get("setup", SCALES[scale].setup), **setup)
        return dataclasses.replace(SCALES[scale], scale=scale, **changes)


_SMOKE_CONTROLLER = mpc.ControllerConfig(horizon=8, gradient=gradient.GradientConfig(iterations=15), candidates=16)
SCALES = {
    "smoke": PushToGoalConfig(objects=("rect1",), goals_per_object=2, models=("lynch",), planners=("gradient",),
                              seed=0, setup=episode.EpisodeConfig(max_time=30.0), controller=_SMOKE_CONTROLLER),
    "cpu": PushToGoalConfig(objects=OBJECT_NAMES, goals_per_object=2, models=("lynch",),
                            planners=("gradient", "sampling"), seed=0, setup=episode.EpisodeConfig(max_time=60.0),
                            controller=mpc.ControllerConfig()),
    "full": PushToGoalConfig(objects=OBJECT_NAMES, goals_per_object=10, models=("lynch",),
                             planners=("gradient", "sampling"), seed=0, setup=episode.EpisodeConfig(max_time=60.0),
                             controller=mpc.ControllerConfig()),
}
"""The experiment's scales, defined here and only here: objects, goals per object, planners, simulated seconds per
episode (``setup.max_time``) and controller settings (smoke: a shorter horizon, fewer planner iterations and contact
candidates, which compile and plan faster); plain Lynch with motion capture, seed 0."""


def label(model: str, state: str, states: Sequence[str]) -> str:
    """The rows' name of `model` with the state source `state`: the model's name when `states` is motion capture alone
    (the default), else ``model (state)`` with spaces around a ``+``, e.g. ``lynch (mocap + perception)``."""
    return model if tuple(states) == ("mocap",) else f"{model} ({state.replace('+', ' + ')})"


def _fingerprint(settings: dict) -> str:
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _model_specs(models: Sequence[str], effect_params: str,
                 loop_model: str | Path | None) -> dict[str, model_file.AugmentedModel]:
    """{model name: its pushing model}: Lynch with the named effects and the parameters of `effect_params`, or the
    ``loop`` model read from `loop_model`."""
    params = parse_effect_params(effect_params)
    specs = {}
    for name in models:
        effects = model_effects(name)
        specs[name] = model_file.AugmentedModel.create(
            effects, {effect: values for effect, values in params.items() if effect in effects}, PUSHER_OBJECT_FRICTION)
    if LOOP_MODEL in models:
        if loop_model is None:
            raise ValueError(f"loop_model: the model {LOOP_MODEL!r} needs a pushing model file")
        try:
            specs[LOOP_MODEL] = model_file.read(loop_model)
        except ValueError as error:
            raise ModelFileError(str(error)) from None
    return specs


def _settings(config: PushToGoalConfig, loop_spec: model_file.AugmentedModel | None) -> dict:
    """The run's settings, which key its episodes (:func:`_fingerprint`)."""
    settings = {"seed": config.seed, "loop": dataclasses.asdict(config.setup), "effect_params": config.effect_params,
                "controller": repr(config.controller)}
    if loop_spec is not None:
        settings["loop_model"] = loop_spec.as_dict()
    if config.states != ("mocap",):  # the default keeps the fingerprints of the runs before state sources
        settings["states"] = list(config.states)
    if any("perception" in state for state in config.states):
        position = config.position
        settings["position"] = {"description": position.description, "std_m": list(position.std),
                                "every_periods": position.every, **(config.position_settings or {})}
        if position.gate is not None:
            settings["position"]["gate"] = position.gate
    return settings


def _finished(log: Path, fingerprint: str) -> dict[tuple, dict]:
    """{(model, planner, object, goal index): row} of the episodes in `log` of the run keyed by `fingerprint`."""
    done = {}
    if log.exists():
        for line in log.read_text().splitlines():
            row = json.loads(line)
            if row["fingerprint"] == fingerprint:
                done[(row["model"], row["planner"], row["object"], row["index"])] = row
    return done


def run(config: PushToGoalConfig, workdir: str | Path) -> dict:
    """Runs every model and planner of `config` on every goal (resuming from ``workdir/episodes.jsonl``); returns the
    results of :func:`summarise`, the scale's name (when `config` has one) in their settings.

    Raises:
      ModelFileError (a ValueError): the ``loop`` model's file cannot be read; one line.
    """
    specs = _model_specs(config.models, config.effect_params, config.loop_model)
    tasks = goals.draw_goals(config.objects, config.goals_per_object, config.seed)
    settings = _settings(config, specs.get(LOOP_MODEL))
    fingerprint = _fingerprint(settings)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    log = workdir / "episodes.jsonl"
    done = _finished(log, fingerprint)
    rows = []
    states = config.states
    jobs = [(name, state, planner, task) for name in config.models for state in states for planner in config.planners
            for task in tasks]
    with log.open("a") as out:
        for name, state, planner, task in tqdm.tqdm(jobs, desc="push_to_goal", unit="goal"):
            key = (label(name, state, states), planner, task.obj, task.index)
            if key in done:
                rows.append(done[key])
                continue
            spec = specs[name]
            model = make_model(task.obj, mu=spec.mu, effects=spec.effects, params=spec.params)
            sensors = episode.Sensors(motion_capture="mocap" in state,
                                      position=config.position if "perception" in state else None)
            result = episode.run_episode(mpc, model, dataclasses.replace(config.controller, planner=planner), task,
                                         seed=config.seed, setup=config.setup, sensors=sensors)
            row = {"fingerprint": fingerprint, "model": key[0], "planner": planner, "object": task.obj,
                   "index": task.index, **({} if states == ("mocap",) else {"model_name": name, "state": state}),
                   **episode_row(task, result, TRAJECTORY_STRIDE)}
            out.write(json.dumps(row) + "\n")
            out.flush()
            rows.append(row)
    results = summarise(rows, settings, config.looks)
    if config.scale is not None:
        results["settings"]["scale"] = config.scale
    return results


def episode_row(task: goals.Goal, result, stride: int) -> dict:
    """The JSON row of one episode (a :class:`pushjax.studies.episode.EpisodeResult`): errors, success, path,
    times, and the trajectory every `stride` control periods (and the last)."""
    keep = np.unique(np.append(np.arange(0, len(result.poses), stride), len(result.poses) - 1))
    return {
        "start": list(task.start), "goal": list(task.goal), "final_pose": result.final_pose.tolist(),
        "position_error_mm": 1e3 * result.position_error, "yaw_error_deg": math.degrees(result.yaw_error),
        "success": goals.succeeded(result.position_error, result.yaw_error), "path_length_m": result.path_length,
        "time_s": result.time, "wall_s": result.wall_time, "plans": result.plans, "repositions": result.repositions,
        "stop": result.stop,
        **({"readings": len(result.readings), "skipped_readings": result.skipped_readings} if len(result.readings)
           else {}),
        "trajectory": {"poses": result.poses[keep].tolist(), "pusher": result.pusher[keep].tolist()},
    }


def _summary(rows: Sequence[dict]) -> dict:
    successes = sum(row["success"] for row in rows)
    low, high = goals.wilson_interval(successes, len(rows))
    position = np.array([row["position_error_mm"] for row in rows])
    yaw = np.abs([row["yaw_error_deg"] for row in rows])
    return {
        "goals": len(rows), "successes": successes, "success_rate": successes / len(rows),
        "wilson_95": [low, high], "position_error_mm_median": float(np.median(position)),
        "position_error_mm_mean": float(np.mean(position)), "yaw_error_deg_median": float(np.median(yaw)),
        "yaw_error_deg_mean": float(np.mean(yaw)),
        "path_length_m_mean": float(np.mean([row["path_length_m"] for row in rows])),
        "time_s_mean": float(np.mean([row["time_s"] for row in rows])),
        "wall_s_mean": float(np.mean([row["wall_s"] for row in rows])),
        "stops": {stop: sum(row["stop"] == stop for row in rows) for stop in sorted({row["stop"] for row in rows})},
    }


def compare(rows: Sequence[dict], baseline: str, model: str, max_time: float, looks: int = 1) -> dict:
    """`model` against `baseline` on the goals both were given (paired by planner, world, object and goal; a goal's
    differences averaged over its planners, so that the goals are the unit of resampling), decided on the time to
    success by :func:`pushjax.stats.decide` at the `looks`-th look at the comparison.

    Returns:
      ``{"model", "baseline", "goals", "time_to_success_difference_s": {"mean", "standard_error"},
      "position_error_difference_mm": {"mean", "standard_error"}, "only_model_succeeded",
      "only_baseline_succeeded", "verdict"}``; differences are `model` minus `baseline`, a failed goal's time to
      success is `max_time` (s), and the verdict is "better", "worse" or "not decided".
    """
    def by_goal(name):
        return {(row["planner"], row.get("world", 0), row["object"], row["index"]): row for row in rows
                if row["model"] == name}

    ours, theirs = by_goal(model), by_goal(baseline)
    keys = sorted(set(ours) & set(theirs))

    def time_to_success(row):
        return row["time_s"] if row["success"] else max_time

    tasks = sorted({key[1:] for key in keys})  # the goals; a goal's planners are averaged, not counted apart

    def paired(value):
        difference = np.array([np.mean([value(ours[key]) - value(theirs[key]) for key in keys if key[1:] == task])
                               for task in tasks])
        error = float(np.std(difference, ddof=1) / math.sqrt(len(tasks))) if len(tasks) > 1 else math.inf
        return {"mean": float(np.mean(difference)) if tasks else math.nan, "standard_error": error}

    time = paired(time_to_success)
    verdict = {stats.HOLDS: "better", stats.FAILS: "worse", stats.UNDECIDED: "not decided"}[
        stats.decide(time["mean"], time["standard_error"], looks)]
    return {"model": model, "baseline": baseline, "goals": len(tasks), "time_to_success_difference_s": time,
            "position_error_difference_mm": paired(lambda row: row["position_error_mm"]),
            "only_model_succeeded": sum(ours[key]["success"] and not theirs[key]["success"] for key in keys),
            "only_baseline_succeeded": sum(theirs[key]["success"] and not ours[key]["success"] for key in keys),
            "verdict": verdict}


def summarise(rows: Sequence[dict], settings: dict, looks: int = 1) -> dict:
    """``{"criterion", "settings", "summary": {model/planner: ...}, "per_object": {model/planner: {object: ...}},
    "comparisons": [every other model against the first, :func:`compare` at the `looks`-th look], "episodes":
    rows}``; the criterion records the look when it is not the first."""
    groups: dict[str, list[dict]] = {}
    for row in rows:
        groups.setdefault(f"{row['model']}/{row['planner']}", []).append(row)
    per_object = {}
    for name, members in groups.items():
        objects = sorted({row["object"] for row in members})
        per_object[name] = {obj: _summary([row for row in members if row["object"] == obj]) for obj in objects}
    models = list(dict.fromkeys(row["model"] for row in rows))
    comparisons = [compare(rows, models[0], model, settings["loop"]["max_time"], looks) for model in models[1:]]
    criterion = {"position_mm": 1e3 * goals.SUCCESS_POSITION, "yaw_deg": goals.SUCCESS_YAW_DEG,
                 "comparison_standard_errors": stats.decision_bound(looks), **({"looks": looks} if looks > 1 else {})}
    return {"criterion": criterion,
            "settings": settings, "summary": {name: _summary(members) for name, members in groups.items()},
            "per_object": per_object, "comparisons": comparisons, "episodes": list(rows)}


def pool_worlds(runs: Sequence[dict]) -> dict:
    """The results of push-to-goal runs in several worlds (each run's ``settings["seed"]``: its goals and testbed
    draws) as one :func:`summarise`: every goal of every world paired across the models, the goals of all worlds the
    unit of the comparisons; ``settings`` holds each run's under ``"runs"``.

    Raises:
      ValueError: fewer than two runs, two runs of one world, or runs of different models or time limits.
    """
    worlds = [run["settings"]["seed"] for run in runs]
    if len(runs) < 2 or len(set(worlds)) != len(worlds):
        raise ValueError(f"runs: expected runs of two or more different worlds (seeds), got seeds {worlds}")
    models = [list(dict.fromkeys(row["model"] for row in run["episodes"])) for run in runs]
    limits = {run["settings"]["loop"]["max_time"] for run in runs}
    if any(names != models[0] for names in models) or len(limits) != 1:
        raise ValueError(f"runs: expected the same models and time limit in every run, got {models} and {limits}")
    rows = [{**row, "world": world} for run, world in zip(runs, worlds) for row in run["episodes"]]
    return summarise(rows, {"worlds": worlds, "loop": runs[0]["settings"]["loop"],
                            "runs": [run["settings"] for run in runs]})


def _line(label: str, entry: dict) -> str:
    low, high = entry["wilson_95"]
    return (f"| {label} | {entry['successes']}/{entry['goals']} | {100 * entry['success_rate']:.0f} % "
            f"[{100 * low:.0f}, {100 * high:.0f}] | {entry['position_error_mm_median']:.1f} | "
            f"{entry['yaw_error_deg_median']:.1f} | {entry['path_length_m_mean']:.2f} | {entry['time_s_mean']:.1f} | "
            f"{entry['wall_s_mean']:.1f} |")


def table(results: dict) -> str:
    """Markdown: one row per model/planner, then one per model/planner and object."""
    criterion = results["criterion"]
    header = ("| {} | successes | success rate [Wilson 95 %] | median position error (mm) | median orientation error "
              "(deg) | mean pusher path (m) | mean time (s) | mean wall time (s) |\n|---|---:|---:|---:|---:|---:|---:|---:|")
    lines = [f"Success: final position error < {criterion['position_mm']:g} mm and orientation error < "
             f"{criterion['yaw_deg']:g} deg.", ""]
    position = results["settings"].get("position")
    if position:
        noise = ", ".join(f"{1e3 * value:.2f}" for value in position["std_m"])
        gate = f", readings beyond a squared innovation of {position['gate']:g} skipped" if "gate" in position else ""
        lines += [f"State sources: {', '.join(results['settings']['states'])}; perception: {position['description']}, "
                  f"a reading every {position['every_periods']} control period(s), noise std {noise} mm (x, y){gate}.",
                  ""]
    lines += [header.format("model / planner")]
    lines += [_line(name, entry) for name, entry in results["summary"].items()]
    if results.get("comparisons"):
        lines += ["", (f"Comparisons (paired over goals; better: the mean difference of the time to success, a failure "
                       f"counting as the time limit, below zero by more than {criterion['comparison_standard_errors']:g} "
                       "standard errors" + (f", look {criterion['looks']} at the same comparison" if "looks" in criterion
                                            else "") + "):"), "",
                  "| model − baseline | goals | time to success (s) | final position error (mm) | only model succeeded "
                  "| only baseline succeeded | verdict |", "|---|---:|---:|---:|---:|---:|---|"]
        for entry in results["comparisons"]:
            time, position = entry["time_to_success_difference_s"], entry["position_error_difference_mm"]
            lines.append(f"| {entry['model']} − {entry['baseline']} | {entry['goals']} | {time['mean']:+.1f} ± "
                         f"{time['standard_error']:.1f} | {position['mean']:+.1f} ± {position['standard_error']:.1f} | "
                         f"{entry['only_model_succeeded']} | {entry['only_baseline_succeeded']} | {entry['verdict']} |")
    lines += ["", header.format("model / planner, object")]
    lines += [_line(f"{name}, {obj}", entry) for name, objects in results["per_object"].items()
              for obj, entry in objects.items()]
    return "\n".join(lines) + "\n"


def figure(results: dict, path: Path, count: int = 4) -> None:
    """A few episodes: the object's outline over time (light to dark), the goal (dashed), the pusher's path."""
    episodes = results["episodes"][:count]
    axes = plt.subplots(1, len(episodes), figsize=(3.4 * len(episodes), 3.4), squeeze=False)[1][0]
    drawing = axes[0].figure
    for axis, row in zip(axes, episodes):
        outline = get_object(row["object"]).outline
        poses = np.asarray(row["trajectory"]["poses"])
        for shade, pose in zip(np.linspace(0.2, 1.0, len(poses)), poses):
            points = pose[1:3] + planar.rotate(outline, pose[3])
            axis.fill(*points.T, color=plt.cm.Blues(shade), alpha=0.35, linewidth=0.5, edgecolor="k")
        goal = np.asarray(row["goal"])
        goal_points = goal[:2] + planar.rotate(outline, goal[2])
        axis.plot(*np.vstack([goal_points, goal_points[:1]]).T, "r--", linewidth=1.2, label="goal")
        pusher = np.asarray(row["trajectory"]["pusher"])
        axis.plot(pusher[:, 1], pusher[:, 2], "-", color="0.3", linewidth=0.8, label="pusher")
        axis.plot(*pusher[-1, 1:3], "o", color="0.3", markersize=2 * 1e3 * PUSHER_RADIUS / 3)
        axis.set_aspect("equal")
        axis.set_title(f"{row['object']} #{row['index']} ({row['model']}/{row['planner']})\n"
                       f"{row['position_error_mm']:.1f} mm, {row['yaw_error_deg']:.1f} deg", fontsize=8)
        axis.tick_params(labelsize=7)
    axes[0].legend(fontsize=7, loc="best")
    drawing.tight_layout()
    drawing.savefig(path, dpi=100)
    plt.close(drawing)


def write(results: dict, workdir: str | Path) -> list[Path]:
    """Writes ``results.json``, ``results.md`` and ``trajectories.png`` to `workdir`; returns their paths."""
    return outputs.write_results(workdir, results, table(results), "trajectories.png", figure)
