"""Simulated pushes following the MIT Push Dataset protocol, recorded in the dataset's raw layout.

The pusher follows the protocol of :mod:`pushjax.mit.protocol` (path :func:`~pushjax.mit.protocol.pusher_line`,
motion :func:`~pushjax.mit.protocol.pusher_motion`). When the pusher stops, recording goes on for 0.5 s so that
any sliding after the push is recorded.

Recording (250 Hz, one clock, ``t`` from 0 at the start of the pusher's motion):

* ``tip_pose`` [t, x, y, 0]: the simulated pusher tip's centre (m; the tip does not turn).
* ``object_pose`` [t, x, y, yaw]: the object's tracked frame (m, rad in (-π, π]), after the tracking effects
  (and, under a non-ideal testbed, :mod:`pushjax.sim.testbed`'s motion capture: noise, time-stamp jitter and
  dropped samples, so this stream may have fewer rows and off-grid time stamps).
* ``ft_wrench`` [t, fx, fy, torque]: the force (N) that the pusher applies to the object, world axes, and its
  moment (N·m) about the pusher's axis, which only pusher–object friction makes non-zero; both averaged over the
  4 ms before ``t`` like a low-pass filtered force-torque sensor (the sample at ``t = 0`` is instantaneous).

Simulation: MuJoCo scenes from :mod:`pushjax.sim.scene`, whose pusher is a servo-driven carriage (MuJoCo's mocap
bodies have no velocity, so contacts with them lag behind; the mocap body ``pusher`` only mirrors the commanded
position for rendering). The servo tracks the commanded position and velocity; the recorded tip pose is the
simulated one. The time step is ``4 ms / n`` with the smallest ``n >= 2`` for which the pusher advances at most
0.1 mm per step (2 ms up to 50 mm/s, 0.2 ms at 500 mm/s). Before any push the object settles on the table for
0.3 s (with gravity normal to the table); every push starts from that settled state, placed at the requested
pose, with a zero solver warm start, so a push's result does not depend on the pushes simulated before it.

Testbed (:mod:`pushjax.sim.testbed`): a push simulated with :class:`~pushjax.sim.testbed.PushConditions` is stepped
one simulation step at a time. At the start of every 4 ms recording period the support contacts' coefficients are
set from the conditions: the speed factor at the support points' current sliding speeds, the position factors (load
distribution, friction field) where the support points are, evaluated again only once a support point has moved
:data:`FIELD_UPDATE_DISTANCE` (0.5 mm) since their last evaluation (the fields vary over centimetres). The
pusher–object coefficient comes from the push's draw. The mocap body ``pusher`` (drawn, never in contact) is not
moved in a stepped push. Without conditions (the ideal testbed) the push runs as a single ``mujoco.rollout`` call
with the model's fixed coefficients.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable, Sequence

import mujoco
import numpy as np
from mujoco import rollout

from pushjax import planar
from pushjax.geometry.objects import PushObject, get_object
from pushjax.mit.files import PushParams
from pushjax.mit.protocol import push_duration, pusher_line, pusher_motion
from pushjax.sim import scene
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import PushConditions

SAMPLE_RATE = 250.0
"""Recording rate in Hz."""
SAMPLE_PERIOD = 1.0 / SAMPLE_RATE
POST_PUSH_DURATION = 0.5
"""Recording time after the pusher stops in s."""
SETTLE_DURATION = 0.3
"""Time the object rests on the table before any push, to seat its support contacts, in s."""
MAX_STEP_TRAVEL = 1e-4
"""Largest pusher advance per simulation step in m."""
MIN_STEPS_PER_SAMPLE = 2
MAX_SPEED_RATIO = 3.0
SPEED_ALLOWANCE = 0.01
"""A recorded push is physically implausible when its object's tracked frame moves, over any
:data:`SPEED_WINDOW`, faster than ``MAX_SPEED_RATIO`` × the pusher's speed + ``SPEED_ALLOWANCE`` (m/s)."""
SPEED_WINDOW = 0.1
"""Time over which the object's speed is measured for the plausibility check, in s."""
CORNER_SHIFT = 1e-4
"""How far (m, along the side, towards its middle) the pusher's line moves when a push is simulated again."""
FIELD_UPDATE_DISTANCE = 5e-4
"""Under a testbed, the position-dependent support coefficients are evaluated again once a support point has
moved this far (m) from where they were last evaluated (the fields vary over centimetres)."""

_PARKED_PUSHER = np.array([1.0, 1.0])
"""Where the pusher waits while the object settles, m (far from every object)."""


@dataclasses.dataclass(frozen=True, eq=False)
class Recording:
    """One recorded push, every stream sampled on the same 250 Hz clock.

    Attributes:
      params: the push (None for a piece of an :class:`Episode`).
      tip_pose: [N, 4] rows [t s, x m, y m, yaw rad (0)].
      object_pose: [M, 4] rows [t s, x m, y m, yaw rad] as recorded (with the tracking effects; M = N unless a
        testbed drops samples).
      ft_wrench: [N, 4] rows [t s, fx N, fy N, torque N·m].
      true_object_pose: [N, 4] the simulated pose of the tracked frame, before the tracking effects.
      line_shift: how far (m) the pusher's line was moved along the side to avoid a degenerate contact (0 for
        almost every push; see :meth:`Simulator.run`).
    """

    params: PushParams | None
    tip_pose: np.ndarray
    object_pose: np.ndarray
    ft_wrench: np.ndarray
    true_object_pose: np.ndarray
    line_shift: float = 0.0


class ImplausibleMotionError(RuntimeError):
    """A simulated push moved its object faster than the pusher can (see :func:`implausible_speed`)."""


class Simulator:
    """Simulates pushes of one object on one surface under fixed effects (one compiled MuJoCo model).

    Args:
      obj: the object or its name.
      surface: surface name.
      effects: the effects; the physical ones shape the model, the tracking ones the recorded poses.
      support: one of :data:`pushjax.sim.scene.SUPPORT_MODES`.
    """

    def __init__(self, obj: PushObject | str, surface: str, effects: Effects = Effects(), support: str = "grid"):
        self.obj = get_object(obj) if isinstance(obj, str) else obj
        self.surface = surface
        self.effects = effects
        self.support = support
        self.model = scene.build_model(self.obj, surface, effects, support)
        self.data = mujoco.MjData(self.model)
        self._object_qpos = int(self.model.jnt_qposadr[self.model.joint("object_joint").id])
        self._object_dof = int(self.model.jnt_dofadr[self.model.joint("object_joint").id])
        self._pusher_qpos = int(self.model.jnt_qposadr[self.model.joint("pusher_x").id])
        self._pusher_qvel = int(self.model.jnt_dofadr[self.model.joint("pusher_x").id])
        self._pusher_z = float(self.model.body("pusher").pos[2])
        self._state_spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self._control_spec = int(mujoco.mjtState.mjSTATE_CTRL) | int(mujoco.mjtState.mjSTATE_MOCAP_POS)
        self._settled_object = self._settle()
        self._support_local, self._support_areas = scene.support_points(self.obj, support)
        # MuJoCo may swap the two geoms of a pair, so a pair is found by either.
        pair_geoms = np.stack([self.model.pair_geom1, self.model.pair_geom2], axis=1)
        self._support_of_geom = {int(self.model.geom(f"support{k}").id): k for k in range(len(self._support_local))}
        self._support_pairs = np.array([int(np.flatnonzero((pair_geoms == geom).any(axis=1))[0])
                                        for geom in self._support_of_geom])
        self._pusher_pairs = np.flatnonzero((pair_geoms == self.model.geom("pusher_tip").id).any(axis=1))

    def _settle(self) -> np.ndarray:
        """[7] free-joint qpos of the object resting at the origin (gravity normal to the table)."""
        model, data = self.model, self.data
        mujoco.mj_resetData(model, data)
        tilted_gravity = model.opt.gravity.copy()
        model.opt.gravity[:] = [0.0, 0.0, -np.linalg.norm(tilted_gravity)]
        model.opt.timestep = SAMPLE_PERIOD / MIN_STEPS_PER_SAMPLE
        data.qpos[self._object_qpos + 2] = self.obj.thickness / 2
        data.qpos[self._pusher_qpos:self._pusher_qpos + 2] = _PARKED_PUSHER
        data.ctrl[:] = [*_PARKED_PUSHER, 0.0, 0.0]
        try:
            mujoco.mj_step(model, data, nstep=round(SETTLE_DURATION / model.opt.timestep))
        finally:
            model.opt.gravity[:] = tilted_gravity
        settled = data.qpos[self._object_qpos:self._object_qpos + 7].copy()
        settled[:2] = 0.0
        settled[3:] = _yaw_removed(settled[3:])
        return settled

    def run(self, params: PushParams, initial_pose: Sequence[float] = (0.0, 0.0, 0.0),
            rng: np.random.Generator | None = None, conditions: PushConditions | None = None,
            on_step: Callable[[Simulator], None] | None = None) -> Recording:
        """Simulates and records one push.

        Args:
          params: the push (its ``shape`` must be this simulator's object).
          initial_pose: (x m, y m, yaw rad) of the object's tracked frame at the start.
          rng: random generator for the tracking noise; required when ``effects.tracking_noise`` is non-zero.
          conditions: the testbed's draw for this push (:func:`pushjax.sim.testbed.draw_conditions`; its
            ``plate_pressure`` must have one value per support point); None: the ideal testbed.
          on_step: called with this simulator after every physics step (e.g. to read
            :meth:`support_normal_forces`); the push is then stepped in Python, the same simulation but slower.

        Returns:
          The :class:`Recording`.

        Raises:
          ImplausibleMotionError: the push moved the object implausibly fast (:func:`implausible_speed`) even
            with its line shifted. A pusher whose line runs exactly along the face next to the pushed corner
            (a corner push of a rectangle at 0°) meets a degenerate vertex contact, which MuJoCo's convex
            collision may resolve along the wrong face and fling the plate centimetres sideways; such a push is
            simulated again with the pusher's line moved :data:`CORNER_SHIFT` along the side towards its middle
            (recorded in ``Recording.line_shift``), every other push as requested.
        """
        if params.shape != self.obj.name:
            raise ValueError(f"params: shape {params.shape!r} does not match the simulator's object {self.obj.name!r}")
        if params.side >= len(self.obj.sides):
            raise ValueError(
                f"params: side {params.side} out of range, {self.obj.name} has {len(self.obj.sides)} sides")
        pose = np.asarray(initial_pose, dtype=np.float64)
        if pose.shape != (3,) or not np.all(np.isfinite(pose)):
            raise ValueError(f"initial_pose: expected finite (x, y, yaw), got {initial_pose!r}")
        noisy = any(self.effects.tracking_noise)
        if conditions is not None and len(conditions.plate_pressure) != len(self._support_pairs):
            raise ValueError(f"conditions: {len(conditions.plate_pressure)} support values for "
                             f"{len(self._support_pairs)} support points")
        if noisy and rng is None:
            raise ValueError("rng: required to draw the tracking noise of these effects")

        line_shift = 0.0
        true_pose, tip_pose, ft_wrench = self._simulate(params, pose, conditions, line_shift, on_step)
        if implausible_speed(true_pose, params) is not None:
            line_shift = CORNER_SHIFT
            true_pose, tip_pose, ft_wrench = self._simulate(params, pose, conditions, line_shift, on_step)
            if (speed := implausible_speed(true_pose, params)) is not None:
                raise ImplausibleMotionError(
                    f"params: {params}: the object moved at {speed * 1000:.0f} mm/s behind a pusher at "
                    f"{params.velocity_si * 1000:.0f} mm/s, also with the pusher's line shifted "
                    f"{CORNER_SHIFT * 1000:g} mm")
        recorded = _tracked(true_pose, self.effects, rng if noisy else None)
        if conditions is not None:
            recorded = conditions.track(recorded)
        return Recording(params=params, tip_pose=tip_pose, object_pose=recorded, ft_wrench=ft_wrench,
                         true_object_pose=true_pose, line_shift=line_shift)

    def _simulate(self, params: PushParams, pose: np.ndarray, conditions: PushConditions | None,
                  line_shift: float, on_step: Callable[[Simulator], None] | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """([N, 4] true object pose, [N, 4] tip pose, [N, 4] wrench) of one push (see :meth:`run`), its pusher's
        line moved ``line_shift`` m along the pushed side towards the side's middle."""
        model, data = self.model, self.data
        steps_per_sample = max(MIN_STEPS_PER_SAMPLE,
                               math.ceil(params.velocity_si * SAMPLE_PERIOD / MAX_STEP_TRAVEL - 1e-9))
        model.opt.timestep = SAMPLE_PERIOD / steps_per_sample
        samples = math.ceil((push_duration(params) + POST_PUSH_DURATION) / SAMPLE_PERIOD) + 1
        nstep = (samples - 1) * steps_per_sample

        rotation = planar.rotation_matrix(pose[2])
        start_local, direction_local = pusher_line(self.obj, _shifted(self.obj, params, line_shift))
        start = pose[:2] + rotation @ start_local
        direction = rotation @ direction_local
        targets = np.arange(1, nstep + 1) * model.opt.timestep
        distance, speed = pusher_motion(params, targets)
        target_xy = start + distance[:, None] * direction
        control = np.concatenate([
            target_xy, speed[:, None] * direction, target_xy, np.full((nstep, 1), self._pusher_z)], axis=1)

        initial_state = self._place(pose, start, pusher_motion(params, np.zeros(1))[1][0] * direction)
        if conditions is None and on_step is None:
            states, sensors = rollout.rollout(
                model, data, initial_state[None], control[None], control_spec=self._control_spec,
                initial_warmstart=np.zeros((1, model.nv)))
            qpos_steps, sensors = states[0][:, 1:1 + model.nq], sensors[0]
        else:
            qpos_steps, sensors = self._stepped(control, conditions, steps_per_sample, on_step)

        # qpos_steps[k] follows step k; prepend the initial state so that index k is time k * timestep.
        qpos_path = np.concatenate([initial_state[None, 1:1 + model.nq], qpos_steps])
        sampled = qpos_path[::steps_per_sample]
        times = np.arange(samples) * SAMPLE_PERIOD
        object_qpos = sampled[:, self._object_qpos:self._object_qpos + 7]
        true_pose = np.column_stack([times, object_qpos[:, :2], _yaw(object_qpos[:, 3:])])
        tip_pose = np.column_stack([times, sampled[:, self._pusher_qpos:self._pusher_qpos + 2], np.zeros(samples)])

        # sensors[k] is computed at the state of time k * timestep: force, torque (at pos), pos.
        wrench = _step_wrench(sensors, qpos_path[:-1, self._pusher_qpos:self._pusher_qpos + 2])
        averaged = np.concatenate([wrench[:1], wrench.reshape(samples - 1, steps_per_sample, 3).mean(axis=1)])
        ft_wrench = np.column_stack([times, averaged])
        return true_pose, tip_pose, ft_wrench

    def _place(self, pose: np.ndarray, pusher: np.ndarray, pusher_velocity: np.ndarray) -> np.ndarray:
        """Resets ``self.data`` to the settled object at `pose` (x m, y m, yaw rad) and the pusher at `pusher` [2]
        (m) moving at `pusher_velocity` [2] (m/s), with a zero solver warm start; returns that state (full
        physics)."""
        model, data = self.model, self.data
        mujoco.mj_resetData(model, data)
        rotation = planar.rotation_matrix(pose[2])
        qpos = data.qpos
        qpos[self._object_qpos:self._object_qpos + 2] = pose[:2] + rotation @ self._settled_object[:2]
        qpos[self._object_qpos + 2] = self._settled_object[2]
        quaternion = np.empty(4)
        mujoco.mju_mulQuat(quaternion, _yaw_quaternion(pose[2]), self._settled_object[3:])
        qpos[self._object_qpos + 3:self._object_qpos + 7] = quaternion
        qpos[self._pusher_qpos:self._pusher_qpos + 2] = pusher
        data.qvel[self._pusher_qvel:self._pusher_qvel + 2] = pusher_velocity
        data.qacc_warmstart[:] = 0.0
        initial_state = np.empty(mujoco.mj_stateSize(model, self._state_spec))
        mujoco.mj_getState(model, data, initial_state, self._state_spec)
        return initial_state

    def _stepped(self, control: np.ndarray, conditions: PushConditions | None, steps_per_update: int,
                 on_step: Callable[[Simulator], None] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """([nstep, nq] qpos after each step, [nstep, nsensordata] sensors at the state before each step) of the
        push whose state ``self.data`` holds, under the coefficients of ``conditions``: the pusher's for the whole
        push, the supports' set from the object's state every ``steps_per_update`` steps (see the module docstring;
        the model's coefficients are restored afterwards); None: the model's own coefficients. ``on_step`` (if any)
        is called after every step."""
        model, data = self.model, self.data
        nominal = model.pair_friction.copy()
        support_nominal = nominal[self._support_pairs, :2]
        nstep = len(control)
        qpos_steps = np.empty((nstep, model.nq))
        sensors = np.empty((nstep, model.nsensordata))
        ctrl, qpos, sensordata = data.ctrl, data.qpos, data.sensordata
        pair_friction = model.pair_friction
        # Any support point is at most this far from the tracked frame's origin (bounds its motion by the pose's).
        reach = float(np.linalg.norm(self._support_local, axis=1).max())
        evaluated_at = (math.inf, math.inf, 0.0)  # pose (x m, y m, yaw rad) of the last position factors
        try:
            if conditions is not None:
                pair_friction[self._pusher_pairs, :2] = nominal[self._pusher_pairs, :2] * conditions.pusher_friction
            for first_step in range(0, nstep, steps_per_update):
                if conditions is not None:
                    pose, speeds = self._support_motion()
                    moved = math.hypot(pose[0] - evaluated_at[0], pose[1] - evaluated_at[1]) + reach * abs(
                        pose[2] - evaluated_at[2])
                    if moved > FIELD_UPDATE_DISTANCE:
                        points = planar.rotate(self._support_local, pose[2]) + pose[:2]
                        position_factors = conditions.position_factors(points, self._support_areas)
                        evaluated_at = pose
                    factors = position_factors * conditions.speed_factors(speeds)
                    pair_friction[self._support_pairs, :2] = support_nominal * factors[:, None]
                for k in range(first_step, min(first_step + steps_per_update, nstep)):
                    ctrl[:] = control[k, :4]
                    mujoco.mj_step(model, data)
                    qpos_steps[k] = qpos
                    sensors[k] = sensordata
                    if on_step is not None:
                        on_step(self)
        finally:
            model.pair_friction[:] = nominal
        return qpos_steps, sensors

    @property
    def support_points(self) -> np.ndarray:
        """[K, 2] the support points in the tracked frame, m (:func:`pushjax.sim.scene.support_points`)."""
        return self._support_local.copy()

    def support_forces(self) -> np.ndarray:
        """[K, 2] the size of the table's normal and of its tangential (friction) force on each support point in the
        current state, N (each summed over the point's contacts; 0 where it does not touch)."""
        model, data = self.model, self.data
        normal, friction = np.zeros((len(self._support_local), 3)), np.zeros((len(self._support_local), 3))
        wrench = np.zeros(6)
        for c in range(data.ncon):
            contact = data.contact[c]
            k = self._support_of_geom.get(int(contact.geom1), self._support_of_geom.get(int(contact.geom2)))
            if k is not None:
                mujoco.mj_contactForce(model, data, c, wrench)
                frame = contact.frame.reshape(3, 3)  # rows: the contact's normal and its two tangents, world axes
                normal[k] += wrench[0] * frame[0]
                friction[k] += wrench[1] * frame[1] + wrench[2] * frame[2]
        return np.stack([np.linalg.norm(normal, axis=1), np.linalg.norm(friction, axis=1)], axis=1)

    def support_normal_forces(self) -> np.ndarray:
        """[K] normal force of each support point on the table in the current state, N (0 where it does not
        touch)."""
        return self.support_forces()[:, 0]

    def support_sliding_speeds(self) -> np.ndarray:
        """[K] sliding speed of each support point over the table in the current state, m/s."""
        return self._support_motion()[1]

    def object_velocity(self) -> np.ndarray:
        """[3] the tracked frame's velocity along its own axes (m/s) and its yaw rate (rad/s) in the current state."""
        (_, _, yaw), _ = self._support_motion()
        dof = self._object_dof
        vx, vy, _, _, _, spin = self.data.qvel[dof:dof + 6].tolist()
        return np.array([math.cos(yaw) * vx + math.sin(yaw) * vy, math.cos(yaw) * vy - math.sin(yaw) * vx, spin])

    def _support_motion(self) -> tuple[tuple[float, float, float], np.ndarray]:
        """(pose (x m, y m, yaw rad) of the tracked frame, [K] sliding speeds of the support points in m/s) in
        ``self.data``'s state.

        The free joint's linear velocity is in the world frame, its angular velocity in the body frame (the plate
        is level to within its settling tilt, so the body z axis is the world's); a support point at ``r`` in the
        body frame slides at ``|R^T v + omega x r|``.
        """
        first, dof = self._object_qpos, self._object_dof
        x, y, _, w, qx, qy, qz = self.data.qpos[first:first + 7].tolist()
        yaw = math.atan2(2 * (w * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        vx, vy, _, _, _, spin = self.data.qvel[dof:dof + 6].tolist()
        cos, sin = math.cos(yaw), math.sin(yaw)
        local_x, local_y = self._support_local.T
        speeds = np.hypot(cos * vx + sin * vy - spin * local_y, cos * vy - sin * vx + spin * local_x)
        return (x, y, yaw), speeds


class Episode:
    """A push of any length along commanded pusher positions, simulated piece by piece as a controller sends them.

    The scene, the stepping and the testbed's coefficients are those of :meth:`Simulator.run` (the stepped path,
    with or without conditions); the object's and the pusher's states carry over from one :meth:`advance` to the
    next. The time step is fixed for the episode from ``speed_limit`` as :meth:`Simulator.run` sets it from a push's
    velocity, and no commanded move may exceed it. Motion capture: the tracking effects and, with ``conditions``,
    the testbed's noise, jitter and drops of :meth:`pushjax.sim.testbed.PushConditions.track`, drawn for piece ``k``
    from the conditions' tracking seed extended by ``k`` (the same episode gives the same measurements).

    The episode uses its simulator's ``MjData``: run one episode (or push) of a simulator at a time.

    Args:
      simulator: the :class:`Simulator` (object, surface, effects).
      object_pose: (x m, y m, yaw rad) of the object's tracked frame at the start.
      pusher: (x m, y m) of the pusher at the start (not touching the object).
      speed_limit: the pusher's largest speed, m/s.
      rng: random generator of the effects' tracking noise; required when ``effects.tracking_noise`` is non-zero.
      conditions: the testbed's draw (:func:`pushjax.sim.testbed.draw_conditions`); None: the ideal testbed.
    """

    def __init__(self, simulator: Simulator, object_pose: Sequence[float], pusher: Sequence[float],
                 speed_limit: float, rng: np.random.Generator | None = None,
                 conditions: PushConditions | None = None):
        pose = np.asarray(object_pose, dtype=np.float64)
        pusher = np.asarray(pusher, dtype=np.float64)
        if pose.shape != (3,) or not np.all(np.isfinite(pose)):
            raise ValueError(f"object_pose: expected finite (x, y, yaw), got {object_pose!r}")
        if pusher.shape != (2,) or not np.all(np.isfinite(pusher)):
            raise ValueError(f"pusher: expected finite (x, y), got {pusher!r}")
        if not (math.isfinite(speed_limit) and speed_limit > 0):
            raise ValueError(f"speed_limit: expected a speed > 0 m/s, got {speed_limit!r}")
        if any(simulator.effects.tracking_noise) and rng is None:
            raise ValueError("rng: required to draw the tracking noise of these effects")
        if conditions is not None and len(conditions.plate_pressure) != len(simulator._support_pairs):
            raise ValueError(f"conditions: {len(conditions.plate_pressure)} support values for "
                             f"{len(simulator._support_pairs)} support points")
        self.simulator, self.speed_limit, self.rng, self.conditions = simulator, speed_limit, rng, conditions
        self.steps_per_sample = max(MIN_STEPS_PER_SAMPLE,
                                    math.ceil(speed_limit * SAMPLE_PERIOD / MAX_STEP_TRAVEL - 1e-9))
        simulator.model.opt.timestep = SAMPLE_PERIOD / self.steps_per_sample
        simulator._place(pose, pusher, np.zeros(2))
        self.pusher = pusher
        self.samples = 0
        self.pieces = 0

    @property
    def time(self) -> float:
        """Seconds simulated so far."""
        return self.samples * SAMPLE_PERIOD

    def advance(self, targets: np.ndarray) -> Recording:
        """Moves the pusher through `targets` [n, 2] (m), one per 4 ms sample, straight and at constant speed from
        one to the next; returns the piece's :class:`Recording` of the n samples after the start (times from the
        episode's start; ``params`` None).

        Raises:
          ValueError: a move faster than the speed limit, or not [n, 2] finite positions.
        """
        simulator, data = self.simulator, self.simulator.data
        targets = np.asarray(targets, dtype=np.float64)
        if targets.ndim != 2 or targets.shape[1] != 2 or not len(targets) or not np.all(np.isfinite(targets)):
            raise ValueError(f"targets: expected [n, 2] finite pusher positions, got shape {targets.shape}")
        moves = np.diff(np.concatenate([self.pusher[None], targets]), axis=0)
        fastest = float(np.linalg.norm(moves, axis=1).max()) / SAMPLE_PERIOD
        if fastest > self.speed_limit * (1 + 1e-6):
            raise ValueError(f"targets: a move at {fastest * 1000:.1f} mm/s exceeds the speed limit "
                             f"{self.speed_limit * 1000:.1f} mm/s")
        steps = self.steps_per_sample
        fractions = np.arange(1, steps + 1) / steps
        starts = np.concatenate([self.pusher[None], targets[:-1]])
        position = (starts[:, None] + fractions[None, :, None] * moves[:, None]).reshape(-1, 2)
        velocity = np.repeat(moves / SAMPLE_PERIOD, steps, axis=0)
        pusher_columns = slice(simulator._pusher_qpos, simulator._pusher_qpos + 2)
        tip_before = data.qpos[pusher_columns].copy()
        qpos_steps, sensors = simulator._stepped(np.concatenate([position, velocity], axis=1), self.conditions, steps)
        tip_at_step = np.concatenate([tip_before[None], qpos_steps[:-1, pusher_columns]])
        wrench = _step_wrench(sensors, tip_at_step).reshape(len(targets), steps, 3).mean(axis=1)
        sampled = qpos_steps[steps - 1::steps]
        times = (self.samples + np.arange(1, len(targets) + 1)) * SAMPLE_PERIOD
        first = simulator._object_qpos
        true_pose = np.column_stack([times, sampled[:, first:first + 2], _yaw(sampled[:, first + 3:first + 7])])
        tip = sampled[:, pusher_columns]
        recorded = _tracked(true_pose, simulator.effects, self.rng if any(simulator.effects.tracking_noise) else None)
        if self.conditions is not None:
            piece = dataclasses.replace(self.conditions,
                                        tracking_seed=(*self.conditions.tracking_seed, self.pieces))
            recorded = piece.track(recorded)
        self.pusher = targets[-1]
        self.samples += len(targets)
        self.pieces += 1
        return Recording(params=None, tip_pose=np.column_stack([times, tip, np.zeros(len(times))]),
                         object_pose=recorded, ft_wrench=np.column_stack([times, wrench]),
                         true_object_pose=true_pose)


def _step_wrench(sensors: np.ndarray, tip_at_step: np.ndarray) -> np.ndarray:
    """[n, 3] (fx N, fy N, torque N·m about the pusher's axis) from the contact sensor's [n, 9] readings (force,
    torque at pos, pos) and the pusher tip's [n, 2] positions at the same states."""
    force = sensors[:, 0:2]
    lever = sensors[:, 6:8] - tip_at_step
    moment = sensors[:, 5] + lever[:, 0] * sensors[:, 1] - lever[:, 1] * sensors[:, 0]
    return np.column_stack([force, moment])


def implausible_speed(object_pose: np.ndarray, params: PushParams) -> float | None:
    """The object's largest speed (m/s, over :data:`SPEED_WINDOW`) if it exceeds what the push can cause, else None.

    Args:
      object_pose: [N, 4] rows [t s, x m, y m, yaw rad], increasing t (simulated or tracked, with gaps or not).
      params: the push (its velocity bounds the object's).
    """
    times = object_pose[:, 0]
    later = np.searchsorted(times, times + SPEED_WINDOW)
    first = np.flatnonzero(later < len(times))
    if not len(first):
        return None
    last = later[first]
    distance = np.linalg.norm(object_pose[last, 1:3] - object_pose[first, 1:3], axis=1)
    speed = float((distance / (times[last] - times[first])).max())
    return speed if speed > MAX_SPEED_RATIO * params.velocity_si + SPEED_ALLOWANCE else None


def _shifted(obj: PushObject, params: PushParams, distance: float) -> PushParams:
    """``params`` with its contact point moved ``distance`` m along the side towards the side's middle."""
    if distance == 0.0:
        return params
    length = float(np.linalg.norm(np.diff(obj.sides[params.side], axis=0), axis=1).sum())
    step = min(distance / length, abs(0.5 - params.point))
    return dataclasses.replace(params, point=params.point + math.copysign(step, 0.5 - params.point))


def _tracked(true_pose: np.ndarray, effects: Effects, rng: np.random.Generator | None) -> np.ndarray:
    """The motion-capture view of [N, 4] poses: marker offset (bias) and i.i.d. Gaussian noise."""
    dx, dy, dyaw = effects.tracking_bias
    yaw = true_pose[:, 3]
    recorded = true_pose.copy()
    recorded[:, 1:3] += planar.rotate(np.array([dx, dy]), yaw)
    recorded[:, 3] += dyaw
    if rng is not None:
        sigma_xy, sigma_yaw = effects.tracking_noise
        noise = rng.standard_normal((len(recorded), 3))
        recorded[:, 1:3] += sigma_xy * noise[:, :2]
        recorded[:, 3] += sigma_yaw * noise[:, 2]
    recorded[:, 3] = np.angle(np.exp(1j * recorded[:, 3]))
    return recorded


def _yaw_quaternion(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def _yaw(quaternions: np.ndarray) -> np.ndarray:
    """[N] yaw in (-π, π] of [N, 4] unit quaternions (w, x, y, z)."""
    w, x, y, z = quaternions.T
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _yaw_removed(quaternion: np.ndarray) -> np.ndarray:
    """The quaternion with its yaw turned back to 0 (keeps the small settling tilt)."""
    result = np.empty(4)
    mujoco.mju_mulQuat(result, _yaw_quaternion(-float(_yaw(quaternion[None])[0])), quaternion)
    return result


@functools.lru_cache(maxsize=8)
def simulator(obj: str, surface: str, effects: Effects = Effects(), support: str = "grid") -> Simulator:
    """A cached :class:`Simulator` (one per object, surface, effects and support in this process)."""
    return Simulator(obj, surface, effects, support)


def simulate_push(params: PushParams, effects: Effects = Effects(), support: str = "grid",
                  initial_pose: Sequence[float] = (0.0, 0.0, 0.0),
                  rng: np.random.Generator | None = None, conditions: PushConditions | None = None) -> Recording:
    """Simulates one push (object and surface from ``params``); see :meth:`Simulator.run`."""
    return simulator(params.shape, params.surface, effects, support).run(params, initial_pose, rng, conditions)
