r"""Prediction over time: every model rolled out along whole recorded pushes, its error against the horizon.

The one-step experiments cut pushes into 0.5 s windows; here each test sequence is followed from its start to the
pusher's stop, on the clock of the models' own step (`STEP_S`, the datasets' horizon), and each model predicts where
the object is after 0.5, 1, 2 and 4 s (`HORIZONS_S`, when the push lasts that long) and at the end of the push:

* ``zero``: the object does not move;
* ``physics_long``: Lynch's model from the true start pose, one step with the pusher's whole displacement up to the
  horizon (what the one-step ``physics`` baseline does with a longer action);
* ``physics_chained``: the JAX rollout (`pushjax.physics.rollout`) from the true start pose, one step per 0.5 s
  of the pusher's path, the contact re-annotated on the outline at every step;
* ``hybrid``, ``error``: their perception reads the first depth image only; the object's pose is recovered from the
  estimated centre of mass, contact point and normal on the known object's outline (`pose_from_contact`), and the
  rollout goes on through the analytical part (the JAX rollout with the true ``l`` and ``mu``) — the learned error
  term of ``error`` needs an image per step and is not applied after the first image;
* ``neural``: needs an image per step, so the scene is rendered (`pushjax.render`) with the object at the pose the
  network itself predicted at the step before (the pusher on its recorded path) and the network predicts the next
  step from that image.

Errors are those of the motion since the push's start (translation of the centre of mass, yaw change), so a model
starting from its own estimate of the pose is judged by the motion it predicts. Per horizon and model, ``rows``
hold per-sequence sums in the shape of `pushjax.train.evaluate.error_metrics` (one window per sequence), so
``trans_percent`` (% of ``zero``'s error) gets the house's sequence bootstrap and seed spread
(`pushjax.paper.statistics`); ``trans_mm`` and ``rot_deg`` are mean errors per sequence.

`EXPECTATIONS` are stated before the run and decided on its numbers (`decide`) by the project's rule,
`pushjax.stats.decide`: 2 standard errors of the paired difference, the test sequences and seeds the unit of
resampling, one look per run (an earlier, smaller run is its own record, not a first look combined with this one).
"""

from __future__ import annotations

import collections
import dataclasses
import functools
import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import jax
import jax.numpy as jnp
import matplotlib.pyplot as plt
import numpy as np

from pushjax import data, outputs, planar, stats
from pushjax.data import examples as examples_lib
from pushjax.geometry import get_object, limit_surface_ratio, outline_jax
from pushjax.mit import files as mit_files, protocol
from pushjax.paper import findings, statistics
from pushjax.paper.runner import RunOutcome
from pushjax.paper.spec import SETUPS, ExperimentSpec, Setup
from pushjax.physics import rollout as rollout_lib
from pushjax.stats import sequence_bootstrap_weights
from pushjax.train.predictor import Predictor

STEP_S = 0.5
"""The models' step, s: the datasets' horizon (``DatasetConfig.horizon``), on which pushes are chained."""
HORIZONS_S = (0.5, 1.0, 2.0, 4.0)
"""Prediction horizons, s, besides the whole push (`WHOLE`)."""
WHOLE = "whole push"
"""The horizon label of the push's end: the first step boundary at or after the pusher's stop."""
BASELINES = ("zero", "physics_long", "physics_chained")
"""The models that need no training."""
LEARNED = ("hybrid", "error", "neural")
"""The trained variants this experiment rolls out (others are not supported)."""
MODELS = (*BASELINES, *LEARNED)
FIGURE = "rollouts.png"


def horizon_labels() -> tuple[str, ...]:
    return (*(f"{h:g} s" for h in HORIZONS_S), WHOLE)


@dataclasses.dataclass(frozen=True)
class Expectation:
    """A prediction about the run, fixed before it: ``better``'s score is lower than ``worse``'s
    (`pushjax.stats.decide`).

    Each side is ``(model, horizon label)`` or, for a difference of two models at a horizon, ``(model_a, model_b,
    horizon label)`` (``a - b``). Scores are `pushjax.paper.statistics.SCORE` on `test_split`.
    """

    key: str
    statement: str
    test_split: str
    better: tuple[str, ...]
    worse: tuple[str, ...]


EXPECTATIONS = (
    Expectation("chaining", "Chaining short (0.5 s) analytical steps beats one long step over the whole push at "
                "20 mm/s: the contact and the object's rotation are updated as the push goes on.",
                "test_20", ("physics_chained", WHOLE), ("physics_long", WHOLE)),
    Expectation("hybrid_over_neural_grows", "Hybrid's advantage over neural (neural - hybrid score) is larger over "
                "the whole push than over one 0.5 s step at 20 mm/s: neural's errors compound through the images "
                "of its own predictions, hybrid's rollout keeps the physics.",
                "test_20", ("neural", "hybrid", "0.5 s"), ("neural", "hybrid", WHOLE)),
    Expectation("hybrid_beats_neural_whole", "Over the whole push at 20 mm/s hybrid beats neural.",
                "test_20", ("hybrid", WHOLE), ("neural", WHOLE)),
)
"""What the run is expected to show, decided by `decide` (`pushjax.stats.decide`)."""


@dataclasses.dataclass(frozen=True)
class PushSequence:
    """One recorded push on the models' clock, moved so that the object's start centre of mass is at the table
    origin (where the camera looks).

    Attributes:
      sequence_id: the sequence's id in its dataset's split plan (the unit of the bootstrap).
      obj: the object's name.
      surface: the support surface.
      l: limit-surface ratio, m.
      mu: pusher-object friction coefficient.
      poses: [K + 1, 3] the object's tracked-frame pose (x m, y m, yaw rad) at each step boundary.
      pusher: [K + 1, 2] the pusher centre at each step boundary, m.
    """

    sequence_id: int
    obj: str
    surface: str
    l: float
    mu: float
    poses: np.ndarray
    pusher: np.ndarray

    @property
    def steps(self) -> int:
        return len(self.pusher) - 1

    def horizon_step(self, label: str) -> int | None:
        """The step index of a horizon label, None when the push ends before it."""
        if label == WHOLE:
            return self.steps
        step = round(float(label.removesuffix(" s")) / STEP_S)
        return step if step <= self.steps else None


def on_step_clock(push: mit_files.Push, sequence_id: int, step_s: float = STEP_S) -> PushSequence:
    """`push` sampled every `step_s` from its start until the first sample at or after the pusher's stop, moved so
    that its start centre of mass is at the origin."""
    params = push.params
    frequency = 1.0 / float(push.time[1] - push.time[0])
    steps = math.ceil(protocol.push_duration(params) / step_s - 1e-9)
    indices = np.minimum(np.round(np.arange(steps + 1) * step_s * frequency).astype(int), len(push.time) - 1)
    obj = get_object(params.shape)
    poses = np.array(push.object[indices], np.float64)
    shift = planar.centre_of_mass(obj.centroid, poses[0])
    poses[:, :2] -= shift
    return PushSequence(sequence_id=sequence_id, obj=params.shape, surface=params.surface,
                        l=float(limit_surface_ratio(obj)), mu=examples_lib.pusher_friction(push), poses=poses,
                        pusher=np.asarray(push.tip[indices, :2], np.float64) - shift)


def load_sequences(spec: ExperimentSpec) -> dict[str, list[PushSequence]]:
    """test split label -> its whole push sequences (raw MIT files of the spec's test dataset, on `STEP_S`)."""
    dataset = spec.test_dataset
    raw_dir = data.PushEffects(config=data.config_name(dataset.experiment, dataset.scale, dataset.testbed),
                               data_dir=spec.data_dir, seed=dataset.seed).raw_dir
    plan = data.plan_splits(dataset, raw_dir)
    return {spec.test_split_label(split): [on_step_clock(mit_files.load_push(plan.jobs[i].path), i)
                                           for i in plan.splits[split]]
            for split in spec.test_splits}


def pose_from_contact(obj: str, com: np.ndarray, contact: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """[3] the tracked-frame pose of the known object `obj` that puts a point of its outline at the estimated
    contact with the estimated inward normal there.

    For each edge of the outline, the yaw that turns its inward normal onto `normal` is tried; the edge whose
    segment then lies closest to the contact point is chosen (symmetric objects have several equal choices, which
    give the same motion).

    Args:
      obj: the object's name.
      com: [2] estimated centre of mass, world, m.
      contact: [2] estimated contact point relative to `com`, world axes, m.
      normal: [2] estimated inward normal at the contact, world (any length > 0).
    """
    shape = _outline(obj)
    count = int(shape.count)  # the outline is padded past its real vertices
    start, edge, outward = (np.asarray(a, np.float64)[:count] for a in (shape.start, shape.edge, shape.outward))
    centroid = np.asarray(shape.centroid, np.float64)
    yaw = math.atan2(normal[1], normal[0]) - np.arctan2(-outward[:, 1], -outward[:, 0])
    local = centroid + planar.rotate(np.broadcast_to(np.asarray(contact, np.float64), (len(yaw), 2)), -yaw)
    along = np.clip(np.sum((local - start) * edge, -1) / np.sum(edge * edge, -1), 0.0, 1.0)
    distance = np.linalg.norm(local - start - along[:, None] * edge, axis=-1)
    best = float(yaw[np.argmin(distance)])
    return np.concatenate([np.asarray(com, np.float64) - planar.rotate(centroid, best), [best]])


def padded_path(sequence: PushSequence, steps: int | None = None) -> np.ndarray:
    """[max(K, steps) + 1, 2] the pusher's path held at its end after step K (a resting pusher moves nothing), so
    that pushes of different lengths share one compiled rollout."""
    extra = max(0, (steps or 0) - sequence.steps)
    return np.concatenate([sequence.pusher, np.repeat(sequence.pusher[-1:], extra, axis=0)])


@jax.jit
def _chained(shape, pose, pusher, l, mu):
    return rollout_lib.rollout(shape, pose, pusher, l, mu).poses


@functools.cache
def _outline(obj: str) -> outline_jax.Outline:
    return outline_jax.outline(obj)


def physics_chained(sequence: PushSequence, start_pose: np.ndarray | None = None, steps: int | None = None) -> np.ndarray:
    """[K + 1, 3] poses of the JAX rollout along the pusher's path, one step per `STEP_S`, from `start_pose`
    (default the true one); `steps`: compile for a path padded to this many steps (`padded_path`)."""
    shape = _outline(sequence.obj)
    pose = sequence.poses[0] if start_pose is None else start_pose
    poses = _chained(shape, jnp.asarray(pose, jnp.float32), jnp.asarray(padded_path(sequence, steps), jnp.float32),
                     sequence.l, sequence.mu)
    return np.asarray(poses, np.float64)[:sequence.steps + 1]


@jax.jit
def _long(shape, pose, paths, l, mu):
    return jax.vmap(lambda path: rollout_lib.rollout(shape, pose, path, l, mu).poses[-1])(paths)


def physics_long(sequence: PushSequence, steps: int | None = None) -> np.ndarray:
    """[K + 1, 3] poses that one step of Lynch's model predicts from the true start pose for the pusher's whole
    displacement up to each step boundary; `steps` as in `physics_chained`."""
    shape = _outline(sequence.obj)
    path = padded_path(sequence, steps)
    paths = np.stack([np.broadcast_to(path[0], path.shape), path], axis=1)
    poses = _long(shape, jnp.asarray(sequence.poses[0], jnp.float32), jnp.asarray(paths, jnp.float32),
                  sequence.l, sequence.mu)
    return np.asarray(poses, np.float64)[:sequence.steps + 1]


def _com_and_yaw(sequence: PushSequence, poses: np.ndarray) -> np.ndarray:
    """[..., 3] centre of mass (m) and yaw (rad) of tracked-frame poses of the sequence's object."""
    return np.concatenate([planar.centre_of_mass(get_object(sequence.obj).centroid, poses), poses[..., 2:]], -1)


class Scenes:
    """Depth images of pushes' scenes, one renderer per object and surface (`pushjax.data.examples.make_renderer`)."""

    def __init__(self, dataset: data.DatasetConfig):
        self.dataset = dataset
        self.camera = examples_lib.make_camera(dataset)
        self._renderers = {}

    def depth(self, sequence: PushSequence, pose: np.ndarray, pusher: np.ndarray) -> np.ndarray:
        """[H, W] depth of `sequence`'s object at `pose` [3] with the pusher at `pusher` [2]."""
        key = (sequence.obj, sequence.surface)
        if key not in self._renderers:
            self._renderers[key] = examples_lib.make_renderer(self.dataset, *key)
        return self._renderers[key].depth(pose, pusher)

    def close(self):
        for renderer in self._renderers.values():
            renderer.close()


def _predict(predictor: Predictor, scenes: Scenes, sequences: Sequence[PushSequence], poses: np.ndarray, step: int):
    """The predictor on every sequence's scene at `step` with the object at `poses` [S, 3] (a sequence that has
    ended repeats its last step, whose prediction is not used)."""
    steps = [min(step, sequence.steps - 1) for sequence in sequences]
    images = np.stack([scenes.depth(sequence, pose, sequence.pusher[k])
                       for sequence, pose, k in zip(sequences, poses, steps)])
    pusher = np.stack([sequence.pusher[k] for sequence, k in zip(sequences, steps)])
    action = np.stack([sequence.pusher[k + 1] - sequence.pusher[k] for sequence, k in zip(sequences, steps)])
    return predictor(images, pusher, action, scenes.camera, np.array([s.l for s in sequences]),
                     np.array([s.mu for s in sequences]))


def neural_rollouts(predictor: Predictor, scenes: Scenes, sequences: Sequence[PushSequence]) -> list[np.ndarray]:
    """[K + 1, 3] centre of mass and yaw per sequence, each step predicted from the scene rendered with the object
    where the model put it (the first image is the true scene)."""
    poses = np.stack([sequence.poses[0] for sequence in sequences])
    tracks = [[_com_and_yaw(sequence, pose)] for sequence, pose in zip(sequences, poses)]
    for step in range(max(sequence.steps for sequence in sequences)):
        motion = np.asarray(_predict(predictor, scenes, sequences, poses, step).motion, np.float64)
        for index, sequence in enumerate(sequences):
            if step < sequence.steps:
                state = tracks[index][-1] + motion[index]
                tracks[index].append(state)
                centroid = get_object(sequence.obj).centroid
                poses[index] = np.concatenate([state[:2] - planar.rotate(centroid, state[2]), state[2:]])
    return [np.stack(track) for track in tracks]


def perceived_rollouts(predictor: Predictor, scenes: Scenes, sequences: Sequence[PushSequence],
                       steps: int | None = None) -> list[np.ndarray]:
    """[K + 1, 3] centre of mass and yaw per sequence: the JAX rollout from the pose `pose_from_contact` recovers
    from the model's perception of the first image (its centre of mass, contact point and normal); `steps` as in
    `physics_chained`."""
    first = _predict(predictor, scenes, sequences, np.stack([s.poses[0] for s in sequences]), 0)
    tracks = []
    for index, sequence in enumerate(sequences):
        pose = pose_from_contact(sequence.obj, first.object_pos[index], first.contact[index], first.normal[index])
        tracks.append(_com_and_yaw(sequence, physics_chained(sequence, pose, steps)))
    return tracks


def _yaw_error_deg(predicted, true):
    return float(np.degrees(abs(predicted - true)))


def horizon_rows(model: str, test_split: str, sequences: Sequence[PushSequence], tracks: Sequence[np.ndarray],
                 seed: int | None) -> list[dict]:
    """One row per horizon: per-sequence sums of the motion errors since the start (`pushjax.stats` schema) and
    their means.

    Args:
      model: the model's name.
      test_split: the split's label.
      sequences: the split's sequences.
      tracks: per sequence [K + 1, 3] predicted centre of mass (m) and yaw (rad).
      seed: the trained model's seed, None for a baseline.
    """
    rows = []
    for label in horizon_labels():
        sums = collections.defaultdict(list)
        for sequence, track in zip(sequences, tracks):
            step = sequence.horizon_step(label)
            if step is None:
                continue
            truth = _com_and_yaw(sequence, sequence.poses)
            true_motion, motion = truth[step] - truth[0], track[step] - track[0]
            sums["id"].append(sequence.sequence_id)
            sums["count"].append(1.0)
            sums["trans_mm"].append(float(np.linalg.norm(motion[:2] - true_motion[:2])) * planar.M_TO_MM)
            sums["trans_zero_mm"].append(float(np.linalg.norm(true_motion[:2])) * planar.M_TO_MM)
            sums["rot_deg"].append(_yaw_error_deg(motion[2], true_motion[2]))
            sums["rot_zero_deg"].append(_yaw_error_deg(0.0, true_motion[2]))
        if len(sums["id"]) < 2:  # the bootstrap needs two sequences
            continue
        row = {"model": model, "kind": "baseline" if seed is None else "trained", "test_split": test_split,
               "horizon": label, "seed": seed, "sequences": dict(sums)}
        totals = {name: float(np.sum(values)) for name, values in sums.items() if name != "id"}
        weights = sequence_bootstrap_weights(sums["id"])
        for name, zero in (("trans", "trans_zero_mm"), ("rot", "rot_zero_deg")):
            value = f"{name}_mm" if name == "trans" else "rot_deg"
            per_sequence = np.asarray(sums[value])
            row[value] = totals[value] / totals["count"]
            row[f"{value}_se"] = float((weights @ per_sequence / weights.sum(1)).std(ddof=1))
            row[f"{name}_percent"] = 100.0 * totals[value] / totals[zero] if totals[zero] > 0 else None
        rows.append(row)
    return rows


def trained_predictors(outcome: RunOutcome) -> list[tuple[str, int, Predictor]]:
    """(variant, seed, predictor) of every trained model of the run that `LEARNED` names (built from the run's own
    state, so the predictor's ``checkpoint`` names no folder, only the step)."""
    found = []
    for sweep in outcome.sweeps:
        result = sweep.result
        for index, model_spec in enumerate(result.specs):
            variant = model_spec.variant or sweep.variants[0]
            if variant not in LEARNED:
                continue
            state = result.model_state(index)
            found.append((variant, model_spec.seed, Predictor(
                result.model, {"params": state.params, "batch_stats": state.batch_stats},
                f"seed={model_spec.seed}", variant, (Path(), int(state.step)))))
    return found


def setup(test_splits: Sequence[str] = ()) -> Setup:
    """The ``rollouts`` `Setup` with `test_splits` (a subset of its own; empty: all); raises ``ValueError`` naming
    an unknown or repeated split."""
    default = SETUPS["rollouts"]
    if not test_splits:
        return default
    if len(set(test_splits)) != len(test_splits) or not set(test_splits) <= set(default.test_splits):
        raise ValueError(f"test_splits: expected some of {', '.join(default.test_splits)} without repeats, got "
                         f"{', '.join(test_splits)}")
    return dataclasses.replace(default, test_splits=tuple(test_splits))


def check_models(spec: ExperimentSpec) -> None:
    """Raises ``ValueError`` naming a variant this experiment cannot roll out."""
    unsupported = [variant for variant in spec.variants if variant not in LEARNED]
    if unsupported:
        raise ValueError(f"variants: {', '.join(unsupported)} cannot be rolled out; choose from "
                         f"{', '.join((*LEARNED, 'zero', 'physics'))}")


def evaluate(outcome: RunOutcome, sequences: Mapping[str, Sequence[PushSequence]] | None = None,
             progress: Callable[[str], None] = print) -> dict:
    """``results.json`` of the run (`pushjax.paper.runner`'s, one-step rows included) with ``horizon_rows`` (every
    model at every horizon on every test split) and ``expectations`` (`decide`).

    Args:
      outcome: the run of the ``rollouts`` setup (`pushjax.paper.runner.run`).
      sequences: test split label -> sequences (default: `load_sequences` of the run's spec).
      progress: called with a line per model and split.
    """
    sequences = load_sequences(outcome.spec) if sequences is None else sequences
    steps = max(sequence.steps for split in sequences.values() for sequence in split)
    rows = []
    for split, split_sequences in sequences.items():
        truths = [_com_and_yaw(s, s.poses) for s in split_sequences]
        rows += horizon_rows("zero", split, split_sequences, [np.broadcast_to(t[0], t.shape) for t in truths], None)
        for name, rollout in (("physics_long", physics_long), ("physics_chained", physics_chained)):
            rows += horizon_rows(name, split, split_sequences,
                                 [_com_and_yaw(s, rollout(s, steps=steps)) for s in split_sequences], None)
    scenes = Scenes(outcome.spec.test_dataset)
    try:
        for variant, seed, predictor in trained_predictors(outcome):
            for split, split_sequences in sequences.items():
                progress(f"rolling out {variant} seed {seed} on {split} ({len(split_sequences)} pushes)")
                tracks = (neural_rollouts(predictor, scenes, split_sequences) if variant == "neural"
                          else perceived_rollouts(predictor, scenes, split_sequences, steps))
                rows += horizon_rows(variant, split, split_sequences, tracks, seed)
    finally:
        scenes.close()
    results = {**outcome.results, "horizon_rows": rows, "step_s": STEP_S}
    results["expectations"] = decide(results)
    return results


def cell(results: Mapping, model: str, test_split: str, horizon: str,
         metric: str = statistics.SCORE) -> statistics.Estimate | None:
    """The `Estimate` of `metric` over the seeds of one model, split and horizon (None when absent)."""
    members = [row for row in results["horizon_rows"]
               if (row["model"], row["test_split"], row["horizon"]) == (model, test_split, horizon)]
    if not members:
        return None
    if metric in ("trans_mm", "rot_deg"):  # means per sequence: each row's bootstrap error and the seeds' spread
        values = [row[metric] for row in members]
        se_seeds = float(np.std(values, ddof=1) / math.sqrt(len(values))) if len(values) > 1 else None
        return statistics.Estimate(float(np.mean(values)), float(np.mean([row[f"{metric}_se"] for row in members])),
                                   se_seeds, tuple(values))
    return statistics.estimate(members, metric)


def _side(results: Mapping, test_split: str, side: Sequence[str]) -> statistics.Estimate | None:
    estimates = [cell(results, model, test_split, side[-1]) for model in side[:-1]]
    if any(estimate is None for estimate in estimates):
        return None
    return estimates[0] if len(estimates) == 1 else statistics.difference(*estimates)


def decide(results: Mapping) -> list[dict]:
    """Every `EXPECTATIONS` entry decided on the run: holds / does not hold / not decided (`pushjax.stats.decide`
    of the difference) / not checked (a model or horizon missing), with the difference better - worse."""
    decided = []
    for expectation in EXPECTATIONS:
        better, worse = (_side(results, expectation.test_split, side) for side in (expectation.better,
                                                                                   expectation.worse))
        entry = {"key": expectation.key, "statement": expectation.statement, "test_split": expectation.test_split}
        if better is None or worse is None:
            decided.append({**entry, "verdict": findings.UNCHECKED, "difference": None, "se": None})
            continue
        difference = statistics.difference(better, worse)
        decided.append({**entry, "verdict": stats.decide(difference.value, difference.se),
                        "difference": difference.value, "se": difference.se})
    return decided


def _splits(results: Mapping) -> list[str]:
    return list(dict.fromkeys(row["test_split"] for row in results["horizon_rows"]))


def _format(estimate: statistics.Estimate | None, digits: int = 1) -> str:
    if estimate is None:
        return "–"
    return f"{estimate.value:.{digits}f}" + (f" ± {estimate.se:.{digits}f}" if estimate.se is not None else "")


def markdown(results: Mapping) -> str:
    """The tables of the run: translation error (mm, and % of zero's) and rotation error (degrees) by horizon per
    test split, and the expectations' verdicts."""
    labels = horizon_labels()
    lines = [f"# Prediction over time ({results['config']['scale']} scale, seeds "
             f"{', '.join(map(str, results['config']['seeds']))})", "",
             f"Error of the motion since the push's start at each horizon, mean over pushes and seeds ± standard "
             f"error (sequence bootstrap and seeds). Steps of {results['step_s']:g} s; hybrid and error perceive the "
             "first image only and roll out their analytical part; neural sees the scene rendered at its own "
             "predicted pose at every step. – : no push of the split lasts that long.", ""]
    header = ["| model | " + " | ".join(labels) + " |", "|---|" + "---|" * len(labels)]
    for split in _splits(results):
        for metric, title in (("trans_mm", "translation error, mm"), ("trans_percent", "translation error, % of zero"),
                              ("rot_deg", "rotation error, degrees")):
            lines += [f"## {split}: {title}", "", *header]
            for model in MODELS:
                cells = [cell(results, model, split, label, metric) for label in labels]
                if any(estimate is not None for estimate in cells):
                    lines.append(f"| {model} | " + " | ".join(_format(estimate) for estimate in cells) + " |")
            lines.append("")
    lines += ["## Expectations (stated before the run, score = mean of translation and rotation % of zero, decided at "
              f"{stats.DECISION_STANDARD_ERRORS:g} standard errors of the paired difference)", "",
              "| expectation | split | better − worse | verdict |", "|---|---|---|---|"]
    for entry in results["expectations"]:
        difference = "–" if entry["difference"] is None else f"{entry['difference']:+.1f} ± {entry['se'] or 0:.1f}"
        lines.append(f"| {entry['key']}: {entry['statement']} | {entry['test_split']} | {difference} | "
                     f"{entry['verdict']} |")
    return "\n".join(lines) + "\n"


def plot(results: Mapping, path: str | os.PathLike) -> Path:
    """Translation error (mm) against the horizon, one panel per test split, a line per model."""
    splits = _splits(results)
    labels = horizon_labels()
    columns = min(4, len(splits))
    rows = math.ceil(len(splits) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(4 * columns, 3.4 * rows), squeeze=False)
    for axis, split in zip(axes.flat, splits):
        for model in MODELS:
            cells = [cell(results, model, split, label, "trans_mm") for label in labels]
            shown = [(k, c) for k, c in enumerate(cells) if c is not None]
            if shown:
                axis.errorbar([k for k, _ in shown], [c.value for _, c in shown], [c.se or 0.0 for _, c in shown],
                              marker="o", capsize=3, label=model)
        axis.set_xticks(range(len(labels)), labels, fontsize="small")
        axis.set_title(split)
        axis.set_ylabel("translation error [mm]")
    for axis in axes.flat[len(splits):]:
        axis.set_axis_off()
    axes.flat[0].legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return Path(path)


def write(results: dict, workdir: str | os.PathLike) -> list[Path]:
    """``results.json``, ``results.md`` and `FIGURE` in `workdir` (`pushjax.outputs.write_results`)."""
    return outputs.write_results(workdir, results, markdown(results), FIGURE, plot)
