"""The pusher–object friction read from the force sensor, so that the motion fit cannot use it as a knob.

While the pusher slides along the object, Coulomb friction holds the contact force on the edge of the friction cone:
``|F_t| / F_n = mu`` (Lynch's model and the exact limit surface assume the same). Sliding is read from the kinematics
alone — within :data:`SLIDE_LAG` the tip slips over the object (it moves, along the contact's tangent, by more than
the object carried the material point it touches) and the touched point moves along the outline, both by more than
:data:`MIN_SLIDE` and four standard deviations of the tracking noise, averaged over :data:`SLIDE_LAG` — and the force
from ``ft_wrench`` (the force the pusher applies to the object, world axes), so the estimate uses no model of the
object's motion. Either alone is not sliding: while the contact sticks and the object turns at ``omega``, the touched
point moves around the round tip at ``omega * radius`` without slip (on the testbed at 40 mm/s such samples, inside the
cone, read the coefficient up to 10 % low, issue 29); while the tip slips around a corner, the touched point stays at
the vertex, where the outline has no normal. A push's estimate is the
:data:`SLIDING_QUANTILE` percentile of the ratio over its sliding samples (samples that tracking noise makes look
sliding while the contact sticks lie inside the cone, below ``mu``); pushes that never slide (their force stays inside
the cone) or whose force sensor reads nothing have none and are counted.

A push's reading has a standard error, so that the spread of the readings over pushes can be told from their
measurement error (:mod:`pushjax.loop.variability`): the robust standard deviation of the ratio over the sliding samples
above their median, ``(p90 - p50) / 1.2816``, and at least :data:`MIN_RELATIVE_STD` of the reading. The samples of one
push share their error along it (the contact's place, the plate's dynamics), so the spread of one sample, not that of
their mean, bounds how far the reading is off: on realistic testbed pushes (rect1 on pu, 20 mm/s) the readings scatter
about the simulated coefficients by 0.24 % (equal coefficients) and 0.8 % (a spread of 0.4), the samples' spread is
1.2-1.5 %, the standard error of a mean of stretches of :data:`SLIDE_LAG` 0.14 %; on the ideal testbed (no tracking
noise) the readings of one coefficient scatter by 0.18 % while their samples' spread is 0.02 % (median), hence the floor.
A reading resting on less than :data:`SLIDE_LAG` of sliding has none: such readings were off by up to 0.67 (of 0.25) on
the realistic testbed.

With this measurement the motion fit has no reason left to move the pusher friction: the loop gives the model the
measured coefficient and drops ``pusher_friction`` from the candidates (:func:`pushjax.loop.pipeline.decide`). On clean
testbed pushes the sensor reads the simulated 0.250 while the motion fit of ``pusher_friction`` on top of the exact
limit surface asks for 0.28: that scale was a knob absorbing another misfit, not the pusher's friction.
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from pushjax import planar
from pushjax.geometry import PUSHER_RADIUS, ContactAnnotation, PushObject, annotate
from pushjax.mit.files import Push

SLIDE_LAG = 0.1
"""Time over which the tip's slip over the object is measured, s."""
MIN_SLIDE = 5e-4
"""Slip of the tip over the touched material point, and motion of that point along the outline, within
:data:`SLIDE_LAG` (m) above which the pusher slides."""
MIN_NORMAL_FORCE_SHARE = 0.1
"""Samples whose normal force is below this share of the push's largest carry too little force for a ratio."""
SLIDING_QUANTILE = 90
"""Percentile of a push's sliding samples' force ratios taken as its coefficient."""
MIN_SLIDING_SAMPLES = 5
"""A push needs this many sliding samples for an estimate."""
MIN_RELATIVE_STD = 0.005
"""Smallest standard error of a push's reading, relative to it: readings of one coefficient scatter by up to 0.24 % over
testbed pushes beyond their samples' spread (module docstring)."""
_NORMAL_QUANTILE = 1.2816
"""The standard normal's :data:`SLIDING_QUANTILE` percentile: its distance from the median in standard deviations."""
MIN_SEQUENCES = 8
"""Push sequences with an estimate needed before the measurement replaces the nominal coefficient."""


def sliding_friction(push: Push, obj: PushObject, noise: np.ndarray, touches: Touches | None = None
                     ) -> tuple[float, float]:
    """The pusher–object friction coefficient of one push from its sliding samples and its standard error.

    Args:
      push: a cleaned push (object and tip poses m, rad; wrench [T, 3] fx N, fy N, torque N·m, world axes).
      obj: the pushed object.
      noise: [3] standard deviation of the object pose's tracking noise (x m, y m, yaw rad).
      touches: ``touches_of(push, obj)`` when the caller has it (the costly part); None: computed here.

    Returns:
      (coefficient, standard error) (see the module docstring); (NaN, NaN) with fewer than
      :data:`MIN_SLIDING_SAMPLES` sliding samples, a NaN standard error with fewer than :data:`SLIDE_LAG` of them.
    """
    touches = touches or touches_of(push, obj)
    if touches is None:
        return math.nan, math.nan
    contact, touching, lag = touches
    pose, tip = push.object, push.tip[:, :2]
    normal = np.asarray(contact.normal)
    arm = np.asarray(contact.contact_rel_com)
    # Where the object carried the touched material point within the lag, the tip's slip over it along the contact's
    # tangent, and the touched point's motion along the outline, each averaged over the lag.
    material = planar.rotate(arm, -pose[:, 2])
    carried = pose[lag:, :2] + planar.rotate(material[:-lag], pose[lag:, 2]) - (pose[:-lag, :2] + arm[:-lag])
    slip = tip[lag:] - tip[:-lag] - carried
    along = _moving_average(_tangential(slip, normal[:-lag])[:, None], lag)[:, 0]
    local = _moving_average(material, lag)
    migration = np.linalg.norm(local[lag:] - local[:-lag], axis=1)
    # Tracking noise of the touched point (object position, and yaw times the lever arm; the tip's adds alike), on a
    # difference of two poses, averaged over the lag.
    lever = float(np.median(np.linalg.norm(arm[touching], axis=1))) if np.any(touching) else 0.0
    point_noise = math.sqrt(2.0) * math.hypot(float(np.hypot(noise[0], noise[1])), float(noise[2]) * lever)
    threshold = max(MIN_SLIDE, 4.0 * point_noise * math.sqrt(2.0 / lag))
    slide = np.zeros(len(pose), bool)
    same_side = np.sum(normal[lag:] * normal[:-lag], axis=1) > 0.99
    slide[:-lag] = (touching[:-lag] & touching[lag:] & same_side & (np.abs(along) > threshold)
                    & (migration > threshold))
    force = push.wrench[:, :2]
    normal_force = np.sum(force * normal, axis=1)
    tangential_force = np.abs(_tangential(force, normal))
    loaded = normal_force > MIN_NORMAL_FORCE_SHARE * max(float(np.max(normal_force, initial=0.0)), 1e-9)
    used = slide & loaded
    if np.count_nonzero(used) < MIN_SLIDING_SAMPLES:
        return math.nan, math.nan
    median, reading = np.percentile(tangential_force[used] / normal_force[used], [50, SLIDING_QUANTILE])
    std = max((reading - median) / _NORMAL_QUANTILE, MIN_RELATIVE_STD * reading) if np.count_nonzero(used) >= lag \
        else math.nan
    return float(reading), float(std)


def _lag(push: Push) -> int:
    """Samples in :data:`SLIDE_LAG` (0 for a push of one sample)."""
    dt = float(np.median(np.diff(push.time))) if len(push.time) > 1 else math.inf
    return max(1, round(SLIDE_LAG / dt)) if math.isfinite(dt) else 0


class Touches(NamedTuple):
    """Where the pusher touches the object at every sample of a push (:func:`touches_of`).

    Attributes:
      contact: the contact of every sample (:func:`pushjax.geometry.annotate`), annotated along the pusher's motion
        over the next ``lag`` samples (at rest: towards the object's centre).
      touching: [T] whether the pusher touches the outline.
      lag: samples in :data:`SLIDE_LAG`.
    """

    contact: ContactAnnotation
    touching: np.ndarray
    lag: int


def touches_of(push: Push, obj: PushObject) -> Touches | None:
    """The contact of every sample of ``push`` and whether the pusher touches there; None for a push no longer than
    :data:`SLIDE_LAG`."""
    lag = _lag(push)
    if lag == 0 or len(push.time) <= lag:
        return None
    tip, pose = push.tip[:, :2], push.object
    motion = np.concatenate([tip[lag:] - tip[:-lag], np.zeros((lag, 2))])
    towards = pose[:, :2] - tip
    direction = np.where(np.linalg.norm(motion, axis=1, keepdims=True) > 1e-6, motion, towards)
    contact = annotate(obj, pose, tip, direction * (0.01 / np.maximum(np.linalg.norm(direction, axis=1),
                                                                      1e-12))[:, None], radius=PUSHER_RADIUS)
    return Touches(contact, np.asarray(contact.touches) & (np.asarray(contact.first_contact_fraction) < 0.05), lag)


def window_wrenches(push: Push, obj: PushObject, starts: np.ndarray, ends: np.ndarray,
                    touches: Touches | None = None) -> np.ndarray:
    """The mean wrench the pusher applied to the object over each window.

    Args:
      push: a cleaned push (wrench [T, 3], the force in N in its first two columns, world axes).
      obj: the pushed object.
      starts, ends: [W] window start and end sample indices.
      touches: ``touches_of(push, obj)`` when the caller has it; None: computed here.

    Returns:
      [W, 3] force along the object's axes (N) and moment about the object's centre of mass (N·m), averaged over
      the window's samples at which the pusher touches and the force is loaded; NaN where there are none.
    """
    wrenches = np.full((len(starts), 3), np.nan)
    touches = touches or touches_of(push, obj)
    if touches is None:
        return wrenches
    contact, touching, _ = touches
    force = push.wrench[:, :2]
    arm = np.asarray(contact.contact_rel_com)
    moment = arm[:, 0] * force[:, 1] - arm[:, 1] * force[:, 0]
    magnitude = np.linalg.norm(force, axis=1)
    used = touching & (magnitude > MIN_NORMAL_FORCE_SHARE * max(float(np.max(magnitude, initial=0.0)), 1e-9))
    local = np.column_stack([planar.rotate(force, -push.object[:, 2]), moment])
    for k, (start, end) in enumerate(zip(starts, ends)):
        inside = used[start:end]
        if np.any(inside):
            wrenches[k] = local[start:end][inside].mean(axis=0)
    return wrenches


def _tangential(vectors: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """[T] the signed component of [T, 2] ``vectors`` along the tangent of the [T, 2] unit ``normal`` (turned -90°)."""
    return vectors[:, 0] * normal[:, 1] - vectors[:, 1] * normal[:, 0]


def _moving_average(values: np.ndarray, width: int) -> np.ndarray:
    """[T, D] centred moving average over ``width`` samples (shorter at the ends)."""
    kernel = np.ones(width)
    counts = np.convolve(np.ones(len(values)), kernel, mode="same")
    return np.column_stack([np.convolve(column, kernel, mode="same") for column in values.T]) / counts[:, None]


@dataclasses.dataclass(frozen=True)
class ForceFriction:
    """The pusher–object friction of a set of windows' pushes.

    Attributes:
      value: mean over push sequences of their pushes' mean estimate (None without any).
      std: its standard error over sequences (None with fewer than two).
      n_sequences: sequences with an estimate.
      n_pushes: pushes with an estimate.
      n_pushes_without: pushes without one (they never slid, or their sensor read no force).
    """

    value: float | None
    std: float | None
    n_sequences: int
    n_pushes: int
    n_pushes_without: int

    @property
    def measured(self) -> bool:
        """Whether enough sequences slid for the measurement to replace the nominal coefficient."""
        return self.value is not None and self.n_sequences >= MIN_SEQUENCES

    def as_dict(self) -> dict:
        return {**dataclasses.asdict(self), "measured": self.measured}


def estimate(push_friction: np.ndarray, push: np.ndarray, sequence: np.ndarray) -> ForceFriction:
    """Pools per-push estimates by sequence.

    Args:
      push_friction: [N] the estimate of each window's push (NaN: none), e.g. ``Examples.push_friction``.
      push: [N] push index of each window.
      sequence: [N] sequence index of each window.
    """
    _, first = np.unique(push, return_index=True)
    values, sequences = push_friction[first], sequence[first]
    known = np.isfinite(values)
    per_sequence = np.array([np.mean(values[known & (sequences == s)]) for s in np.unique(sequences[known])])
    n = len(per_sequence)
    return ForceFriction(
        value=float(np.mean(per_sequence)) if n else None,
        std=float(np.std(per_sequence, ddof=1) / math.sqrt(n)) if n > 1 else None,
        n_sequences=n, n_pushes=int(np.count_nonzero(known)), n_pushes_without=int(np.count_nonzero(~known)))

