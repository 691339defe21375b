"""The controller closed on the MuJoCo testbed: the testbed pushes, motion capture measures, a filter estimates,
the controller plans again.

One :func:`run_episode` is one goal (a :class:`pushjax.control.goals.Goal`): the object rests at its start pose, the
pusher waits on the clearance circle (:func:`pushjax.control.contact.clearance_radius`) on the object's -x side
(world). Every ``config.replan_steps`` control periods (or after a reposition) the episode

1. filters the motion capture of the periods since the last plan (the testbed's noise, jitter and drops in the
   realistic profile; a dropped sample is NaN and only predicted) with the extended Kalman filter of
   :mod:`pushjax.filter.ekf`, whose process model is the same rollout step, one step per control period (process
   noise: :data:`pushjax.studies.tracking.PROCESS_STD_PER_S`, tuned there on testbed pushes); with a
   :class:`PositionSource` among its :class:`Sensors` (e.g. a trained model's perception of the rendered depth
   image, made at layer 6 by ``pushjax.sensing.perception``) its reading of the true scene at the end of every
   ``every``-th control period follows the pose update (:func:`pushjax.filter.models.update_position`, the source's
   own noise); without motion capture (``Sensors(motion_capture=False, ...)``: perception only) the readings are the
   only observation, the first one and the start pose's orientation (the object was placed there) start the
   filter, and the orientation is only predicted and inferred from how the position moves;
2. asks the controller (a :class:`pushjax.control.controller.Controller`, e.g. :mod:`pushjax.control.mpc`) to
   replan from the filtered pose and the commanded pusher position;
3. has the testbed (:class:`pushjax.sim.push.Episode`: the testbed's scene, stepping and testbed draws) move the
   pusher through the plan's first steps, or along the detour of a reposition, at the 4 ms recording clock.

It stops when the filtered pose is within :attr:`EpisodeConfig.stop_position` and :attr:`EpisodeConfig.stop_yaw` of
the goal, when the controller has nothing that helps for :attr:`EpisodeConfig.patience` plans in a row, or after
:attr:`EpisodeConfig.max_time` simulated seconds; the pusher then stands still for :attr:`EpisodeConfig.settle` s
and the final TRUE pose (the simulation's, before motion capture) is scored. Same seed, same episode: the testbed's
draws come from ``(seed, object, goal index)``, the controller's key from ``seed`` and the goal index.
"""

from __future__ import annotations

import dataclasses
import math
import time
import zlib
from collections.abc import Callable

import jax
import jax.numpy as jnp
import numpy as np

from pushjax.control import contact, goals, mpc
from pushjax.control.controller import Command, Controller
from pushjax.control.cost import wrap
from pushjax.control.model import PlanningModel
from pushjax.filter import ekf, models
from pushjax.sim import push, scene
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import REALISTIC, Testbed, draw_conditions
from pushjax.studies import tracking

__all__ = ["EpisodeConfig", "EpisodeResult", "PositionSource", "STATE_SOURCES", "Sensors", "filter_period",
           "run_episode", "waypoint_targets"]

STATE_SOURCES = ("mocap", "mocap+perception", "perception")
"""Where the filter's observations come from: motion capture alone, motion capture and a :class:`PositionSource`,
the position source alone."""

PRIOR_STD = (1e-3, 1e-3, 0.02, 0.3, 0.3)
"""Prior standard deviations of the filter at the first measurement (x m, y m, yaw rad, log mu, log l)."""


@dataclasses.dataclass(frozen=True)
class EpisodeConfig:
    """When an episode stops, and the testbed's settings.

    Attributes:
      max_time: simulated seconds before giving up.
      stop_position: the filtered position error that ends pushing, m.
      stop_yaw: the filtered orientation error that ends pushing, rad.
      patience: plans in a row without a helpful move that end pushing.
      settle: seconds the pusher stands still before the final pose is read.
      surface: surface name.
      testbed: the testbed profile (realistic unless :data:`pushjax.sim.testbed.IDEAL` is asked for).
      effects: the simulated world's effects (:class:`pushjax.sim.effects.Effects`).
      filtered_friction: plan with the pusher friction the EKF infers as it goes (the planned-with model's times
        ``exp`` of the filter's ``log_mu_scale``), updated before every plan, instead of the model's own.
    """

    max_time: float = 60.0
    stop_position: float = 0.003
    stop_yaw: float = math.radians(3.0)
    patience: int = 5
    settle: float = 0.5
    surface: str = "abs"
    testbed: Testbed = REALISTIC
    effects: Effects = Effects()
    filtered_friction: bool = False


@dataclasses.dataclass(frozen=True)
class PositionSource:
    """A second sensor of the episode: the object's centre of mass read from the true scene (e.g. a trained model's
    perception of its rendered depth image, :meth:`pushjax.sensing.perception.PerceptionSensor.locate`).

    Attributes:
      locate: ``locate(obj, poses [N, 3], pushers [N, 2]) -> [N, 2]``: the centre of mass (world x, y, m) read in the
        scenes of `obj` at the true poses (x m, y m, yaw rad) with the pusher tip at `pushers` (m); deterministic.
      std: [2] standard deviation of a reading, world x and y, m (> 0; estimated on other pushes than the evaluated).
      every: control periods between readings (a reading at the end of every `every`-th period).
      description: the sensor in words (for the report).
      gate: a reading whose squared innovation, in the units of its predicted covariance (chi-square, 2 degrees of
        freedom), exceeds `gate` is skipped (None: every reading is used; e.g. 13.8, the 99.9 % quantile).
    """

    locate: Callable[[str, np.ndarray, np.ndarray], np.ndarray]
    std: tuple[float, float]
    every: int = 1
    description: str = ""
    gate: float | None = None

    def __post_init__(self):
        if self.every < 1:
            raise ValueError(f"every: expected a whole number of control periods >= 1, got {self.every}")
        if self.gate is not None and not (math.isfinite(self.gate) and self.gate > 0):
            raise ValueError(f"gate: expected a positive chi-square bound, got {self.gate}")
        models.checked_position_std(self.std)


@dataclasses.dataclass(frozen=True)
class Sensors:
    """What the episode's filter observes (:data:`STATE_SOURCES`).

    Attributes:
      motion_capture: whether the filter reads the testbed's motion capture (False: `position` alone).
      position: a :class:`PositionSource` whose readings follow the motion capture's (None: motion capture only).

    Raises:
      ValueError: `motion_capture` False without a `position` source.
    """

    motion_capture: bool = True
    position: PositionSource | None = None

    def __post_init__(self):
        if not self.motion_capture and self.position is None:
            raise ValueError("position: without motion capture the episode needs a position source")


@dataclasses.dataclass(frozen=True)
class EpisodeResult:
    """One episode.

    Attributes:
      final_pose: [3] true final pose (x m, y m, yaw rad).
      position_error: m, of the true final pose.
      yaw_error: rad (wrapped, signed).
      path_length: distance the pusher was commanded to travel, m.
      time: simulated seconds.
      wall_time: seconds of computation (planning, filtering, simulation).
      plans: number of plans.
      repositions: number of repositions.
      stop: why pushing ended: ``"reached"``, ``"stuck"`` or ``"timeout"``.
      poses: [N, 4] true poses (t s, x m, y m, yaw rad) at the control periods' ends.
      pusher: [N, 3] pusher tip (t s, x m, y m) at the same times.
      estimates: [P, 3] filtered poses the plans started from (and the last, at which pushing stopped).
      estimate_times: [P] simulated seconds of the estimates (the true pose then: the row of `poses` at that time).
      readings: [R, 3] the position source's readings (t s, x m, y m; centre of mass); [0, 3] without one.
      skipped_readings: readings the gate skipped (:attr:`PositionSource.gate`).
      recording: the whole episode at the testbed's 250 Hz clock (:class:`pushjax.sim.push.Recording`, ``params``
        None, times from the episode's start): the pusher tip, the object pose as motion capture measured it (rows of
        dropped samples missing), the force sensor's wrench and the true object pose; what a push file of the episode
        holds (e.g. ``pushjax.studies.adapt``). None only for results made without the testbed.
    """

    final_pose: np.ndarray
    position_error: float
    yaw_error: float
    path_length: float
    time: float
    wall_time: float
    plans: int
    repositions: int
    stop: str
    poses: np.ndarray
    pusher: np.ndarray
    estimates: np.ndarray
    readings: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros((0, 3)))
    estimate_times: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    skipped_readings: int = 0
    recording: push.Recording | None = None


@jax.jit
def filter_period(system: models.System, mean, cov, pusher, increment, measurement):
    """(mean [5], cov [5, 5]) after predicting through one control period, the pusher moving from `pusher` [2] by
    `increment` [2] (world, m), and updating with `measurement` [3] (x m, y m, yaw rad; NaN: dropped)."""
    return models.update_linear(system, *ekf.predict(system, mean, cov, pusher, increment), measurement)


position_update = jax.jit(models.gated_update_position)
"""(mean [5], cov [5, 5], used []) after a position reading and its gate
(:func:`pushjax.filter.models.gated_update_position`), compiled."""


def waypoint_targets(start, waypoints, step: float, multiple: int) -> np.ndarray:
    """[n, 2] positions along the polyline from `start` [2] through `waypoints` [W, 2] (m), at most `step` (m) apart,
    the last repeated so that n is a positive multiple of `multiple`."""
    points = np.concatenate([np.asarray(start, np.float64)[None], np.asarray(waypoints, np.float64)])
    targets = []
    for begin, end in zip(points[:-1], points[1:]):
        pieces = max(1, math.ceil(np.linalg.norm(end - begin) / step - 1e-9))
        targets.append(begin + np.arange(1, pieces + 1)[:, None] / pieces * (end - begin))
    targets = np.concatenate(targets)
    padding = -len(targets) % multiple
    return np.concatenate([targets, np.repeat(targets[-1:], padding, axis=0)])


def _measured(piece: push.Recording, sample_indices: np.ndarray) -> np.ndarray:
    """[n, 3] tracked poses of `piece` at the 250 Hz sample indices, NaN where the tracking dropped them."""
    out = np.full((len(sample_indices), 3), np.nan)
    rows = {int(k): row for row, k in enumerate(np.rint(piece.object_pose[:, 0] / push.SAMPLE_PERIOD))}
    for slot, k in enumerate(sample_indices):
        if int(k) in rows:
            out[slot] = piece.object_pose[rows[int(k)], 1:]
    return out


@dataclasses.dataclass
class _Testbed:
    """The testbed's side of one episode: moves the pusher and keeps what happened and what the sensors read."""

    episode: push.Episode
    obj: str
    samples_per_period: int
    sensors: Sensors
    poses: list = dataclasses.field(default_factory=list)
    tips: list = dataclasses.field(default_factory=list)
    readings: list = dataclasses.field(default_factory=list)
    pieces: list = dataclasses.field(default_factory=list)
    path_length: float = 0.0
    periods: int = 0

    def execute(self, targets, read: bool = True):
        """Moves the pusher through `targets`; returns its positions [n, 2] at the n control periods' ends, their
        motion-capture poses [n, 3] (NaN: dropped or no motion capture) and the position readings [n, 2] (NaN: none)."""
        position = self.sensors.position
        self.path_length += float(np.linalg.norm(np.diff(np.concatenate([self.episode.pusher[None], targets]), axis=0),
                                                 axis=1).sum())
        first_sample = self.episode.samples
        piece = self.episode.advance(targets)
        self.pieces.append(piece)
        ends = np.arange(self.samples_per_period - 1, len(targets), self.samples_per_period)
        self.poses.append(piece.true_object_pose[ends])
        self.tips.append(piece.tip_pose[ends, :3])
        measured = _measured(piece, first_sample + 1 + ends)
        if not self.sensors.motion_capture:
            measured[:] = np.nan
        found = np.full((len(ends), 2), np.nan)
        if position is not None and read:
            rows = np.flatnonzero((self.periods + 1 + np.arange(len(ends))) % position.every == 0)
            if len(rows):
                found[rows] = position.locate(self.obj, piece.true_object_pose[ends[rows], 1:],
                                              piece.tip_pose[ends[rows], 1:3])
                self.readings.append(np.concatenate([piece.true_object_pose[ends[rows], :1], found[rows]], axis=1))
        self.periods += len(ends)
        return piece.tip_pose[ends, 1:3], measured, found


def _samples_per_period(config) -> int:
    """The testbed's 4 ms samples in one control period of `config`."""
    samples = round(config.period / push.SAMPLE_PERIOD)
    if abs(samples * push.SAMPLE_PERIOD - config.period) > 1e-9:
        raise ValueError(f"period: expected a multiple of {push.SAMPLE_PERIOD} s, got {config.period}")
    return samples


def _place(model: PlanningModel, config, task: goals.Goal, seed: int, setup: EpisodeConfig,
           sensors: Sensors) -> _Testbed:
    """The testbed of `task`: the object at its start pose, the pusher on the clearance circle on its -x side, the
    testbed's draws from ``(seed, object, goal index)``."""
    samples_per_period = _samples_per_period(config)
    start = np.asarray(task.start, np.float64)
    simulator = push.simulator(task.obj, setup.surface, setup.effects)
    episode_key = (seed, zlib.crc32(task.obj.encode()), task.index)
    conditions = None if setup.testbed.ideal else draw_conditions(
        setup.testbed, seed, task.obj, setup.surface, episode_key, len(scene.support_points(task.obj)[0]))
    com = start[:2] + np.asarray(contact.rotate(model.shape.centroid, start[2]), np.float64)
    circle = float(contact.clearance_radius(model.shape, model.radius, config.clearance))
    pusher = com - np.array([circle, 0.0])
    episode = push.Episode(simulator, start, pusher, config.speed_limit,
                           rng=np.random.default_rng([*episode_key, 5]), conditions=conditions)
    return _Testbed(episode, task.obj, samples_per_period, sensors)


def _filter_system(model: PlanningModel, config, obj: str, setup: EpisodeConfig) -> models.System:
    """The EKF's system: the planned-with model, :data:`pushjax.studies.tracking.PROCESS_STD_PER_S` per control period
    and the testbed's tracking noise as the measurement noise."""
    measurement_std = (max(setup.testbed.tracking_noise_xy, 1e-5),) * 2 + (max(setup.testbed.tracking_noise_yaw, 1e-4),)
    return models.make_system(obj, mu=float(model.mu), l=float(model.l),
                              process_std=np.asarray(tracking.PROCESS_STD_PER_S) * math.sqrt(config.period),
                              measurement_std=measurement_std, effects=model.effects, params=model.params)


def _first_belief(testbed: _Testbed, model: PlanningModel, start: np.ndarray):
    """(mean [5], cov [5, 5]) of the filter at the first observation, the pusher standing still until one comes."""
    still = np.repeat(testbed.episode.pusher[None], testbed.samples_per_period, axis=0)
    if testbed.sensors.motion_capture:
        observed = testbed.execute(still)[1][-1]
        while not np.all(np.isfinite(observed)):  # the first measurement was dropped: wait for one
            observed = testbed.execute(still)[1][-1]
        prior_std = np.asarray(PRIOR_STD)
    else:  # the first reading locates the centre of mass; the orientation is the start pose's, where it was placed
        found = testbed.execute(still)[2][-1]
        while not np.all(np.isfinite(found)):
            found = testbed.execute(still)[2][-1]
        observed = np.concatenate([found - np.asarray(contact.rotate(model.shape.centroid, start[2]), np.float64),
                                   start[2:3]])
        prior_std = np.concatenate([testbed.sensors.position.std, PRIOR_STD[2:]])
    mean = jnp.asarray(np.concatenate([observed, [0.0, 0.0]]), jnp.float32)
    cov = jnp.diag(jnp.asarray(prior_std, jnp.float32) ** 2)
    return mean, cov


def _with_filtered_friction(model: PlanningModel, mean) -> PlanningModel:
    """`model` with the pusher friction of the filter's belief `mean` [5] (its ``log_mu_scale`` on the model's)."""
    scale = jnp.exp(jnp.asarray(mean)[models.STATE_NAMES.index("log_mu_scale")])
    return model.replace(mu=(model.mu * scale).astype(model.mu.dtype))


def _targets(command: Command, commanded: np.ndarray, config, samples_per_period: int) -> np.ndarray:
    """The 4 ms pusher targets of `command` from the commanded position `commanded` [2]: the detour of a
    reposition at the speed limit, else the plan's first ``config.replan_steps`` increments."""
    if command.reposition:
        return waypoint_targets(commanded, command.waypoints, config.speed_limit * push.SAMPLE_PERIOD,
                                samples_per_period)
    steps = np.asarray(command.increments[:config.replan_steps], np.float64)
    fractions = np.arange(1, samples_per_period + 1)[None, :, None] / samples_per_period
    starts = commanded + np.concatenate([np.zeros((1, 2)), np.cumsum(steps, axis=0)[:-1]])
    return (starts[:, None] + fractions * steps[:, None]).reshape(-1, 2)


def _filtered(system: models.System, sensor, gate: float, mean, cov, commanded, observed):
    """(mean, cov, readings the gate skipped) after the control periods of `observed` (:meth:`_Testbed.execute`'s
    answer) from the pusher at `commanded`."""
    tip_path, measurements, found = observed
    path = np.concatenate([commanded[None], tip_path]).astype(np.float32)
    skipped = 0
    for begin, end, measurement, reading in zip(path[:-1], path[1:], measurements.astype(np.float32),
                                                found.astype(np.float32)):
        mean, cov = filter_period(system, mean, cov, begin, end - begin, measurement)
        if np.all(np.isfinite(reading)):
            mean, cov, used = position_update(sensor, mean, cov, reading, gate)
            skipped += not bool(used)
    return mean, cov, skipped


def _result(testbed: _Testbed, goal: np.ndarray, began: float, estimates: list, estimate_times: list, plans: int,
            repositions: int, stop: str, skipped: int) -> EpisodeResult:
    """The :class:`EpisodeResult` of the finished `testbed`, scored on its final TRUE pose."""
    poses, tips = np.concatenate(testbed.poses), np.concatenate(testbed.tips)
    final = poses[-1, 1:]
    return EpisodeResult(
        final_pose=final, position_error=float(np.hypot(*(final[:2] - goal[:2]))),
        yaw_error=float(wrap(final[2] - goal[2])), path_length=testbed.path_length, time=testbed.episode.time,
        wall_time=time.perf_counter() - began, plans=plans, repositions=repositions, stop=stop, poses=poses,
        pusher=tips, estimates=np.asarray(estimates).reshape(-1, 3),
        readings=np.concatenate(testbed.readings) if testbed.readings else np.zeros((0, 3)),
        estimate_times=np.asarray(estimate_times, np.float64), skipped_readings=skipped,
        recording=push.Recording(params=None, **{
            name: np.concatenate([getattr(piece, name) for piece in testbed.pieces])
            for name in ("tip_pose", "object_pose", "ft_wrench", "true_object_pose")}))


def run_episode(controller: Controller, model: PlanningModel, config: mpc.ControllerConfig, task: goals.Goal, *,
                seed: int, setup: EpisodeConfig = EpisodeConfig(), sensors: Sensors = Sensors()) -> EpisodeResult:
    """Pushes ``task.obj`` from ``task.start`` to ``task.goal`` (x m, y m, yaw rad) on the testbed of `setup`; see the
    module docstring.

    Args:
      controller: the :class:`~pushjax.control.controller.Controller` (e.g. :mod:`pushjax.control.mpc`).
      model: the :class:`~pushjax.control.model.PlanningModel` the controller plans with (of ``task.obj``).
      config: the controller's settings (e.g. :class:`~pushjax.control.mpc.ControllerConfig`).
      task: the goal (:class:`~pushjax.control.goals.Goal`; its ``index`` is part of the draws' entropy).
      seed: seed of the testbed's draws and the controller's key.
      setup: the :class:`EpisodeConfig`.
      sensors: what the filter observes (:class:`Sensors`).
    """
    began = time.perf_counter()
    start, goal = np.asarray(task.start, np.float64), np.asarray(task.goal, np.float64)
    testbed = _place(model, config, task, seed, setup, sensors)
    system = _filter_system(model, config, task.obj, setup)
    state = controller.init(config, jax.random.fold_in(jax.random.key(seed), task.index))
    goal_array = jnp.asarray(goal, jnp.float32)
    position = sensors.position
    sensor = None if position is None else models.make_position_sensor(model.shape, position.std)
    gate = math.inf if position is None or position.gate is None else position.gate
    mean, cov = _first_belief(testbed, model, start)
    estimates, estimate_times, plans, repositions, idle, stop, skipped = [], [], 0, 0, 0, "timeout", 0
    while testbed.episode.time < setup.max_time:
        estimate = np.asarray(mean[:3], np.float64)
        estimates.append(estimate)
        estimate_times.append(testbed.episode.time)
        position_error = float(np.hypot(*(estimate[:2] - goal[:2])))
        if position_error < setup.stop_position and abs(float(wrap(estimate[2] - goal[2]))) < setup.stop_yaw:
            stop = "reached"
            break
        commanded = testbed.episode.pusher.copy()
        planned = _with_filtered_friction(model, mean) if setup.filtered_friction else model
        state, command = controller.replan(config, planned, state, jnp.asarray(estimate, jnp.float32),
                                           jnp.asarray(commanded, jnp.float32), goal_array)
        plans += 1
        command = jax.device_get(command)
        helpful = bool(command.reposition) or command.cost < command.idle_cost * (1.0 - 1e-3)
        idle = 0 if helpful else idle + 1
        if idle >= setup.patience:
            stop = "stuck"
            break
        repositions += bool(command.reposition)
        observed = testbed.execute(_targets(command, commanded, config, testbed.samples_per_period))
        mean, cov, newly_skipped = _filtered(system, sensor, gate, mean, cov, commanded, observed)
        skipped += newly_skipped
    testbed.execute(np.repeat(testbed.episode.pusher[None], max(1, round(setup.settle / config.period))
                              * testbed.samples_per_period, axis=0), read=False)
    return _result(testbed, goal, began, estimates, estimate_times, plans, repositions, stop, skipped)
