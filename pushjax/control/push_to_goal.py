"""The push-to-goal experiment (``python -m experiments.push_to_goal``): every model and planner pushes every
object to its goals on the testbed, closed loop.

Models are named ``lynch`` (plain Lynch) or ``lynch+<effect>+...`` (Lynch with effects of
:data:`pushjax.physics.effects.EFFECTS`), their parameters set by ``effect.parameter=value`` items
(:func:`parse_effect_params`; unset parameters keep their "no effect" values), planning with the testbed's nominal
pusher friction; or ``loop``: the model in a pushing model file (:mod:`pushjax.physics.model_file`, e.g. the
``model.json`` that ``experiments.close_loop`` selected), with its effects, parameters and pusher friction. Every
model plans with the uniform-pressure limit-surface ratio.

Each model runs with each state source of :data:`pushjax.control.closed_loop.STATE_SOURCES`: ``mocap`` (motion capture
through the EKF), ``mocap+perception`` (and a :class:`~pushjax.control.closed_loop.PositionSource`'s readings, e.g. a
trained hybrid's perception of the rendered depth image, wired at layer 6/7 by ``experiments.push_to_goal``),
``perception`` (the readings alone). With the default, motion capture alone, rows are named by the model; otherwise
by the model and its state source, e.g. ``lynch (mocap + perception)`` (:func:`label`), so that
:func:`pushjax.control.report.compare` pairs them on the same goals. Episodes are appended to
``episodes.jsonl`` in the work folder as they finish, keyed by the run's settings, so an interrupted run resumes
where it stopped; :mod:`pushjax.control.report` turns the rows into ``results.json``, a table and a figure.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import tqdm

from pushjax.control import closed_loop, goals, gradient, mpc, report
from pushjax.control.model import make_model
from pushjax.geometry.objects import OBJECT_NAMES
from pushjax.physics import effects as effects_lib
from pushjax.physics import model_file
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION

__all__ = ["LOOP_MODEL", "SCALES", "ModelFileError", "label", "model_effects", "parse_effect_params", "run"]

SCALES = {
    "smoke": {"objects": ("rect1",), "goals": 2, "planners": ("gradient",), "max_time": 30.0,
              "controller": mpc.ControllerConfig(horizon=8, gradient=gradient.GradientConfig(iterations=15),
                                                 candidates=16)},
    "cpu": {"objects": OBJECT_NAMES, "goals": 2, "planners": ("gradient", "sampling"), "max_time": 60.0,
            "controller": mpc.ControllerConfig()},
    "full": {"objects": OBJECT_NAMES, "goals": 10, "planners": ("gradient", "sampling"), "max_time": 60.0,
             "controller": mpc.ControllerConfig()},
}
"""Objects, goals per object, planners, simulated seconds per episode and controller settings of each scale (smoke:
a shorter horizon, fewer planner iterations and contact candidates, which compile and plan faster)."""
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


def label(model: str, state: str, states: Sequence[str]) -> str:
    """The rows' name of `model` with the state source `state`: the model's name when `states` is motion capture alone
    (the default), else ``model (state)`` with spaces around a ``+``, e.g. ``lynch (mocap + perception)``."""
    return model if tuple(states) == ("mocap",) else f"{model} ({state.replace('+', ' + ')})"


def _fingerprint(settings: dict) -> str:
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()[:16]


def run(workdir: str | Path, objects: Sequence[str], goals_per_object: int, models: Sequence[str],
        planners: Sequence[str], seed: int, loop: closed_loop.LoopConfig, effect_params: str = "",
        controller: mpc.ControllerConfig = mpc.ControllerConfig(), loop_model: str | Path | None = None,
        states: Sequence[str] = ("mocap",), position: closed_loop.PositionSource | None = None,
        position_settings: dict | None = None, looks: int = 1) -> dict:
    """Runs every model and planner on every goal (resuming from ``workdir/episodes.jsonl``); returns the
    results of :func:`pushjax.control.report.summarise`.

    Args:
      workdir: the work folder (created).
      objects: object names.
      goals_per_object: goals per object (:func:`pushjax.control.goals.draw_goals`).
      models: model names (:func:`model_effects`).
      planners: planner names (:data:`pushjax.control.mpc.PLANNERS`).
      seed: seed of the goals, the testbed's draws and the controllers' keys.
      loop: the :class:`~pushjax.control.closed_loop.LoopConfig` (testbed, world, surface, limits).
      effect_params: the models' effect parameters (:func:`parse_effect_params`).
      controller: the controller's settings (``planner`` replaced by each of `planners`).
      loop_model: the pushing model file of the ``loop`` model (needed when `models` has it).
      states: state sources from :data:`pushjax.control.closed_loop.STATE_SOURCES`, no repeats.
      position: the position source of the states with ``perception`` (needed when `states` has one).
      position_settings: what identifies `position` in the results' settings and the episodes' fingerprint (e.g. the
        trained model, its dataset and the noise estimate; JSON-able).
      looks: which look at the models' comparison this run is (:func:`pushjax.stats.decide`; not part of the
        episodes' fingerprint, so a second look resumes the first's episodes).

    Raises:
      ValueError: ``loop`` among `models` without `loop_model`, an unknown or repeated state source, or one with
        perception without `position`; ModelFileError (a ValueError): a bad model file; one line.
    """
    states = tuple(states)
    if not states or len(set(states)) != len(states) or not set(states) <= set(closed_loop.STATE_SOURCES):
        raise ValueError(f"states: expected a non-empty list from {','.join(closed_loop.STATE_SOURCES)}, no repeats, "
                         f"got {','.join(states)}")
    perceives = any("perception" in state for state in states)
    if perceives and position is None:
        raise ValueError("position: the state sources with perception need a position source")
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
    tasks = goals.draw_goals(objects, goals_per_object, seed)
    settings = {"seed": seed, "loop": dataclasses.asdict(loop), "effect_params": effect_params,
                "controller": repr(controller)}
    if LOOP_MODEL in models:
        settings["loop_model"] = specs[LOOP_MODEL].as_dict()
    if states != ("mocap",):  # the default keeps the fingerprints of the runs before state sources
        settings["states"] = list(states)
    if perceives:
        settings["position"] = {"description": position.description, "std_m": list(position.std),
                                "every_periods": position.every, **(position_settings or {})}
        if position.gate is not None:
            settings["position"]["gate"] = position.gate
    fingerprint = _fingerprint(settings)
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    log = workdir / "episodes.jsonl"
    done = {}
    if log.exists():
        for line in log.read_text().splitlines():
            row = json.loads(line)
            if row["fingerprint"] == fingerprint:
                done[(row["model"], row["planner"], row["object"], row["index"])] = row
    rows = []
    jobs = [(name, state, planner, task) for name in models for state in states for planner in planners
            for task in tasks]
    with log.open("a") as out:
        for name, state, planner, task in tqdm.tqdm(jobs, desc="push_to_goal", unit="goal"):
            key = (label(name, state, states), planner, task.obj, task.index)
            if key in done:
                rows.append(done[key])
                continue
            spec = specs[name]
            model = make_model(task.obj, mu=spec.mu, effects=spec.effects, params=spec.params)
            config = dataclasses.replace(controller, planner=planner)
            result = closed_loop.run_episode(model, config, task.obj, task.start, task.goal, seed=seed,
                                             index=task.index, loop=loop,
                                             position=position if "perception" in state else None,
                                             motion_capture="mocap" in state)
            row = {"fingerprint": fingerprint, "model": key[0], "planner": planner, "object": task.obj,
                   "index": task.index, **({} if states == ("mocap",) else {"model_name": name, "state": state}),
                   **report.episode_row(task, result, TRAJECTORY_STRIDE)}
            out.write(json.dumps(row) + "\n")
            out.flush()
            rows.append(row)
    return report.summarise(rows, settings, looks)
