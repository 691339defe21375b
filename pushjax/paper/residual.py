"""How much of the physics baseline's error any model could learn: its error on a test split, decomposed (issue 50).

Table 1's ``physics`` baseline (`pushjax.paper.baselines`: Lynch's quasi-static model on the annotated state, the
nominal pusher friction ``mu`` and the uniform-pressure limit-surface ratio ``l``) is scored against labels cut
from the motion capture. Its error has three sources, which `decompose` tells apart by giving the model, one step
at a time, what the testbed (`pushjax.sim.testbed`) knows and the examples do not, on the same examples (windows,
scene transforms, pusher paths):

(a) **Tracking noise**. The realistic profile records the object through a motion capture
    (`pushjax.sim.testbed.PushConditions.track`): Gaussian pose noise, time-stamp jitter and dropped samples, drawn
    from the push's own generator (``[*push_key, 4]``) after the simulation, so it changes no other draw. Every
    test push is simulated again from its recording job (`pushjax.sim.dataset.PushJob`, the same conditions of
    `pushjax.sim.dataset.job_conditions`), and the recording must equal the stored file bit for bit (tip pose,
    tracked object pose, wrench; else `ReproductionError`): then the simulator's ``true_object_pose`` is the truth
    behind that file. The noise-free labels are the true poses read on the cleaned push's own clock
    (`pushjax.mit.files.clean_push` resamples the jittered stream onto ``t0 + k / 250 Hz``; the truth is
    interpolated at the same instants), moved by each example's stored scene transform; the noise-free state is the
    contact annotated (`pushjax.geometry.annotate`) on the true window-start pose with the stored pusher and action.
    Examples whose pusher was moved off the object keep zero motion and no contact.
(b) **Push-to-push randomness**. The realistic profile draws per push the pusher–object friction (the files'
    ``pushjax_testbed_draw``), per object the plate's uneven support load and per surface the table's uneven load
    and the friction field over the table (`pushjax.sim.testbed.draw_conditions`). Lynch is told, in turn, the
    push's own ``mu``, then ``l`` and the centre of friction of the plate's own load (per object, fixed in the
    plate), then of the whole drawn load where the plate is (table unevenness and friction field added, the load
    averaged over the window's true poses). A load's ``l`` and centre are measured on the simulator's support points
    relative to those of their area weights alone (so a uniform load gives the nominal model exactly), and Lynch is
    applied about the centre of friction (contact taken relative to it, its twist carried to the centre of mass).
(c) **What is left**: the structural misfit of the quasi-static ellipsoidal model to the MuJoCo plate (dynamics,
    the plate sliding on after the pusher stops, the load shifting as it slides, the speed-dependent coefficient).
    Two further rows show how much of it a better quasi-static model explains: the exact limit surface
    (`pushjax.physics.limit_surface`) of the drawn load on the simulator's point supports, then of the supports'
    measured friction capacity (normal force times coefficient, read from the simulation at every 4 ms sample and
    averaged over the window: the dynamic load transfer and the speed term included).

Every row's error is in % of the ``zero`` baseline's on the motion-capture labels (Table 1's denominator), with a
bootstrap over push sequences (`pushjax.paper.statistics`, the same resamples for every row, so the differences
between consecutive rows are paired). Reference rows: ``zero`` on the noise-free labels; ``truth``, the noise-free
motion itself scored against the motion-capture labels (the label noise: about the floor of any model on Table 1's
metric); ``hidden_draws``, the noise-free motion moved by what the draws a model given the state cannot know (the
push's friction, the table's load and friction field where the plate is) change in the exact quasi-static model,
against the noise-free labels, and ``state_floor``, the same against the motion-capture labels: about the best error
a model given the state and the object could reach (``*_lynch``: with Lynch's sensitivity to those draws instead).

The rows' names and descriptions (`CHAIN`, `REFERENCES`), the report (`markdown`) and `write` are in
`pushjax.paper.residual_report`, re-exported here.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

import jax
import numpy as np
import tqdm

from pushjax import data, planar
from pushjax.data import configs
from pushjax.geometry import annotate, get_object
from pushjax.mit import files as mit_files
from pushjax.paper import baselines, statistics
from pushjax.paper.residual_report import CHAIN, REFERENCES
from pushjax.paper.residual_report import markdown as markdown, write as write  # re-exported
from pushjax.physics import limit_surface, lynch
from pushjax.sim import push as sim_push
from pushjax.sim import scene
from pushjax.sim.dataset import PushJob, job_conditions
from pushjax.train import evaluate

EXPERIMENT = "data_efficiency"
"""Table 1's experiment."""
DEFAULT_SCALE = "cpu_full"
SPLIT = "test"
PATCH_RADIUS = 5e-4
"""Radius (m) of each support's disc patch in the exact limit surface: the simulator's supports are points (no
torsional friction), so a small patch (a few % of the plates' size) with more Newton iterations."""
EXACT_ITERATIONS = 24
"""Newton iterations of both exact solves (small patches sharpen the kinks, `limit_surface.ITERATIONS`)."""
CONVERGED_RESIDUAL = 1e-4
"""An exact solve whose residual (units of the total support friction) is above this counts as not converged."""

_READ_FIELDS = ("motion", "contact", "normal", "contact_flag", "action_from_contact", "l", "mu", "push_velocity",
                "object_pos", "sequence_id", "start_time", "scene_transform", "object_pose", "pusher_pos", "action",
                "pusher_moved")
_READ_CHUNK = 1000


class ReproductionError(RuntimeError):
    """A test push simulated again from its recording job does not reproduce its stored file."""


@dataclasses.dataclass(frozen=True, eq=False)
class SequenceTruth:
    """What the simulation knows about one recorded push, on its cleaned push's clock (T samples).

    Attributes:
      sequence_id: the push's id in the dataset's split plan.
      obj: the object's name.
      noisy: [T, 3] the cleaned motion-capture pose (x m, y m, yaw rad unwrapped), `mit_files.Push.object`.
      clean: [T, 3] the true pose of the tracked frame at the same instants (yaw continuous with ``noisy``).
      mu_factor: the push's drawn multiplier of the pusher-object coefficient (1: ideal testbed).
      support_points: [K, 2] the simulator's support points relative to the centre of mass, object axes, m.
      areas: [K] their area weights (mean 1).
      object_weights: [K] friction weights of the plate's own load (areas x plate unevenness).
      drawn_weights: [T, K] friction weights of the whole drawn load at each true pose (areas x position factors).
      measured_weights: [T, K] the supports' friction capacity read from the simulation (normal force N x
        coefficient) at the nearest 4 ms sample.
    """

    sequence_id: int
    obj: str
    noisy: np.ndarray
    clean: np.ndarray
    mu_factor: float
    support_points: np.ndarray
    areas: np.ndarray
    object_weights: np.ndarray
    drawn_weights: np.ndarray
    measured_weights: np.ndarray


class _CapacityRecorder:
    """``on_step`` of `pushjax.sim.push.Simulator.run`: the supports' friction capacity at every 4 ms sample, by
    sample index (a push simulated again with its line shifted overwrites the first attempt's)."""

    def __init__(self, simulator: sim_push.Simulator):
        model = simulator.model
        pairs = np.stack([model.pair_geom1, model.pair_geom2], axis=1)
        self.pairs = np.array([int(np.flatnonzero((pairs == model.geom(f"support{k}").id).any(axis=1))[0])
                               for k in range(len(simulator.support_points))])
        self.capacity: dict[int, np.ndarray] = {}

    def __call__(self, simulator: sim_push.Simulator) -> None:
        samples = simulator.data.time / sim_push.SAMPLE_PERIOD
        sample = round(samples)
        if abs(samples - sample) < 1e-6:
            normal = simulator.support_forces()[:, 0]
            self.capacity[sample] = normal * simulator.model.pair_friction[self.pairs, 0]


def clock(raw: mit_files.RawPush, frequency: float = mit_files.DEFAULT_FREQUENCY) -> np.ndarray:
    """[T] the instants (s, the file's time) that `pushjax.mit.files.clean_push` resamples ``raw`` at."""
    streams = [getattr(raw, name)[:, 0] for name in mit_files.DATASETS]
    start, end = max(float(times.min()) for times in streams), min(float(times.max()) for times in streams)
    samples = math.floor((end - start) * frequency + 1e-9) + 1
    return np.minimum(start + np.arange(samples) / frequency, end)


def _pose_at(stream: np.ndarray, times: np.ndarray) -> np.ndarray:
    """[T, 3] poses of a [N, 4] (t, x, y, yaw) stream interpolated at ``times``, the yaw unwrapped."""
    yaw = np.unwrap(stream[:, 3])
    return np.stack([np.interp(times, stream[:, 0], column) for column in (stream[:, 1], stream[:, 2], yaw)], -1)


def sequence_truth(job: PushJob, sequence_id: int) -> SequenceTruth:
    """Simulates the push of ``job`` again and returns what the simulation knows about it.

    Raises:
      ReproductionError: the simulation does not reproduce the stored file bit for bit.
    """
    raw = mit_files.read_raw_push(job.path)
    push = mit_files.clean_push(raw)
    conditions = job_conditions(job)
    params = dataclasses.replace(job.params, repetition=None)
    simulator = sim_push.simulator(params.shape, params.surface, job.effects, job.support)
    recorder = _CapacityRecorder(simulator)
    recording = simulator.run(params, job.initial_pose, rng=np.random.default_rng(job.noise_seed),
                              conditions=conditions, on_step=recorder)
    for name, stored, simulated in (("tip_pose", raw.tip_pose, recording.tip_pose),
                                    ("object_pose", raw.object_pose, recording.object_pose),
                                    ("ft_wrench", raw.ft_wrench, recording.ft_wrench)):
        if stored.shape != simulated.shape or not np.array_equal(stored, simulated):
            difference = (float(np.abs(stored - simulated).max()) if stored.shape == simulated.shape
                          else f"shape {simulated.shape} for {stored.shape}")
            raise ReproductionError(f"{job.path}: the push simulated again from its job differs from the file in "
                                    f"{name} (largest difference {difference}); its truth cannot be recovered")
    mu_factor = 1.0 if conditions is None else conditions.pusher_friction
    if "pushjax_testbed_draw" in raw.attributes:
        stored_factor = json.loads(raw.attributes["pushjax_testbed_draw"])["pusher_friction_factor"]
        if not math.isclose(stored_factor, mu_factor, rel_tol=1e-12):
            raise ReproductionError(f"{job.path}: pushjax_testbed_draw has the pusher friction factor {stored_factor}, "
                                    f"the job draws {mu_factor}")

    times = clock(raw)
    if len(times) != len(push.time):
        raise ReproductionError(f"{job.path}: {len(times)} clock samples for the cleaned push's {len(push.time)}")
    clean = _pose_at(recording.true_object_pose, times)
    clean[:, 2] += 2 * np.pi * np.round((push.object[0, 2] - clean[0, 2]) / (2 * np.pi))

    obj = get_object(params.shape)
    local, areas = simulator.support_points, scene.support_points(obj, job.support)[1]
    capacity = recorder.capacity
    first = min(capacity)  # the state before the first step is not seen by on_step: its first sample stands in
    samples = np.clip(np.round(times / sim_push.SAMPLE_PERIOD).astype(int), first, max(capacity))
    measured = np.stack([capacity[sample] for sample in samples])
    if conditions is None:
        object_weights = areas.copy()
        drawn = np.broadcast_to(areas, (len(times), len(areas))).copy()
    else:
        object_weights = areas * np.exp(conditions.testbed.pressure_plate_sigma * conditions.plate_pressure)
        drawn = np.stack([areas * conditions.position_factors(planar.rotate(local, yaw) + xy, areas)
                          for xy, yaw in zip(clean[:, :2], clean[:, 2])])
    return SequenceTruth(sequence_id=sequence_id, obj=params.shape, noisy=np.asarray(push.object, np.float64),
                         clean=clean, mu_factor=float(mu_factor), support_points=local - obj.centroid, areas=areas,
                         object_weights=object_weights, drawn_weights=drawn, measured_weights=measured)


def _transformed(poses: np.ndarray, rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    """[E, 3] poses moved by the examples' planar scene transforms."""
    return np.concatenate([planar.rotate(poses[:, :2], rotation) + translation,
                           (poses[:, 2] + rotation)[:, None]], axis=1)


def _load_parameters(weights: np.ndarray, points: np.ndarray, areas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """([E] l of [E, K] support weights over that of the area weights alone, [E, 2] their centre of friction minus
    the area weights', object axes, m)."""
    def centre_and_l(w):
        w = np.atleast_2d(w)
        centre = w @ points / w.sum(-1, keepdims=True)
        spread = np.linalg.norm(points[None] - centre[:, None], axis=-1)
        return centre, (w * spread).sum(-1) / w.sum(-1)

    reference_centre, reference_l = centre_and_l(areas)
    centre, l = centre_and_l(weights)
    return l / reference_l, centre - reference_centre


def sequence_examples(examples: Mapping[str, np.ndarray], truth: SequenceTruth, config: configs.DatasetConfig
                      ) -> dict[str, np.ndarray]:
    """The noise-free labels and state and the drawn parameters of one sequence's E examples.

    Returns:
      {"noisy_motion": [E, 3] the labels cut again from the motion capture (checks the windows against the stored
      ``motion``), "noisy_pose": [E, 3] the window-start pose so moved (against the stored ``object_pose``),
      "motion": [E, 3] the noise-free labels, "contact", "normal", "action_from_contact" [E, 2] and "contact_flag"
      [E] the state annotated on the true pose, "mu_factor" [E], and for each load ``object``, ``drawn`` and
      ``measured``: "<load>_l_factor" [E], "<load>_offset" [E, 2] (centre of friction minus centre of mass, world
      axes of the example, m), and "<load>_weights" [E, K] with "points" [E, K, 2] (support points relative to the
      centre of mass, the example's world axes)}.
    """
    frequency = mit_files.DEFAULT_FREQUENCY
    horizon = round(config.horizon * frequency)
    start = np.round(np.asarray(examples["start_time"], np.float64) * frequency).astype(int)
    end = start + horizon
    if end.max() >= len(truth.clean):
        raise ValueError(f"examples: a window of sequence {truth.sequence_id} ends after its push")
    transform = np.asarray(examples["scene_transform"], np.float64)
    rotation = np.arctan2(transform[:, 1, 0], transform[:, 0, 0])
    translation = transform[:, :2, 2]
    moved = np.asarray(examples["pusher_moved"]) > 0
    obj = get_object(truth.obj)
    result = {}
    for name, poses in (("noisy", truth.noisy), ("clean", truth.clean)):
        pose0 = _transformed(poses[start], rotation, translation)
        pose1 = _transformed(poses[end], rotation, translation)
        motion = np.concatenate([planar.centre_of_mass(obj.centroid, pose1) - planar.centre_of_mass(obj.centroid, pose0),
                                 (pose1[:, 2] - pose0[:, 2])[:, None]], axis=1)
        motion[moved] = 0.0
        result[f"{name}_motion"], result[f"{name}_pose"] = motion, pose0
    pusher = np.asarray(examples["pusher_pos"], np.float64)
    action = np.asarray(examples["action"], np.float64)
    contact = annotate(obj, result["clean_pose"], pusher, action)
    touches = contact.touches & ~moved
    out = {"noisy_motion": result["noisy_motion"], "noisy_pose": result["noisy_pose"], "motion": result["clean_motion"],
           "contact": np.where(touches[:, None], contact.contact_rel_com, 0.0),
           "normal": np.where(touches[:, None], contact.normal, 0.0),
           "action_from_contact": np.where(touches[:, None], contact.action_from_contact, 0.0),
           "contact_flag": touches.astype(np.float64), "mu_factor": np.full(len(start), truth.mu_factor)}
    yaw = result["clean_pose"][:, 2]
    out["points"] = planar.rotate(truth.support_points[None], yaw[:, None])
    window = np.arange(horizon + 1)
    for load, weights in (("object", np.broadcast_to(truth.object_weights, (len(start), len(truth.areas)))),
                          ("drawn", truth.drawn_weights[start[:, None] + window].mean(axis=1)),
                          ("measured", truth.measured_weights[start[:, None] + window].mean(axis=1))):
        l_factor, offset = _load_parameters(weights, truth.support_points, truth.areas)
        out[f"{load}_l_factor"], out[f"{load}_offset"] = l_factor, planar.rotate(offset, yaw)
        out[f"{load}_weights"] = np.asarray(weights, np.float64)
    return out


def lynch_about(contact, normal, action, l, mu, s, offset) -> np.ndarray:
    """[N, 3] Lynch's motion of the centre of mass when the limit surface is centred ``offset`` [N, 2] (m) from it:
    the contact taken relative to the centre of friction, its twist carried to the centre of mass."""
    offset = np.asarray(offset, np.float64)
    twist = np.asarray(lynch.predict(*(np.asarray(value, np.float32) for value in (
        np.asarray(contact) - offset, normal, action, l, mu, s))), np.float64)
    return np.concatenate([twist[:, :2] + twist[:, 2:] * np.stack([offset[:, 1], -offset[:, 0]], -1), twist[:, 2:]],
                          axis=1)


@functools.partial(jax.jit, static_argnames="iterations")
def _exact(contact, normal, action, mu, points, weights, s, iterations):
    return limit_surface.solve(contact, normal, action, mu, points, weights, PATCH_RADIUS, s,
                               stick_iterations=iterations, slip_iterations=iterations)


def exact(clean: Mapping[str, np.ndarray], mu: np.ndarray, load: str) -> tuple[np.ndarray, np.ndarray]:
    """([N, 3] motion of the centre of mass on the exact limit surface of ``load``'s weights, [N] the solves'
    residuals), float32."""
    arrays = [np.asarray(value, np.float32) for value in (
        clean["contact"], clean["normal"], clean["action_from_contact"], mu, clean["points"], clean[f"{load}_weights"],
        clean["contact_flag"])]
    solution = _exact(*arrays, iterations=EXACT_ITERATIONS)
    return np.asarray(solution.twist, np.float64), np.asarray(solution.residual, np.float64)


def predictions(examples: Mapping[str, np.ndarray], clean: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Component name -> [N, 3] predicted motion (m, m, rad) of every row of `CHAIN` and `REFERENCES`, and
    ``"exact_residual"`` -> the largest of the exact solves' residuals per example.

    ``hidden_draws`` (and ``state_floor``) is the noise-free motion minus what the hidden draws change in the exact
    quasi-static model: the exact limit surface with the push's friction and the whole drawn load, minus the one
    with the nominal friction and the plate's own load (what a model that knows the object could learn);
    ``hidden_draws_lynch`` the same with Lynch's model (``drawn_load`` minus ``object_load``).
    """
    physics = baselines.predictions("physics", examples)["motion"].astype(np.float64)
    l, mu = np.asarray(examples["l"], np.float64), np.asarray(examples["mu"], np.float64)
    true_mu = mu * clean["mu_factor"]
    state = (clean["contact"], clean["normal"], clean["action_from_contact"])
    s = clean["contact_flag"]
    zero = np.zeros_like(physics)
    exact_drawn, residual_drawn = exact(clean, true_mu, "drawn")
    exact_measured, residual_measured = exact(clean, true_mu, "measured")
    exact_known, residual_known = exact(clean, mu, "object")
    hidden = clean["motion"] - (exact_drawn - exact_known)
    object_load = lynch_about(*state, l * clean["object_l_factor"], mu, s, clean["object_offset"])
    drawn_load = lynch_about(*state, l * clean["drawn_l_factor"], true_mu, s, clean["drawn_offset"])
    hidden_lynch = clean["motion"] - (drawn_load - object_load)
    return {
        "physics": physics, "clean_labels": physics,
        "clean_state": lynch_about(*state, l, mu, s, zero[:, :2]),
        "object_load": object_load,
        "true_mu": lynch_about(*state, l * clean["object_l_factor"], true_mu, s, clean["object_offset"]),
        "drawn_load": drawn_load,
        "exact_drawn": exact_drawn, "exact_measured": exact_measured,
        "zero": zero, "zero_clean_labels": zero, "truth": clean["motion"], "hidden_draws": hidden,
        "state_floor": hidden, "hidden_draws_lynch": hidden_lynch, "state_floor_lynch": hidden_lynch,
        "exact_residual": np.maximum.reduce([residual_drawn, residual_measured, residual_known]),
    }


_NOISY_LABELLED = {"physics", "zero", "truth", "state_floor", "state_floor_lynch"}
"""The rows scored against the motion-capture labels; every other against the noise-free ones."""


def _errors(predicted: np.ndarray, labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """([N] translation error mm, [N] rotation error deg), as `pushjax.train.evaluate.error_metrics`."""
    return (np.linalg.norm(predicted[:, :2] - labels[:, :2], axis=-1) * planar.M_TO_MM,
            np.degrees(np.abs(predicted[:, 2] - labels[:, 2])))


def _sums(sequence_id: np.ndarray, values: np.ndarray) -> list[float]:
    ids, inverse = np.unique(sequence_id, return_inverse=True)
    return np.bincount(inverse, weights=values, minlength=len(ids)).tolist()


def score(predicted: Mapping[str, np.ndarray], noisy_labels: np.ndarray, clean_labels: np.ndarray,
          sequence_id: np.ndarray) -> list[dict]:
    """The rows (`CHAIN` then `REFERENCES`): errors in mm / degrees per example and in % of the zero baseline on the
    motion-capture labels, sequence-bootstrap standard errors (`pushjax.paper.statistics.estimate`), and for each
    `CHAIN` row after the first its paired difference from the one before."""
    sequence_id = np.asarray(sequence_id)
    zero_trans, zero_rot = _errors(np.zeros_like(noisy_labels), noisy_labels)
    base = {"id": np.unique(sequence_id).tolist(), "count": _sums(sequence_id, np.ones(len(sequence_id))),
            "trans_zero_mm": _sums(sequence_id, zero_trans), "rot_zero_deg": _sums(sequence_id, zero_rot)}
    rows, estimates = [], {}
    for name, part, labels, state, description in (*CHAIN, *REFERENCES):
        trans, rot = _errors(predicted[name], noisy_labels if name in _NOISY_LABELLED else clean_labels)
        row = {"component": name, "part": part, "labels": labels, "state": state, "description": description,
               "seed": None, "trans_mm": float(trans.mean()), "rot_deg": float(rot.mean()),
               "trans_percent": float(100 * trans.sum() / zero_trans.sum()),
               "rot_percent": float(100 * rot.sum() / zero_rot.sum()),
               "sequences": {**base, "trans_mm": _sums(sequence_id, trans), "rot_deg": _sums(sequence_id, rot)}}
        for metric in ("trans_percent", "rot_percent"):
            estimates[name, metric] = statistics.estimate([row], metric)
            row[f"{metric}_se"] = estimates[name, metric].se
        rows.append(row)
    for previous, row in zip(rows[:len(CHAIN) - 1], rows[1:len(CHAIN)]):
        row["difference"] = {"from": previous["component"]}
        for metric in ("trans_percent", "rot_percent"):
            change = statistics.difference(estimates[row["component"], metric], estimates[previous["component"], metric])
            row["difference"][metric], row["difference"][f"{metric}_se"] = change.value, change.se
    return rows


PARTS = {"tracking": ("physics", "clean_state"), "object_load": ("clean_state", "object_load"),
         "hidden_draws": ("object_load", "drawn_load"), "randomness": ("clean_state", "drawn_load"),
         "exact_limit_surface": ("drawn_load", "exact_measured"), "learnable_gap": ("physics", "state_floor"),
         "learnable_gap_lynch": ("physics", "state_floor_lynch")}
"""Part -> (row, row): the part is the paired difference of the two rows' errors."""


def part_differences(rows: Sequence[Mapping]) -> dict[str, dict]:
    """Every part of `PARTS` as the paired difference of its rows (same sequence resamples)."""
    by_name = {row["component"]: row for row in rows}
    parts = {}
    for part, (high, low) in PARTS.items():
        parts[part] = {"from": high, "to": low}
        for metric in ("trans_percent", "rot_percent"):
            change = statistics.difference(statistics.estimate([by_name[high]], metric),
                                           statistics.estimate([by_name[low]], metric))
            parts[part][metric], parts[part][f"{metric}_se"] = change.value, change.se
    return parts


def test_sequences(config: configs.DatasetConfig, plan: configs.SplitPlan, max_sequences: int | None,
                   split: str = SPLIT) -> tuple[tuple[int, ...], int]:
    """(the sequence ids of ``split`` decomposed, the stride k): every k-th of the split's sorted ids, k the
    smallest that keeps at most ``max_sequences`` (None: all, k = 1)."""
    ids = plan.splits[split]
    stride = 1 if not max_sequences or max_sequences >= len(ids) else math.ceil(len(ids) / max_sequences)
    return tuple(ids[::stride][:max_sequences or None]), stride


def read_examples(source, config: configs.DatasetConfig, split_ids: Sequence[int], chosen: Sequence[int]
                  ) -> dict[str, np.ndarray]:
    """The stored examples of the ``chosen`` sequences (a split's examples are stored sequence by sequence, in id
    order, `examples_per_sequence` each), the fields `decompose` reads."""
    per = config.examples_per_sequence
    position = {sequence: index for index, sequence in enumerate(split_ids)}
    keys = np.concatenate([np.arange(position[s] * per, (position[s] + 1) * per) for s in chosen])
    if len(source) != len(split_ids) * per:
        raise ValueError(f"data_dir: the split holds {len(source)} examples, its plan {len(split_ids)} x {per}")
    fields = {name: [] for name in _READ_FIELDS}
    for begin in range(0, len(keys), _READ_CHUNK):
        for example in source.__getitems__(keys[begin:begin + _READ_CHUNK].tolist()):
            for name in _READ_FIELDS:
                fields[name].append(example[name])
    examples = {name: np.asarray(values) for name, values in fields.items()}
    expected = np.repeat(np.asarray(chosen), per)
    if not np.array_equal(examples["sequence_id"], expected):
        raise ValueError("data_dir: the split's examples are not stored sequence by sequence in id order")
    return examples


def dataset_builder(data_dir: str | Path, scale: str) -> data.PushEffects:
    """The built ``data_efficiency`` dataset at ``scale`` in ``data_dir``.

    Raises:
      ValueError: ``data_dir: ...`` when it is not built there.
    """
    builder = data.PushEffects(config=data.config_name(EXPERIMENT, scale), data_dir=str(data_dir))
    if not builder.is_prepared():
        raise ValueError(f"data_dir: dataset {data.dataset_name(EXPERIMENT, scale)} is not built in {data_dir} "
                         f"(python -m experiments.build_dataset --experiment={EXPERIMENT} --scale={scale} "
                         f"--data_dir={data_dir} builds it)")
    return builder


def decompose(data_dir: str | Path, scale: str = DEFAULT_SCALE, max_sequences: int | None = None,
              progress: bool = True) -> dict:
    """The decomposition of the ``physics`` baseline's error on the ``data_efficiency`` test split at ``scale``.

    Args:
      data_dir: the TFDS data directory holding the built dataset (and its raw push cache).
      scale: the dataset's scale.
      max_sequences: at most this many test sequences, every k-th of the split (None: all).
      progress: a tqdm bar over the pushes simulated again.

    Returns:
      The results (``rows`` of `score`, ``parts`` of `part_differences`, the subset, the checks, timings).
    """
    started = time.monotonic()
    builder = dataset_builder(data_dir, scale)
    config = builder.dataset_config
    plan = configs.plan_splits(config, builder.raw_dir)
    chosen, stride = test_sequences(config, plan, max_sequences)
    source = data.load(EXPERIMENT, scale, data_dir=str(data_dir), split=SPLIT)
    examples = read_examples(source, config, plan.splits[SPLIT], chosen)
    per = config.examples_per_sequence
    parts = []
    simulated_s = 0.0
    for index, sequence in enumerate(tqdm.tqdm(chosen, disable=not progress, unit="push",
                                               desc="re-simulating test pushes for their true poses")):
        tick = time.monotonic()
        truth = sequence_truth(plan.jobs[sequence], sequence)
        simulated_s += time.monotonic() - tick
        rows = slice(index * per, (index + 1) * per)
        parts.append(sequence_examples({name: values[rows] for name, values in examples.items()}, truth, config))
    clean = {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
    predicted = predictions(examples, clean)
    noisy = np.asarray(examples["motion"], np.float64)
    rows = score(predicted, noisy, clean["motion"], examples["sequence_id"])
    table1 = evaluate.error_metrics(baselines.predictions("physics", examples), examples)
    stored_pose = np.asarray(examples["object_pose"], np.float64)
    touching = np.asarray(examples["contact_flag"]) > 0.5
    checks = {
        "resimulated_identical": len(chosen),
        "noisy_motion_max_difference_m": float(np.abs(clean["noisy_motion"][:, :2] - noisy[:, :2]).max()),
        "noisy_yaw_max_difference_rad": float(np.abs(clean["noisy_motion"][:, 2] - noisy[:, 2]).max()),
        "noisy_pose_max_difference_m": float(np.abs(clean["noisy_pose"][:, :2] - stored_pose[:, :2]).max()),
        "table1_physics": {"trans_percent": table1["trans_percent"], "rot_percent": table1["rot_percent"]},
        "contact_flag_changed": int(np.sum(touching != (clean["contact_flag"] > 0.5))),
        "exact_not_converged": int(np.sum(predicted["exact_residual"] > CONVERGED_RESIDUAL)),
        "exact_largest_residual": float(predicted["exact_residual"].max()),
    }
    split_ids = plan.splits[SPLIT]
    return {
        "dataset": data.dataset_name(EXPERIMENT, scale), "testbed": config.testbed, "split": SPLIT,
        "split_sequences": len(split_ids), "sequences": len(chosen), "examples": int(len(noisy)), "stride": stride,
        "subset": ("all sequences of the split" if stride == 1 and len(chosen) == len(split_ids) else
                   f"every {stride}-th sequence of the split's sorted ids, starting with the first ({len(chosen)} of "
                   f"{len(split_ids)})"),
        "units": {"trans": "mm (per example, mean)", "rot": "deg (per example, mean)",
                  "percent": "% of the zero baseline on the motion-capture labels"},
        "patch_radius_m": PATCH_RADIUS, "exact_iterations": EXACT_ITERATIONS,
        "zero": {"trans_mm": rows[len(CHAIN)]["trans_mm"], "rot_deg": rows[len(CHAIN)]["rot_deg"]},
        "rows": rows, "parts": part_differences(rows), "checks": checks,
        "wall_s": round(time.monotonic() - started, 1), "simulation_s": round(simulated_s, 1),
    }

