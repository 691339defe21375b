"""The closed loop's prediction windows of measured pushes: horizon windows, contact annotation, split by push.

Only what real MIT files hold is used: the three streams (resampled by :mod:`pushjax.mit.files`)
and the file-name fields; file attributes (e.g. declared simulation effects) are never read.

A window starts at ``t0`` while the pusher moves (every ``stride`` s from its first motion) and ends
at ``t0 + horizon``, within the recording. Its model inputs are the contact annotation of the pusher
displacement over the window against the object pose at ``t0`` (:func:`pushjax.geometry.annotate`;
where the pusher stops short of the object, the contact it would make within :data:`LOOKAHEAD` further,
with ``s = 0`` and no action), the pusher's speed and stop, the nominal limit-surface ratio of the
object (uniform pressure), its footprint as support cells and its hull's corners as feet
(:func:`pushjax.geometry.support`, for the exact limit surface) and a nominal pusher friction; its
target is the displacement of the object's nominal centre of mass (the uniform plate's centroid in the
tracked frame) and the change of yaw over the window.
"""

from __future__ import annotations

import collections
import dataclasses
import math
from collections.abc import Iterable

import jax
import numpy as np

from pushjax import planar
from pushjax.geometry import (
    OBJECT_NAMES,
    PUSHER_RADIUS,
    annotate,
    get_object,
    limit_surface_ratio,
    support,
)
from pushjax.loop.force import sliding_friction, touches_of, window_wrenches
from pushjax.mit.files import Push
from pushjax.physics.effects import PushInputs

NOMINAL_PUSHER_FRICTION = 0.25
"""Steel tip on steel plate, the value commonly used with the MIT data for the quasi-static model."""
SPEED_WINDOW = 0.02
"""Time over which the pusher's speed is measured, s."""
LOOKAHEAD = 0.03
"""How far beyond a window's pusher motion (m) a contact is still annotated, as one the pusher would make."""
MIN_MOVING_SPEED = 0.002
"""Pusher speeds below this (m/s), or below half the push's typical speed, count as stopped."""

NUMERIC, CATEGORICAL = "numeric", "categorical"
VARIABLES = {
    "push velocity": NUMERIC,
    "push angle": NUMERIC,
    "contact position along the side": NUMERIC,
    "object orientation in the world": NUMERIC,
    "object": CATEGORICAL,
    "surface": CATEGORICAL,
    "time in the push": NUMERIC,
    "contact versus no contact": CATEGORICAL,
    "pushed side": CATEGORICAL,
    "push direction in the world": NUMERIC,
}
"""Candidate explanatory variables of the residual and their kinds. Units: mm/s, deg, fraction of the
side, deg, -, -, s, -, side index, deg."""


@dataclasses.dataclass(frozen=True, eq=False)
class Examples:
    """Prediction windows, all arrays with the leading axis N (NumPy, float64 unless stated).

    Attributes:
      inputs: the model inputs (:class:`pushjax.physics.effects.PushInputs` of [N, ...] arrays).
      target: [N, 3] measured displacement of the nominal centre of mass (world, m) and yaw change (rad).
      sequence: [N] int, index of the push sequence (repetitions of one push share it).
      push: [N] int, index of the push (file) in reading order.
      window: [N] int, index of the window in its push (the same index in repetitions of a push starts at the same
        time after the pusher's first motion).
      tracking_noise: [N, 3] standard deviation of the pose measurement of the window's push (x m, y m, yaw rad),
        estimated from the pose stream (:func:`tracking_noise`).
      push_friction: [N] the pusher–object friction coefficient that the force sensor read while the window's push
        slid (:func:`pushjax.loop.force.sliding_friction`; NaN where it never slid or read no force).
      push_friction_std: [N] that reading's standard error (NaN where the push slid too briefly for one).
      wrench: [N, 3] the mean wrench the pusher applied over the window: force along the object's axes (N) and moment
        about its centre of mass (N·m) (:func:`pushjax.loop.force.window_wrenches`; NaN where it never touched).
      variables: {name: [N] values} of the candidate explanatory variables (see :data:`VARIABLES`).
      sequence_names: names of the sequences, indexed by ``sequence``.
    """

    inputs: PushInputs
    target: np.ndarray
    sequence: np.ndarray
    push: np.ndarray
    window: np.ndarray
    tracking_noise: np.ndarray
    push_friction: np.ndarray
    push_friction_std: np.ndarray
    wrench: np.ndarray
    variables: dict[str, np.ndarray]
    sequence_names: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.target)

    @property
    def n_sequences(self) -> int:
        return len(np.unique(self.sequence))

    @property
    def n_pushes(self) -> int:
        return len(np.unique(self.push))

    def select(self, mask: np.ndarray) -> Examples:
        """The examples where ``mask`` [N] (bool or indices) selects; sequence indices are kept."""
        return Examples(
            inputs=jax.tree.map(lambda values: np.asarray(values)[mask], self.inputs),
            target=self.target[mask], sequence=self.sequence[mask], push=self.push[mask], window=self.window[mask],
            tracking_noise=self.tracking_noise[mask], push_friction=self.push_friction[mask],
            push_friction_std=self.push_friction_std[mask], wrench=self.wrench[mask],
            variables={name: values[mask] for name, values in self.variables.items()}, sequence_names=self.sequence_names,
        )


@dataclasses.dataclass(frozen=True)
class BuildSummary:
    """Pushes used and skipped while building examples.

    Attributes:
      n_pushes: pushes that gave at least one window.
      skipped: {reason: [push file names]} of pushes that gave none.
    """

    n_pushes: int
    skipped: dict[str, list[str]]

    @property
    def n_skipped(self) -> int:
        return sum(len(names) for names in self.skipped.values())


def _sequence_key(push: Push) -> str:
    """The push sequence of `push`: its file-name fields bar the repetition (the MIT protocol repeats a straight
    push from one start pose at one velocity), and, for a file in a folder of its own below its object's folder
    (``<surface>/<object>/<sequence>/...h5``), that folder: a push whose pusher path is not the protocol's, e.g. one
    controller episode (``pushjax.studies.adapt``), is a sequence of its own whatever its file-name fields."""
    params = dataclasses.replace(push.params, repetition=None)
    folder = "" if push.path.parent.name == params.shape else f"{push.path.parent.name}/"
    return (f"{params.surface}/{params.shape}/{folder}a={params.acceleration:g}/v={params.velocity:g}/i={params.side}"
            f"/s={params.point:.3f}/t={params.angle:.3f}")


def _pusher_speeds(push: Push, frequency: float) -> tuple[np.ndarray, np.ndarray]:
    """[T] pusher speeds in m/s: instantaneous (central differences) and over the preceding SPEED_WINDOW."""
    xy = push.tip[:, :2]
    instantaneous = np.linalg.norm(np.gradient(xy, axis=0), axis=1) * frequency
    lag = min(max(1, round(SPEED_WINDOW * frequency)), len(xy) - 1)
    trailing = np.empty(len(xy))
    trailing[lag:] = np.linalg.norm(xy[lag:] - xy[:-lag], axis=1) * frequency / lag
    trailing[:lag] = trailing[lag]
    return instantaneous, trailing


def tracking_noise(pose: np.ndarray) -> np.ndarray:
    """[3] standard deviation of white measurement noise on a [T, 3] pose stream (x m, y m, yaw rad).

    The second difference of a smoothly moving pose is far below the noise at the MIT data's 250 Hz, and that of
    white noise of variance s^2 has variance 6 s^2; its median absolute deviation (robust to the pusher's start and
    stop) gives s.
    """
    second = np.diff(np.asarray(pose, np.float64), n=2, axis=0)
    if len(second) == 0:
        return np.zeros(3)
    return 1.4826 * np.median(np.abs(second - np.median(second, axis=0)), axis=0) / math.sqrt(6.0)


def _windows(push: Push, horizon: float, stride: float):
    """Window start and end indices, the index where the pusher stops and the pusher speed [T] (m/s) at
    each index; None when the push has no window."""
    frequency = 1.0 / (push.time[1] - push.time[0])
    instantaneous, trailing = _pusher_speeds(push, frequency)
    threshold = max(MIN_MOVING_SPEED, 0.5 * np.percentile(instantaneous, 90))
    moving = np.flatnonzero(instantaneous > threshold)
    if len(moving) == 0:
        return None
    first, stop = moving[0], moving[-1]
    length = round(horizon * frequency)
    starts = np.arange(first, stop, max(1, round(stride * frequency)))
    starts = starts[starts + length < len(push.time)]
    if len(starts) == 0:
        return None
    return starts, starts + length, stop, trailing


def build_examples(
    pushes: Iterable[Push],
    horizon: float = 0.5,
    stride: float | None = None,
    pusher_friction: float = NOMINAL_PUSHER_FRICTION,
) -> tuple[Examples, BuildSummary]:
    """Windows of every push, annotated for the pushing model.

    Args:
      pushes: cleaned pushes (e.g. :func:`pushjax.mit.files.iter_pushes`), each with file-name
        parameters.
      horizon: window length, s (> 0).
      stride: time between window starts, s; default ``horizon / 2``.
      pusher_friction: nominal pusher-object friction coefficient given to the model.

    Returns:
      (examples, summary). Pushes of unknown objects, without parsed parameters or too short for one
      window are skipped and counted in the summary.

    Raises:
      ValueError: a non-positive horizon or stride, or no push gave any window.
    """
    if not (math.isfinite(horizon) and horizon > 0):
        raise ValueError(f"horizon: expected a positive duration in s, got {horizon!r}")
    stride = horizon / 2 if stride is None else stride
    if not (math.isfinite(stride) and stride > 0):
        raise ValueError(f"stride: expected a positive duration in s, got {stride!r}")
    skipped = collections.defaultdict(list)
    rows = collections.defaultdict(list)  # object name -> per-push dicts
    sequence_index: dict[str, int] = {}
    n_pushes = 0
    for push in pushes:
        if push.params is None:
            skipped["no file-name parameters"].append(push.path.name)
            continue
        if push.params.shape not in OBJECT_NAMES:
            skipped["unknown object"].append(push.path.name)
            continue
        windows = _windows(push, horizon, stride)
        if windows is None:
            skipped["too short for one window"].append(push.path.name)
            continue
        starts, ends, stop, speed = windows
        n_pushes += 1
        sequence = sequence_index.setdefault(_sequence_key(push), len(sequence_index))
        stop_time = push.time[stop]
        noise = tracking_noise(push.object)
        speed_until = np.minimum(ends, stop)
        obj = get_object(push.params.shape)
        touches = touches_of(push, obj)
        friction, friction_std = sliding_friction(push, obj, noise, touches)
        rows[push.params.shape].append(dict(
            pose0=push.object[starts], pose1=push.object[ends], tip0=push.tip[starts, :2],
            motion=push.tip[ends, :2] - push.tip[starts, :2],
            push_speed=speed[speed_until],
            time_after_stop=np.maximum(push.time[ends] - stop_time, 0.0),
            time=push.time[starts],
            sequence=np.full(len(starts), sequence),
            push=np.full(len(starts), n_pushes - 1),
            window=np.arange(len(starts)),
            tracking_noise=np.broadcast_to(noise, (len(starts), 3)),
            push_friction=np.full(len(starts), friction),
            push_friction_std=np.full(len(starts), friction_std),
            wrench=window_wrenches(push, obj, starts, ends, touches),
            params=push.params,
        ))
    if n_pushes == 0:
        reasons = ", ".join(f"{reason}: {len(names)}" for reason, names in skipped.items()) or "no pushes"
        raise ValueError(f"pushes: none gave a prediction window of {horizon} s ({reasons})")

    examples = _merge([_annotate_object(name, object_rows, pusher_friction)
                       for name, object_rows in sorted(rows.items())], tuple(sequence_index))
    return examples, BuildSummary(n_pushes=n_pushes, skipped=dict(skipped))


def _merge(parts: list[dict], sequence_names: tuple[str, ...]) -> Examples:
    """The examples of every object's annotated windows in one set."""
    # Objects' supports have different numbers of points: padded with zero-weight points to the largest.
    cells = max(part["support_points"].shape[1] for part in parts)
    for part in parts:
        padding = cells - part["support_points"].shape[1]
        part["support_points"] = np.pad(part["support_points"], ((0, 0), (0, padding), (0, 0)))
        part["support_weights"] = np.pad(part["support_weights"], ((0, 0), (0, padding)))
        part["support_feet"] = np.pad(part["support_feet"], ((0, 0), (0, padding)))
    merged = {key: np.concatenate([part[key] for part in parts]) for key in parts[0] if key != "variables"}
    variables = {name: np.concatenate([part["variables"][name] for part in parts]) for name in VARIABLES}
    inputs = PushInputs(**{field.name: merged[field.name] for field in dataclasses.fields(PushInputs)})
    return Examples(inputs=inputs, target=merged["target"], sequence=merged["sequence"], push=merged["push"],
                    window=merged["window"], tracking_noise=merged["tracking_noise"],
                    push_friction=merged["push_friction"], push_friction_std=merged["push_friction_std"],
                    wrench=merged["wrench"], variables=variables, sequence_names=sequence_names)


def _annotate_object(name: str, rows: list[dict], pusher_friction: float) -> dict:
    obj = get_object(name)
    data = {key: np.concatenate([row[key] for row in rows]) for key in rows[0] if key != "params"}
    params = [row["params"] for row in rows for _ in range(len(row["sequence"]))]
    pose0, pose1, tip0, motion = data["pose0"], data["pose1"], data["tip0"], data["motion"]
    contact = annotate(obj, pose0, tip0, motion, radius=PUSHER_RADIUS)
    touches = np.asarray(contact.touches)
    contact_world = np.asarray(contact.contact_world).copy()
    contact_rel_com = np.asarray(contact.contact_rel_com).copy()
    normal = np.asarray(contact.normal).copy()
    # Where the pusher stops short of the object, the contact it would make further on (within
    # LOOKAHEAD): no push, but an outline that is really closer than annotated (frame_offset) is reached.
    length = np.linalg.norm(motion, axis=1)
    short = np.flatnonzero(~touches & (length > 0))
    if len(short):
        extended = motion[short] * (1 + LOOKAHEAD / length[short])[:, None]
        ahead = annotate(obj, pose0[short], tip0[short], extended, radius=PUSHER_RADIUS)
        found = short[np.asarray(ahead.touches)]
        for array, values in ((contact_world, ahead.contact_world), (contact_rel_com, ahead.contact_rel_com),
                              (normal, ahead.normal)):
            array[found] = np.asarray(values)[np.asarray(ahead.touches)]
    annotated = np.any(normal != 0, axis=1)
    gap = np.where(annotated, np.sum((contact_world - tip0) * normal, axis=1) - PUSHER_RADIUS, 0.0)
    com0, com1 = planar.centre_of_mass(obj.centroid, pose0), planar.centre_of_mass(obj.centroid, pose1)
    count = len(pose0)
    support_points, support_weights, support_feet_loads, patch_radius = support(obj)
    yaw = pose0[:, 2]
    variables = {
        "push velocity": np.array([p.velocity for p in params]),
        "push angle": np.degrees([p.angle for p in params]),
        "contact position along the side": np.array([p.point for p in params]),
        "object orientation in the world": np.degrees(np.angle(np.exp(1j * yaw))),
        "object": np.full(count, name),
        "surface": np.array([p.surface for p in params]),
        "time in the push": data["time"],
        "contact versus no contact": np.where(touches, "contact", "no contact"),
        "pushed side": np.array([str(p.side) for p in params]),
        "push direction in the world": np.degrees(np.arctan2(motion[:, 1], motion[:, 0])),
    }
    return dict(
        contact=contact_rel_com, normal=normal,
        action=np.asarray(contact.action_from_contact), pusher_motion=motion, gap=gap,
        l=np.full(count, limit_surface_ratio(obj)), mu=np.full(count, float(pusher_friction)),
        s=touches.astype(np.float64), object_yaw=yaw, push_speed=data["push_speed"],
        time_after_stop=data["time_after_stop"], object_position=com0,
        support_points=np.broadcast_to(support_points, (count, *support_points.shape)),
        support_weights=np.broadcast_to(support_weights, (count, len(support_weights))),
        patch_radius=np.full(count, patch_radius),
        support_feet=np.broadcast_to(support_feet_loads, (count, len(support_feet_loads))),
        target=np.column_stack([com1 - com0, pose1[:, 2] - pose0[:, 2]]),
        sequence=data["sequence"], push=data["push"], window=data["window"], tracking_noise=data["tracking_noise"],
        push_friction=data["push_friction"], push_friction_std=data["push_friction_std"], wrench=data["wrench"],
        variables=variables,
    )


def split_by_sequence(examples: Examples, heldout_fraction: float = 0.3, seed: int = 0) -> tuple[Examples, Examples]:
    """(fit, held-out) examples, whole push sequences on either side, drawn with ``seed``.

    Raises:
      ValueError: ``heldout_fraction`` outside (0, 1) or fewer than 2 sequences.
    """
    if not 0 < heldout_fraction < 1:
        raise ValueError(f"heldout_fraction: expected a fraction in (0, 1), got {heldout_fraction!r}")
    sequences = np.unique(examples.sequence)
    if len(sequences) < 2:
        raise ValueError(f"examples: need at least 2 push sequences to split, got {len(sequences)}")
    n_heldout = min(len(sequences) - 1, max(1, round(heldout_fraction * len(sequences))))
    heldout = np.random.default_rng(seed).permutation(sequences)[:n_heldout]
    is_heldout = np.isin(examples.sequence, heldout)
    return examples.select(~is_heldout), examples.select(is_heldout)
