"""The state, process and observation models the filters share.

State (``STATE_NAMES``, [5]): the object's tracked-frame pose (x m, y m, yaw rad, yaw unwrapped) augmented with
two latent physical parameters as log scales of nominal values, ``mu = mu_nominal exp(log_mu_scale)`` (pusher
friction) and ``l = l_nominal exp(log_l_scale)`` (limit-surface ratio), so a Gaussian belief keeps both
positive.

Process model (:func:`transition`): one step of the JAX rollout, :func:`pushjax.physics.rollout.step` (the
contact annotated again on the outline, the pushing model of Lynch, or of the effects composed into
:attr:`System.effects`), for the pusher's known motion over the step; the latents stay constant. Its noise
(:attr:`System.process_std`, per step) stands for what the model leaves out: a Gaussian on the pose, and a small
random walk on the latents so that they can follow slow changes.

Observation model (:func:`observe`): the pose, as a motion-capture system measures it, with Gaussian noise
(:attr:`System.measurement_std`). A dropped sample is a row of NaN (any NaN in the row): the filters skip the
update there (predict only), they never read it as a zero. Yaw innovations are wrapped to (-pi, pi].

A second observation model (:class:`PositionSensor`, :func:`observe_position`, :func:`update_position`): the world
position of a point fixed on the object (the centre of mass, as a trained perception network locates it in a depth
image: ``pushjax.sensing.perception``), with its own Gaussian noise (:attr:`PositionSensor.std`) and no orientation.
It is nonlinear in the state (the point turns with the yaw), so the Gaussian filters update with it linearised at
the predicted mean (the EKF's update, ``jax.jacfwd`` of :func:`observe_position`). A missing reading is NaN and
skipped, like a dropped pose; where both streams have a sample, the pose update comes first, then the position
update (independent noises: the order does not matter for a linear update).

Units: SI (m, rad). All functions are per push and pure; ``jax.vmap`` the filters over pushes.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import flax.struct
import jax
import jax.numpy as jnp
import numpy as np

from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object, limit_surface_ratio
from pushjax.physics import effects as effects_lib
from pushjax.physics import rollout

__all__ = ["POSE_SIZE", "POSITION_SIZE", "STATE_NAMES", "STATE_SIZE", "PositionSensor", "System", "Track",
           "checked_position_std", "innovation", "make_position_sensor", "make_system", "observe", "observe_position",
           "gated_update_position", "observed", "physical", "transition", "update", "update_linear",
           "update_position"]

STATE_NAMES = ("x", "y", "yaw", "log_mu_scale", "log_l_scale")
STATE_SIZE = len(STATE_NAMES)
POSE_SIZE = 3
POSITION_SIZE = 2


@flax.struct.dataclass
class System:
    """Everything the models need about one object (a pytree; ``effects`` is static).

    Attributes:
      shape: the object's outline (:func:`pushjax.geometry.outline_jax.outline`).
      l: [] nominal limit-surface ratio, m.
      mu: [] nominal pusher-object friction coefficient.
      process_std: [5] standard deviation of the process noise per step (x m, y m, yaw rad, log mu, log l).
      measurement_std: [3] standard deviation of a pose measurement (x m, y m, yaw rad).
      radius: [] pusher radius, m.
      params: the composed effects' parameters ({} for plain Lynch).
      support: the object's support (:func:`pushjax.physics.rollout.object_support`) when an effect needs it (the
        exact limit surface), else None.
      effects: names of the composed effects (static).
    """

    shape: outline_jax.Outline
    l: jax.Array
    mu: jax.Array
    process_std: jax.Array
    measurement_std: jax.Array
    radius: jax.Array
    params: dict
    support: rollout.Support | None = None
    effects: tuple[str, ...] = flax.struct.field(pytree_node=False, default=())


class Track(NamedTuple):
    """A filter's output over a push: ``mean`` [T + 1, 5] and ``cov`` [T + 1, 5, 5], the belief after each
    observation (the first after the first observation), and ``observed`` [T + 1] bool (the row was not dropped)."""

    mean: jax.Array
    cov: jax.Array
    observed: jax.Array


def make_system(obj: PushObject | str, mu: float = 0.25, l: float | None = None, *,
                process_std: Sequence[float] = (2e-4, 2e-4, 3e-3, 1e-3, 1e-3),
                measurement_std: Sequence[float] = (2e-4, 2e-4, 3e-3),
                effects: Sequence[str] = (), params: dict | None = None, dtype=jnp.float32,
                ellipse_points: int | None = None) -> System:
    """The :class:`System` of `obj` with nominal `mu` and `l` (uniform pressure when omitted).

    The default measurement noise is the realistic testbed's motion capture (0.2 mm, 3 mrad); the default process
    noise is of the same size per step.
    """
    obj = get_object(obj) if isinstance(obj, str) else obj
    l = limit_surface_ratio(obj) if l is None else l
    process_std = np.asarray(process_std, np.float64)
    measurement_std = np.asarray(measurement_std, np.float64)
    if process_std.shape != (STATE_SIZE,) or np.any(process_std < 0):
        raise ValueError(f"process_std: expected {STATE_SIZE} values >= 0, got {process_std.tolist()}")
    if measurement_std.shape != (POSE_SIZE,) or np.any(measurement_std <= 0):
        raise ValueError(f"measurement_std: expected {POSE_SIZE} values > 0, got {measurement_std.tolist()}")
    if not (np.isfinite(mu) and mu > 0 and np.isfinite(l) and l > 0):
        raise ValueError(f"mu, l: expected positive nominal values, got {mu}, {l}")
    effects = tuple(effects)
    params = effects_lib.init_params(effects) if params is None else params
    return System(shape=outline_jax.outline(obj, dtype, ellipse_points), l=jnp.asarray(l, dtype),
                  mu=jnp.asarray(mu, dtype), process_std=jnp.asarray(process_std, dtype),
                  measurement_std=jnp.asarray(measurement_std, dtype), radius=jnp.asarray(PUSHER_RADIUS, dtype),
                  params=jax.tree_util.tree_map(lambda x: jnp.asarray(x, dtype), params),
                  support=rollout.object_support(obj, dtype) if effects_lib.needs_support(effects) else None,
                  effects=effects)


def transition(system: System, state, pusher, increment):
    """[5] state after one step of the pusher from `pusher` [2] by `increment` [2] (world, m)."""
    pose, latents = state[:POSE_SIZE], state[POSE_SIZE:]
    mu = system.mu * jnp.exp(latents[0])
    l = system.l * jnp.exp(latents[1])
    new_pose, _ = rollout.step(effects_lib.compose(system.effects), system.params, system.shape, pose, pusher,
                               increment, l, mu, system.radius, support=system.support)
    return jnp.concatenate([new_pose, latents])


def observe(state):
    """[3] the pose a measurement sees."""
    return state[..., :POSE_SIZE]


def observed(measurement):
    """[] bool: the measurement [3] was not dropped (no NaN)."""
    return jnp.all(jnp.isfinite(measurement))


def innovation(measurement, predicted):
    """[3] measurement minus predicted pose, yaw wrapped to (-pi, pi]; zeros for a dropped measurement."""
    present = observed(measurement)
    difference = jnp.where(present, measurement, predicted) - predicted
    yaw = jnp.arctan2(jnp.sin(difference[2]), jnp.cos(difference[2]))
    return difference.at[2].set(yaw)


def update_linear(system: System, mean, cov, measurement):
    """Kalman update of a Gaussian belief with a pose measurement (the observation is linear in the state); a
    dropped measurement leaves the belief unchanged. Joseph form, symmetrised."""
    h = jnp.eye(POSE_SIZE, STATE_SIZE, dtype=cov.dtype)
    r = jnp.diag(system.measurement_std ** 2)
    s = h @ cov @ h.T + r
    gain = jnp.linalg.solve(s, h @ cov).T
    new_mean = mean + gain @ innovation(measurement, observe(mean))
    factor = jnp.eye(STATE_SIZE, dtype=cov.dtype) - gain @ h
    new_cov = factor @ cov @ factor.T + gain @ r @ gain.T
    new_cov = 0.5 * (new_cov + new_cov.T)
    present = observed(measurement)
    return jnp.where(present, new_mean, mean), jnp.where(present, new_cov, cov)


@flax.struct.dataclass
class PositionSensor:
    """The second observation model: the world position of a point fixed on the object, with Gaussian noise (a pytree).

    Attributes:
      offset: [2] the observed point in the object's tracked frame, m (the centre of mass:
        :attr:`pushjax.geometry.objects.PushObject.centroid`).
      std: [2] standard deviation of a reading, world x and y, m.
    """

    offset: jax.Array
    std: jax.Array


def make_position_sensor(obj: PushObject | str, std: Sequence[float], dtype=jnp.float32) -> PositionSensor:
    """The :class:`PositionSensor` of `obj`'s centre of mass with reading noise `std` [2] (world x m, y m; > 0)."""
    obj = get_object(obj) if isinstance(obj, str) else obj
    return PositionSensor(offset=jnp.asarray(obj.centroid, dtype), std=jnp.asarray(checked_position_std(std), dtype))


def checked_position_std(std: Sequence[float]) -> np.ndarray:
    """`std` [2] (world x m, y m) as an array, or a ValueError naming ``std`` unless both are finite and positive."""
    std = np.asarray(std, np.float64)
    if std.shape != (POSITION_SIZE,) or not np.all(np.isfinite(std) & (std > 0)):
        raise ValueError(f"std: expected {POSITION_SIZE} positive values (m), got {std.tolist()}")
    return std


def observe_position(sensor: PositionSensor, state):
    """[2] the world position of the sensor's point for the state [5] (its pose x m, y m, yaw rad)."""
    cos, sin = jnp.cos(state[2]), jnp.sin(state[2])
    offset = sensor.offset.astype(state.dtype)
    return state[:2] + jnp.stack([cos * offset[0] - sin * offset[1], sin * offset[0] + cos * offset[1]])


def gated_update_position(sensor: PositionSensor, mean, cov, position, gate=jnp.inf):
    """(mean [5], cov [5, 5], used []) after the Kalman update of a Gaussian belief (mean [5], cov [5, 5]) with a
    position reading [2] (world, m), the observation linearised at `mean` (the EKF's update; exact for a sensor whose
    point is the tracked frame's origin). The belief is unchanged (used False) where the reading is missing (any NaN)
    or its squared innovation in units of its predicted covariance exceeds `gate` (a chi-square bound with 2 degrees
    of freedom; infinite: no gate). Joseph form, symmetrised."""
    predicted = observe_position(sensor, mean)
    h = jax.jacfwd(observe_position, argnums=1)(sensor, mean)
    r = jnp.diag(sensor.std.astype(cov.dtype) ** 2)
    s = h @ cov @ h.T + r
    gain = jnp.linalg.solve(s, h @ cov).T
    present = jnp.all(jnp.isfinite(position))
    innovation = jnp.where(present, position, predicted) - predicted
    used = present & (innovation @ jnp.linalg.solve(s, innovation) <= gate)
    new_mean = mean + gain @ innovation
    factor = jnp.eye(STATE_SIZE, dtype=cov.dtype) - gain @ h
    new_cov = factor @ cov @ factor.T + gain @ r @ gain.T
    new_cov = 0.5 * (new_cov + new_cov.T)
    return jnp.where(used, new_mean, mean), jnp.where(used, new_cov, cov), used


def update_position(sensor: PositionSensor, mean, cov, position):
    """(mean [5], cov [5, 5]) after a position reading [2] (world, m): :func:`gated_update_position` without a gate;
    a missing reading (any NaN) leaves the belief unchanged."""
    return gated_update_position(sensor, mean, cov, position)[:2]


def update(system: System, mean, cov, measurement, sensor: PositionSensor | None = None, position=None):
    """The update with one step's observations: the pose `measurement` [3] (:func:`update_linear`), then, with a
    `sensor`, its `position` reading [2] (:func:`update_position`); NaN samples are skipped."""
    mean, cov = update_linear(system, mean, cov, measurement)
    if sensor is not None:
        mean, cov = update_position(sensor, mean, cov, position)
    return mean, cov


def gaussian_filter(predict, system: System, mean, cov, pusher_path, measurements,
                    sensor: PositionSensor | None = None, positions=None) -> Track:
    """A Gaussian filter over one push: the update (:func:`update`), then ``predict`` and the update at every step.

    Args:
      predict: ``(system, mean, cov, pusher [2], increment [2]) -> (mean, cov)``, the filter's process step (EKF,
        UKF).
      system, mean, cov, pusher_path, measurements, sensor, positions: as in :func:`pushjax.filter.ekf.filter_push`.
    """
    if (sensor is None) != (positions is None):
        raise ValueError("sensor, positions: expected both (a second, position stream) or neither")
    if positions is None:
        positions = jnp.zeros((measurements.shape[0], 0), measurements.dtype)  # scanned over, never read
    mean, cov = update(system, mean, cov, measurements[0], sensor, positions[0])

    def body(belief, inputs):
        pusher, increment, measurement, position = inputs
        belief = update(system, *predict(system, *belief, pusher, increment), measurement, sensor, position)
        return belief, belief

    _, (means, covs) = jax.lax.scan(body, (mean, cov), (pusher_path[:-1], jnp.diff(pusher_path, axis=0),
                                                        measurements[1:], positions[1:]))
    return Track(mean=jnp.concatenate([mean[None], means]), cov=jnp.concatenate([cov[None], covs]),
                 observed=jax.vmap(observed)(measurements))


def process_cov(system: System, dtype):
    """[5, 5] process noise covariance per step."""
    return jnp.diag(system.process_std.astype(dtype) ** 2)


def physical(system: System, mean, cov):
    """{"mu": [...], "mu_std_log": [...], "l": [...], "l_std_log": [...]}: the latents in physical units."""
    return {"mu": system.mu * jnp.exp(mean[..., 3]), "mu_std_log": jnp.sqrt(cov[..., 3, 3]),
            "l": system.l * jnp.exp(mean[..., 4]), "l_std_log": jnp.sqrt(cov[..., 4, 4])}
