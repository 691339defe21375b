"""The controller closed on the MuJoCo testbed: the testbed pushes, motion capture measures, a filter estimates,
the controller plans again.

One :func:`run_episode` is one goal: the object rests at its start pose, the pusher waits on the clearance circle
(:func:`pushjax.control.contact.clearance_radius`) on the object's -x side (world). Every
``config.replan_steps`` control periods (or after a reposition) the loop

1. filters the motion capture of the periods since the last plan (the testbed's noise, jitter and drops in the
   realistic profile; a dropped sample is NaN and only predicted) with the extended Kalman filter of
   :mod:`pushjax.filter.ekf`, whose process model is the same rollout step, one step per control period (process
   noise: :data:`pushjax.filter.tracking.PROCESS_STD_PER_S`, tuned there on testbed pushes); with a
   :class:`PositionSource` (e.g. a trained model's perception of the rendered depth image, made at layer 6 by
   ``pushjax.sensing.perception``) its reading of the true scene at the end of every ``every``-th control period
   follows the pose update (:func:`pushjax.filter.models.update_position`, the source's own noise); without motion
   capture (``motion_capture=False``: perception only) the readings are the only observation, the first one and the
   start pose's orientation (the object was placed there) start the filter, and the orientation is only predicted
   and inferred from how the position moves;
2. asks :func:`pushjax.control.mpc.replan` with the filtered pose and the commanded pusher position;
3. has the testbed (:class:`pushjax.sim.push.Episode`: the testbed's scene, stepping and testbed draws) move the
   pusher through the plan's first steps, or along the detour of a reposition, at the 4 ms recording clock.

It stops when the filtered pose is within :attr:`LoopConfig.stop_position` and :attr:`LoopConfig.stop_yaw` of the
goal, when the controller has nothing that helps for :attr:`LoopConfig.patience` plans in a row, or after
:attr:`LoopConfig.max_time` simulated seconds; the pusher then stands still for :attr:`LoopConfig.settle` s and
the final TRUE pose (the simulation's, before motion capture) is scored. Same seed, same episode: the testbed's
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

from pushjax.control import contact, mpc
from pushjax.control.cost import wrap
from pushjax.control.model import PushModel
from pushjax.filter import ekf, models, tracking
from pushjax.sim import push, scene
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import REALISTIC, Testbed, draw_conditions

__all__ = ["EpisodeResult", "LoopConfig", "PositionSource", "STATE_SOURCES", "filter_period", "run_episode",
           "waypoint_targets"]

STATE_SOURCES = ("mocap", "mocap+perception", "perception")
"""Where the filter's observations come from: motion capture alone, motion capture and a :class:`PositionSource`,
the position source alone."""

PRIOR_STD = (1e-3, 1e-3, 0.02, 0.3, 0.3)
"""Prior standard deviations of the filter at the first measurement (x m, y m, yaw rad, log mu, log l)."""


@dataclasses.dataclass(frozen=True)
class LoopConfig:
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
    """

    max_time: float = 60.0
    stop_position: float = 0.003
    stop_yaw: float = math.radians(3.0)
    patience: int = 5
    settle: float = 0.5
    surface: str = "abs"
    testbed: Testbed = REALISTIC
    effects: Effects = Effects()


@dataclasses.dataclass(frozen=True)
class PositionSource:
    """A second sensor of the loop: the object's centre of mass read from the true scene (e.g. a trained model's
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


def run_episode(model: PushModel, config: mpc.ControllerConfig, obj: str, start, goal, *, seed: int, index: int = 0,
                loop: LoopConfig = LoopConfig(), position: PositionSource | None = None,
                motion_capture: bool = True) -> EpisodeResult:
    """Pushes `obj` from `start` [3] to `goal` [3] (x m, y m, yaw rad) on the testbed of `loop`; see the module
    docstring.

    Args:
      model: the controller's :class:`~pushjax.control.model.PushModel` (of `obj`).
      config: the :class:`~pushjax.control.mpc.ControllerConfig`.
      obj: object name.
      start: start pose.
      goal: goal pose.
      seed: seed of the testbed's draws and the controller's key.
      index: the goal's index (part of the draws' entropy).
      loop: the :class:`LoopConfig`.
      position: a :class:`PositionSource` whose readings follow the motion capture's (None: motion capture only).
      motion_capture: False: the filter observes only `position`'s readings (perception only).

    Raises:
      ValueError: `motion_capture` False without a `position` source.
    """
    if not motion_capture and position is None:
        raise ValueError("position: without motion capture the loop needs a position source")
    began = time.perf_counter()
    start = np.asarray(start, np.float64)
    goal = np.asarray(goal, np.float64)
    samples_per_period = round(config.period / push.SAMPLE_PERIOD)
    if abs(samples_per_period * push.SAMPLE_PERIOD - config.period) > 1e-9:
        raise ValueError(f"period: expected a multiple of {push.SAMPLE_PERIOD} s, got {config.period}")
    simulator = push.simulator(obj, loop.surface, loop.effects)
    episode_key = (seed, zlib.crc32(obj.encode()), index)
    conditions = None if loop.testbed.ideal else draw_conditions(
        loop.testbed, seed, obj, loop.surface, episode_key, len(scene.support_points(obj)[0]))
    com = start[:2] + np.asarray(contact.rotate(model.shape.centroid, start[2]), np.float64)
    circle = float(contact.clearance_radius(model.shape, model.radius, config.clearance))
    pusher = com - np.array([circle, 0.0])
    episode = push.Episode(simulator, start, pusher, config.speed_limit,
                           rng=np.random.default_rng([*episode_key, 5]), conditions=conditions)
    measurement_std = (max(loop.testbed.tracking_noise_xy, 1e-5),) * 2 + (max(loop.testbed.tracking_noise_yaw, 1e-4),)
    system = models.make_system(obj, mu=float(model.mu), l=float(model.l),
                                process_std=np.asarray(tracking.PROCESS_STD_PER_S) * math.sqrt(config.period),
                                measurement_std=measurement_std, effects=model.effects, params=model.params)
    state = mpc.init(config, jax.random.fold_in(jax.random.key(seed), index))
    goal_array = jnp.asarray(goal, jnp.float32)

    sensor = None if position is None else models.make_position_sensor(model.shape, position.std)
    gate = math.inf if position is None or position.gate is None else position.gate
    poses, tips, readings, pieces = [], [], [], []
    path_length = 0.0
    periods = 0

    def execute(targets, read: bool = True):
        """Moves the pusher through `targets`; returns its positions [n, 2] at the n control periods' ends, their
        motion-capture poses [n, 3] (NaN: dropped or no motion capture) and the position readings [n, 2] (NaN: none)."""
        nonlocal path_length, periods
        path_length += float(np.linalg.norm(np.diff(np.concatenate([episode.pusher[None], targets]), axis=0),
                                            axis=1).sum())
        first_sample = episode.samples
        piece = episode.advance(targets)
        pieces.append(piece)
        ends = np.arange(samples_per_period - 1, len(targets), samples_per_period)
        poses.append(piece.true_object_pose[ends])
        tips.append(piece.tip_pose[ends, :3])
        measured = _measured(piece, first_sample + 1 + ends)
        if not motion_capture:
            measured[:] = np.nan
        found = np.full((len(ends), 2), np.nan)
        if position is not None and read:
            rows = np.flatnonzero((periods + 1 + np.arange(len(ends))) % position.every == 0)
            if len(rows):
                found[rows] = position.locate(obj, piece.true_object_pose[ends[rows], 1:], piece.tip_pose[ends[rows], 1:3])
                readings.append(np.concatenate([piece.true_object_pose[ends[rows], :1], found[rows]], axis=1))
        periods += len(ends)
        return piece.tip_pose[ends, 1:3], measured, found

    still = np.repeat(pusher[None], samples_per_period, axis=0)
    if motion_capture:
        observed = execute(still)[1][-1]
        while not np.all(np.isfinite(observed)):  # the first measurement was dropped: wait for one
            observed = execute(still)[1][-1]
        prior_std = np.asarray(PRIOR_STD)
    else:  # the first reading locates the centre of mass; the orientation is the start pose's, where it was placed
        found = execute(still)[2][-1]
        while not np.all(np.isfinite(found)):
            found = execute(still)[2][-1]
        observed = np.concatenate([found - np.asarray(contact.rotate(model.shape.centroid, start[2]), np.float64),
                                   start[2:3]])
        prior_std = np.concatenate([position.std, PRIOR_STD[2:]])
    mean = jnp.asarray(np.concatenate([observed, [0.0, 0.0]]), jnp.float32)
    cov = jnp.diag(jnp.asarray(prior_std, jnp.float32) ** 2)
    estimates, estimate_times, plans, repositions, idle, stop, skipped = [], [], 0, 0, 0, "timeout", 0
    while episode.time < loop.max_time:
        estimate = np.asarray(mean[:3], np.float64)
        estimates.append(estimate)
        estimate_times.append(episode.time)
        position_error = float(np.hypot(*(estimate[:2] - goal[:2])))
        if position_error < loop.stop_position and abs(float(wrap(estimate[2] - goal[2]))) < loop.stop_yaw:
            stop = "reached"
            break
        commanded = episode.pusher.copy()
        state, decision = mpc.replan(config, model, state, jnp.asarray(estimate, jnp.float32),
                                     jnp.asarray(commanded, jnp.float32), goal_array)
        plans += 1
        decision = jax.device_get(decision)
        helpful = bool(decision.reposition) or decision.cost < decision.idle_cost * (1.0 - 1e-3)
        idle = 0 if helpful else idle + 1
        if idle >= loop.patience:
            stop = "stuck"
            break
        if decision.reposition:
            repositions += 1
            targets = waypoint_targets(commanded, decision.waypoints, config.speed_limit * push.SAMPLE_PERIOD,
                                       samples_per_period)
        else:
            steps = np.asarray(decision.increments[:config.replan_steps], np.float64)
            fractions = np.arange(1, samples_per_period + 1)[None, :, None] / samples_per_period
            starts = commanded + np.concatenate([np.zeros((1, 2)), np.cumsum(steps, axis=0)[:-1]])
            targets = (starts[:, None] + fractions * steps[:, None]).reshape(-1, 2)
        tip_path, measurements, found = execute(targets)
        path = np.concatenate([commanded[None], tip_path]).astype(np.float32)
        for begin, end, measurement, reading in zip(path[:-1], path[1:], measurements.astype(np.float32),
                                                    found.astype(np.float32)):
            mean, cov = filter_period(system, mean, cov, begin, end - begin, measurement)
            if np.all(np.isfinite(reading)):
                mean, cov, used = position_update(sensor, mean, cov, reading, gate)
                skipped += not bool(used)
    execute(np.repeat(episode.pusher[None], max(1, round(loop.settle / config.period)) * samples_per_period, axis=0),
            read=False)
    poses, tips = np.concatenate(poses), np.concatenate(tips)
    final = poses[-1, 1:]
    return EpisodeResult(
        final_pose=final, position_error=float(np.hypot(*(final[:2] - goal[:2]))),
        yaw_error=float(wrap(final[2] - goal[2])), path_length=path_length, time=episode.time,
        wall_time=time.perf_counter() - began, plans=plans, repositions=repositions, stop=stop, poses=poses,
        pusher=tips, estimates=np.asarray(estimates).reshape(-1, 3),
        readings=np.concatenate(readings) if readings else np.zeros((0, 3)),
        estimate_times=np.asarray(estimate_times, np.float64), skipped_readings=skipped,
        recording=push.Recording(params=None, **{name: np.concatenate([getattr(piece, name) for piece in pieces])
                                                  for name in ("tip_pose", "object_pose", "ft_wrench",
                                                               "true_object_pose")}))
