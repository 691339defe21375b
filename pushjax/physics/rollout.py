"""Rollouts of the analytical pushing model along a pusher path, as pure JAX.

A push of several centimetres is the sum of many small steps: at every step the contact is annotated
again on the object's outline where the object now is (:func:`pushjax.geometry.outline_jax.first_contact`:
which feature the disc pusher touches, where, the inward normal, and how far the pusher travels before it
touches, so the contact is lost and regained as the path says; the scan carries the touched feature, and each step
searches a few edges around it, the whole outline only where that cannot prove its choice, so a step costs O(1)
in the outline's vertices), and the step's object motion comes from
the pushing model :func:`pushjax.physics.effects.compose` of any effects (none: plain Lynch). The loop is a
``jax.lax.scan``, so :func:`rollout` is pure and jit-, vmap- and grad-friendly:

    shape = outline_jax.outline("rect1")  # padded to 256 vertices: one program for every object
    poses = rollout(shape, pose, pusher_path, l, mu).poses                   # [T + 1, 3]
    jax.grad(lambda mu: rollout(shape, pose, pusher_path, l, mu).poses[-1, 2])(mu)
    jax.vmap(rollout, in_axes=(None, 0, 0, 0, 0))(shape, poses, paths, ls, mus)  # many pushes

Gradients with respect to the pusher path, ``l``, ``mu`` and the effects' parameters are finite everywhere
(every branch is a double ``where``); they are the exact derivatives of the computed rollout wherever no
step changes its contact feature, its stick/slip mode or whether it touches, and one-sided derivatives
where one does.

Each step is quasi-static with the pusher moving, so the corrections for the slide after the pusher stops
(``inertia``, ``friction_speed``) act only in the last step, with the pusher speed ``|last increment| /
step_time`` and ``time_after_stop``. ``frame_offset`` sees the step's gap to the outline (a contact just
beyond the step can be brought into it); ``friction_field`` the object's position; ``anisotropic_friction``
and ``pressure_gradient`` its yaw. ``limit_surface`` (the exact limit surface in place of Lynch's ellipsoid) needs
the object's support, :func:`object_support`, passed as ``support``:

    rollout(shape, pose, pusher_path, l, mu, params, effects=("limit_surface",), support=object_support("rect1"))

:func:`straight_push` is the former NumPy entry point (one object, a straight push of equal increments,
NumPy in and out), now a thin wrapper around :func:`rollout`.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from pushjax.geometry import outline_jax
from pushjax.geometry.objects import PUSHER_RADIUS, PushObject, get_object, limit_surface_ratio, support
from pushjax.physics import effects as effects_lib

__all__ = ["Rollout", "StepInfo", "Support", "object_support", "rollout", "step", "straight_push"]


class StepInfo(NamedTuple):
    """What one step saw, batch shape ``[...]`` per step (world axes).

    Attributes:
      touches: [] bool, whether the pusher touched the object during the step.
      fraction: [] fraction of the step's pusher increment made before the touch (1: no touch).
      contact: [2] contact point relative to the centre of mass (world axes), m.
      normal: [2] unit inward normal (world axes), zeros when the pusher cannot reach the object.
      twist: [3] predicted motion of the centre of mass (dx m, dy m, dtheta rad).
    """

    touches: jax.Array
    fraction: jax.Array
    contact: jax.Array
    normal: jax.Array
    twist: jax.Array


class Rollout(NamedTuple):
    """A rollout: ``poses`` [T + 1, 3] tracked-frame poses (x m, y m, yaw rad), the first the start pose, and
    ``steps`` (:class:`StepInfo` with a leading [T] axis)."""

    poses: jax.Array
    steps: StepInfo


class Support(NamedTuple):
    """An object's support for the exact limit surface (:func:`pushjax.geometry.support`), object axes relative to
    the uniform plate's centre of mass.

    Attributes:
      points: [K, 2] support points, m.
      weights: [K] their area weights (zero for the hull's corners).
      feet: [K] the loads on the hull's corners (zero for the cells).
      patch_radius: [] radius of a support's patch, m.
    """

    points: jax.Array
    weights: jax.Array
    feet: jax.Array
    patch_radius: jax.Array


def object_support(obj: PushObject | str, dtype=jnp.float32) -> Support:
    """The :class:`Support` of `obj` (or its name)."""
    obj = get_object(obj) if isinstance(obj, str) else obj
    points, weights, feet, patch_radius = support(obj)
    return Support(*(jnp.asarray(value, dtype) for value in (points, weights, feet, patch_radius)))


def _rotate(vector, yaw):
    cos, sin = jnp.cos(yaw), jnp.sin(yaw)
    return jnp.stack([cos * vector[..., 0] - sin * vector[..., 1], sin * vector[..., 0] + cos * vector[..., 1]],
                     axis=-1)


def _safe_norm(vector):
    squared = jnp.sum(vector * vector, axis=-1)
    positive = squared > 0
    return jnp.where(positive, jnp.sqrt(jnp.where(positive, squared, 1.0)), 0.0)


def step(predict, params, shape: outline_jax.Outline, pose, pusher, increment, l, mu,
         radius=PUSHER_RADIUS, step_time=1.0, time_after_stop=0.0,
         support: Support | None = None, *, feature=None, search: str = "local") -> tuple[jax.Array, StepInfo]:
    """One step of a rollout: annotate the contact where the object is, predict, move the object.

    Args:
      predict: the pushing model, ``effects.compose(names)``.
      params: its parameters, {effect: {name: array}} (``{}`` for plain Lynch).
      shape: the object's :class:`~pushjax.geometry.outline_jax.Outline`.
      pose: [3] tracked-frame pose (x m, y m, yaw rad).
      pusher: [2] pusher centre at the step's start, world, m.
      increment: [2] pusher displacement over the step, world, m.
      l: [] limit-surface ratio, m (> 0).
      mu: [] pusher-object friction coefficient (>= 0).
      radius: [] pusher radius, m.
      step_time: [] duration of the step, s (only for the pusher speed of a slide after a stop).
      time_after_stop: [] time from the pusher's stop at the step's end to the end of the window, s.
      support: the object's :class:`Support` (needed by ``limit_surface``; None: unknown).
      feature: [] int, the outline's edge to search the contact around (None: a guess from the pusher's bearing);
        changes no result (:func:`pushjax.geometry.outline_jax.first_contact`).
      search: the contact search, "local" or "full" (:func:`pushjax.geometry.outline_jax.first_contact`).

    Returns:
      ([3] the pose after the step, the step's :class:`StepInfo`).
    """
    new_pose, info, _ = _step(predict, params, shape, pose, pusher, increment, l, mu, radius, step_time,
                              time_after_stop, support, feature, search)
    return new_pose, info


def _step(predict, params, shape, pose, pusher, increment, l, mu, radius, step_time, time_after_stop, support,
          feature, search):
    """:func:`step`, and the edge to search the next step's contact around."""
    pose = jnp.asarray(pose)
    yaw = pose[2]
    local = outline_jax.first_contact(shape, _rotate(pusher - pose[:2], -yaw), _rotate(increment, -yaw), radius,
                                      feature, search)
    com = pose[:2] + _rotate(shape.centroid, yaw)
    touches = local.touches
    contact = _rotate(local.point - shape.centroid, yaw)
    normal = _rotate(local.normal, yaw)
    action = jnp.where(touches, 1.0 - local.fraction, 0.0) * increment
    inputs = effects_lib.PushInputs.create(
        contact=contact, normal=normal, action=action, l=l, mu=mu, s=touches.astype(pose.dtype),
        pusher_motion=increment, gap=local.gap, object_yaw=yaw,
        push_speed=_safe_norm(increment) / step_time, time_after_stop=time_after_stop, object_position=com,
        **({} if support is None else {"support_points": support.points, "support_weights": support.weights,
                                       "support_feet": support.feet, "patch_radius": support.patch_radius}))
    twist = predict(params, inputs)
    new_yaw = yaw + twist[2]
    new_com = com + twist[:2]
    new_pose = jnp.concatenate([new_com - _rotate(shape.centroid, new_yaw), new_yaw[None]])
    return new_pose, StepInfo(touches=touches, fraction=local.fraction, contact=contact, normal=normal,
                              twist=twist), local.feature


@functools.partial(jax.jit, static_argnames=("effects", "search"))
def rollout(shape: outline_jax.Outline, object_pose, pusher_path, l, mu, params=None, *,
            effects: Sequence[str] = (), radius=PUSHER_RADIUS, step_time=1.0, time_after_stop=0.0,
            support: Support | None = None, search: str = "local") -> Rollout:
    """Object poses along a pusher path predicted by the pushing model, one step per path segment.

    Args:
      shape: the object's :class:`~pushjax.geometry.outline_jax.Outline` (``outline_jax.outline(obj)``).
      object_pose: [3] start pose of the tracked frame (x m, y m, yaw rad).
      pusher_path: [T + 1, 2] pusher centre positions, world, m; step k moves the pusher from
        ``pusher_path[k]`` to ``pusher_path[k + 1]``.
      l: [] limit-surface ratio, m (> 0).
      mu: [] pusher-object friction coefficient (>= 0).
      params: {effect: {name: array}} of the composed effects; None for their "no effect" values.
      effects: names of the composed effects (static; a tuple), see :data:`pushjax.physics.effects.EFFECTS`.
      radius: [] pusher radius, m.
      step_time: [] duration of one step, s (the pusher speed of the slide after the stop).
      time_after_stop: [] time from the pusher's stop (the path's end) to the end of the rollout, s.
      support: the object's :class:`Support` (:func:`object_support`); needed by ``limit_surface``.
      search: the contact search (static): "local" (each step searches around the previous step's contact
        feature, the full search only where that cannot prove its choice) or "full" (every feature every step,
        the former search); the same results.

    Returns:
      The :class:`Rollout`: poses [T + 1, 3] and the steps' :class:`StepInfo` [T, ...].
    """
    effects = tuple(effects)
    predict = effects_lib.compose(effects)
    if support is None and effects_lib.needs_support(effects):
        raise ValueError(f"support: effects {effects} include the exact limit surface, which needs the object's "
                         "support (rollout.object_support(obj))")
    params = effects_lib.init_params(effects) if params is None else params
    pusher_path = jnp.asarray(pusher_path)
    if pusher_path.ndim != 2 or pusher_path.shape[-1] != 2 or pusher_path.shape[0] < 2:
        raise ValueError(f"pusher_path: expected shape [T + 1, 2] with T >= 1, got {pusher_path.shape}")
    dtype = jnp.result_type(pusher_path, object_pose, l, mu, float)
    pose = jnp.asarray(object_pose, dtype)
    if pose.shape != (3,):
        raise ValueError(f"object_pose: expected shape [3] (vmap for batches), got {pose.shape}")
    starts, increments = pusher_path[:-1], jnp.diff(pusher_path, axis=0)
    stop_times = jnp.zeros(len(increments), dtype).at[-1].set(time_after_stop)

    # The contact feature is carried from step to step: each step searches around the previous one's.
    first_feature = outline_jax.initial_feature(shape, _rotate(pusher_path[0] - pose[:2], -pose[2]))

    def body(carry, inputs):
        pose, feature = carry
        pusher, increment, stop_time = inputs
        new_pose, info, feature = _step(predict, params, shape, pose, pusher, increment, l, mu, radius, step_time,
                                        stop_time, support, feature, search)
        return (new_pose, feature), (new_pose, info)

    _, (poses, infos) = jax.lax.scan(body, (pose, first_feature), (starts, increments, stop_times))
    return Rollout(poses=jnp.concatenate([pose[None], poses]), steps=infos)


def straight_push(obj: PushObject | str, object_pose, pusher_start, action, mu: float, steps: int = 100,
                  l: float | None = None, pusher_radius: float = PUSHER_RADIUS) -> np.ndarray:
    """Object poses along a straight push of equal increments (NumPy in and out, float32 unless x64 is on).

    Args:
      obj: the pushed object or its name.
      object_pose: [3] start pose of the tracked frame (x m, y m, yaw rad).
      pusher_start: [2] pusher centre at the start, m (world).
      action: [2] total pusher displacement, m (world).
      mu: pusher-object friction coefficient.
      steps: number of equal pusher increments.
      l: limit-surface ratio in m (uniform pressure when omitted).
      pusher_radius: m.

    Returns:
      [steps + 1, 3] tracked-frame poses (x m, y m, yaw rad), the first being ``object_pose``.
    """
    if steps < 1:
        raise ValueError(f"steps: expected a positive integer, got {steps}")
    obj = get_object(obj) if isinstance(obj, str) else obj
    l = limit_surface_ratio(obj) if l is None else l
    dtype = jnp.zeros(()).dtype  # float32, or float64 under jax.enable_x64
    fractions = np.linspace(0.0, 1.0, steps + 1)[:, None]
    path = np.asarray(pusher_start, np.float64) + fractions * np.asarray(action, np.float64)
    result = rollout(outline_jax.outline(obj, dtype), jnp.asarray(object_pose, dtype), jnp.asarray(path, dtype),
                     jnp.asarray(l, dtype), jnp.asarray(mu, dtype), radius=pusher_radius)
    return np.asarray(result.poses, np.float64)
