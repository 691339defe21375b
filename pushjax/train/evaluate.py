"""Evaluation in the paper's units (Kloss et al., Tables 1-2).

* ``trans_percent`` / ``rot_percent``: mean translation [mm] / rotation [deg] error as a percentage of
  the ``zero`` baseline's (predicting no motion) on the same examples, with standard errors ``*_se``.
  The windows of one push sequence are not independent (they share the object, the push and its
  unmodelled physics), so with the examples' ``sequence_id`` the standard error is a bootstrap over push
  sequences (`pushjax.stats.sequence_bootstrap_weights`: the ratio of summed errors to summed zero errors over
  resampled sequences, `pushjax.stats`), and the per-sequence sums are returned under ``sequences`` so that results can
  be averaged over seeds and compared pairwise on the same resamples (`pushjax.paper.statistics`).
  Without ``sequence_id``, or with a single sequence (the ``repeated`` push under many scene transforms), the
  examples count as independent.
* ``pos_mm``: object-position error [mm].
* Physical state errors of the hybrid, simple and error variants on examples with contact:
  ``contact_mm`` (contact point), ``normal_deg`` (surface normal), ``s`` (|s - contact flag|, all
  examples) and ``push_velocity_deg`` (effective push velocity v_p; from the predicted contact and
  normal through Lynch's stage 1 for hybrid / error, predicted directly by simple).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping

import jax
import numpy as np

from pushjax import planar
from pushjax.stats import SEQUENCE_RATIOS, bootstrap_replicates
from pushjax.models import PushModel
from pushjax.physics import lynch
from pushjax.train.batching import Examples, model_fields
from pushjax.train.train_state import TrainState


def predict(
    model: PushModel, state: TrainState, examples: Examples, batch_size: int,
    error_options: np.ndarray | None = None,
) -> dict[str, np.ndarray]:
    """Model outputs (eval mode: running batch statistics) for every example, as NumPy arrays.

    Args:
      model: the model.
      state: one model's `TrainState` (no model axis).
      examples: the split (schema fields).
      batch_size: examples per jitted call; the last batch is padded by repetition.
      error_options: the error-term flags of `PushModel.__call__`, or None for the variant's.
    """
    fields = model_fields(model.config)
    count = len(examples[fields[0]])
    variables = {"params": state.params, "batch_stats": state.batch_stats}
    chunks = []
    for start in range(0, count, batch_size):
        indices = np.minimum(np.arange(start, start + batch_size), count - 1)
        outputs = _apply_eval(model, variables, {name: examples[name][indices] for name in fields},
                              error_options)
        chunks.append(jax.tree.map(lambda x, n=min(batch_size, count - start): np.asarray(x)[:n], outputs))
    return {name: np.concatenate([chunk[name] for chunk in chunks]) for name in chunks[0]}


@functools.partial(jax.jit, static_argnames="model")
def _apply_eval(model: PushModel, variables, batch, error_options):
    # Module-level and keyed on the (hashable) model config, so every model, seed and test split
    # of a sweep shares one compilation.
    return model.apply(variables, batch, train=False, error_options=error_options)


def _angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cosine = np.sum(a * b, -1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def _sequence_sums(sequence_id: np.ndarray, **per_example: np.ndarray) -> dict[str, list]:
    """{"id": [S] sorted sequence ids, "count": [S] examples, name: [S] sums of each per-example array}."""
    ids, inverse = np.unique(np.asarray(sequence_id), return_inverse=True)
    sums = {"id": ids.tolist(), "count": np.bincount(inverse, minlength=len(ids)).tolist()}
    for name, values in per_example.items():
        sums[name] = np.bincount(inverse, weights=values, minlength=len(ids)).tolist()
    return sums


def _mean_and_se(values: np.ndarray) -> tuple[float, float]:
    if values.size == 0:
        return float("nan"), float("nan")
    se = values.std(ddof=1) / np.sqrt(values.size) if values.size > 1 else float("nan")
    return float(values.mean()), float(se)


def error_metrics(predictions: Mapping[str, np.ndarray], examples: Examples) -> dict:
    """Errors of `predictions` (outputs of `predict`) against the ground truth in `examples`.

    Args:
      predictions: {"motion": [N, 3] (m, m, rad), optionally "object_pos" [N, 2] m, "contact" [N, 2] m, "normal"
        [N, 2], "s" [N], "push_velocity" [N, 2]}.
      examples: the N examples (schema fields; ``sequence_id`` [N] makes the standard errors sequence bootstraps).

    Returns:
      {metric: float} as in the module docstring, and with ``sequence_id`` also ``sequences``: {"id", "count",
      "trans_mm", "rot_deg", "trans_zero_mm", "rot_zero_deg", with ``object_pos`` "pos_mm", and for each state
      metric the model predicts its sum and the count of the examples it is defined on ("contact_mm" and
      "contact_count", "normal_deg" and "normal_count", "s", "push_velocity_deg" and "push_velocity_count")}, each a
      list of per-sequence sums over the S sequences (mm, degrees); then every metric of `SEQUENCE_RATIOS` it has
      gets a sequence-bootstrap standard error ``<metric>_se`` (`bootstrap_replicates`); without, state metrics'
      ``_se`` treat the examples as independent.
    """
    true_motion = np.asarray(examples["motion"], np.float64)
    motion = np.asarray(predictions["motion"], np.float64)
    translation_error = np.linalg.norm(motion[:, :2] - true_motion[:, :2], axis=-1) * planar.M_TO_MM
    rotation_error = np.degrees(np.abs(motion[:, 2] - true_motion[:, 2]))
    zero_translation = np.linalg.norm(true_motion[:, :2], axis=-1).mean() * planar.M_TO_MM
    zero_rotation = np.degrees(np.abs(true_motion[:, 2])).mean()
    per_example = {"trans_mm": translation_error, "rot_deg": rotation_error,
                   "trans_zero_mm": np.linalg.norm(true_motion[:, :2], axis=-1) * planar.M_TO_MM,
                   "rot_zero_deg": np.degrees(np.abs(true_motion[:, 2]))}
    metrics = {"count": float(len(motion))}
    for name, error, baseline in (
        ("trans", translation_error, zero_translation), ("rot", rotation_error, zero_rotation)
    ):
        mean, se = _mean_and_se(error)
        metrics[f"{name}_{'mm' if name == 'trans' else 'deg'}"] = mean
        metrics[f"{name}_zero_{'mm' if name == 'trans' else 'deg'}"] = float(baseline)
        metrics[f"{name}_percent"] = 100 * mean / baseline
        metrics[f"{name}_percent_se"] = 100 * se / baseline
    if "object_pos" in predictions:
        per_example["pos_mm"] = np.linalg.norm(predictions["object_pos"] - examples["object_pos"], axis=-1) * planar.M_TO_MM
        metrics["pos_mm"], metrics["pos_mm_se"] = _mean_and_se(per_example["pos_mm"])
    touching = np.asarray(examples["contact_flag"]) > 0.5
    state_errors = {}  # metric -> ([N] per-example error, [N] bool: the example counts)
    if "contact" in predictions:
        state_errors["contact_mm"] = (
            np.linalg.norm(predictions["contact"] - examples["contact"], axis=-1) * planar.M_TO_MM, touching)
    if "normal" in predictions:
        valid = touching & (np.linalg.norm(predictions["normal"], axis=-1) > 0)
        angles = np.zeros(len(motion))
        angles[valid] = _angle_deg(predictions["normal"][valid], examples["normal"][valid])
        state_errors["normal_deg"] = (angles, valid)
    if "s" in predictions:
        state_errors["s"] = (np.abs(predictions["s"] - examples["contact_flag"]), np.ones(len(motion), bool))
    push_velocity = predictions.get("push_velocity")
    if push_velocity is None and "normal" in predictions:
        push_velocity = np.asarray(lynch.effective_push_velocity(
            predictions["contact"], predictions["normal"], examples["action"], examples["l"], examples["mu"]
        )[0])
    if push_velocity is not None:
        true_push_velocity = examples["push_velocity"]
        valid = (
            touching
            & (np.linalg.norm(push_velocity, axis=-1) > 0)
            & (np.linalg.norm(true_push_velocity, axis=-1) > 0)
        )
        angles = np.zeros(len(motion))
        angles[valid] = _angle_deg(push_velocity[valid], true_push_velocity[valid])
        state_errors["push_velocity_deg"] = (angles, valid)
    for name, (error, valid) in state_errors.items():
        metrics[name], metrics[f"{name}_se"] = _mean_and_se(np.asarray(error, np.float64)[valid])
        per_example[name] = np.where(valid, error, 0.0)
        if SEQUENCE_RATIOS[name][1] != "count":
            per_example[SEQUENCE_RATIOS[name][1]] = valid.astype(np.float64)
    if "sequence_id" in examples:
        sequences = _sequence_sums(examples["sequence_id"], **per_example)
        if len(sequences["id"]) > 1:
            for metric in SEQUENCE_RATIOS:
                if f"{metric}_se" in metrics:
                    with np.errstate(divide="ignore", invalid="ignore"):
                        metrics[f"{metric}_se"] = float(bootstrap_replicates(sequences, metric).std(ddof=1))
        metrics["sequences"] = sequences
    return metrics


def evaluate(
    model: PushModel, state: TrainState, examples: Examples, batch_size: int = 256,
    error_options: np.ndarray | None = None,
) -> dict:
    """`error_metrics` of one model's predictions on `examples` (arguments as in `predict`)."""
    return error_metrics(predict(model, state, examples, batch_size, error_options), examples)


def validation_errors(model: PushModel, state: TrainState, examples: Examples, batch_size: int,
                      error_options: np.ndarray | None = None) -> tuple[float, float]:
    """The translation and rotation errors in % of zero of one model on `examples` (arguments as in `predict`): the
    validation score of a `pushjax.train.convergence.Criterion` is their mean."""
    metrics = error_metrics(predict(model, state, examples, batch_size, error_options), examples)
    return float(metrics["trans_percent"]), float(metrics["rot_percent"])
