"""Figs. 7-8 style plots: what each variant predicts for one push seen under many scene transforms.

The ``repeated`` dataset holds one push (`pushjax.data.configs.REPEATED_PUSH`) under random scene rotations
and translations. Rotating every prediction back by its example's ``scene_transform`` puts them all in the
frame of the recorded push, so a perfect model would put every point on the true one.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pushjax import planar
from pushjax.models import ERROR_OPTIONS
from pushjax.paper import runner
from pushjax.train import evaluate
from pushjax.train.batching import ModelSpec



def to_push_frame(vectors: np.ndarray, scene_transforms: np.ndarray) -> np.ndarray:
    """[N, 2] world-axis vectors rotated back by the inverse of [N, 3, 3] planar scene transforms."""
    return np.einsum("nji,nj->ni", scene_transforms[:, :2, :2], vectors)


def plot(predictions: Mapping[str, Mapping[str, np.ndarray]], examples: Mapping[str, np.ndarray],
         path: str | os.PathLike) -> Path:
    """A row per model: predicted object translations (mm) and predicted contacts with normals (mm).

    Args:
      predictions: row title (the model: variant, training size, seed) -> `evaluate.predict` outputs on
        `examples`.
      examples: the ``repeated`` test split, with ``scene_transform``.
      path: the PNG to write.
    """
    transforms = examples["scene_transform"]
    true_motion = to_push_frame(examples["motion"][:, :2], transforms) * planar.M_TO_MM
    true_contact = to_push_frame(examples["contact"], transforms) * planar.M_TO_MM
    true_normal = to_push_frame(examples["normal"], transforms)
    figure, axes = plt.subplots(len(predictions), 2, figsize=(9, 3.8 * len(predictions)), squeeze=False)
    for (title, outputs), (motion_axis, contact_axis) in zip(predictions.items(), axes):
        motion = to_push_frame(outputs["motion"][:, :2], transforms) * planar.M_TO_MM
        motion_axis.scatter(motion[:, 0], motion[:, 1], s=8, alpha=0.6, label="predicted")
        motion_axis.scatter(true_motion[:, 0], true_motion[:, 1], marker="*", color="k", s=60, label="true")
        motion_axis.set_title(f"{title}\nobject translation [mm]", fontsize="medium")
        motion_axis.set_aspect("equal", "datalim")
        if "contact" not in outputs:
            contact_axis.text(0.5, 0.5, "predicts no contact", ha="center", va="center",
                              transform=contact_axis.transAxes)
            contact_axis.set_axis_off()
        else:
            # Drawn only beside predictions: alone, the true points (equal up to rounding) would be autoscaled
            # to their rounding noise.
            contact_axis.scatter(true_contact[:, 0], true_contact[:, 1], marker="*", color="k", s=60, label="true")
            contact_axis.quiver(true_contact[:1, 0], true_contact[:1, 1], true_normal[:1, 0], true_normal[:1, 1],
                                color="k", width=0.006)
            contact = to_push_frame(outputs["contact"], transforms) * planar.M_TO_MM
            contact_axis.scatter(contact[:, 0], contact[:, 1], s=8, alpha=0.6, label="predicted")
            if "normal" in outputs:
                normal = to_push_frame(outputs["normal"], transforms)
                contact_axis.quiver(contact[:, 0], contact[:, 1], normal[:, 0], normal[:, 1], alpha=0.4,
                                    width=0.003)
        contact_axis.set_title(f"{title}\ncontact point and normal [mm]", fontsize="medium")
        contact_axis.set_aspect("equal", "datalim")
        motion_axis.legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return Path(path)


def largest_model(specs: Sequence[ModelSpec], variant: str) -> int:
    """Index of `variant`'s model with the most training examples in a sweep's `specs`, the first among equals
    (the lowest seed, as sweeps list them)."""
    candidates = [k for k, spec in enumerate(specs) if spec.variant in (None, variant)]
    return max(candidates, key=lambda k: len(specs[k].train_indices))


def plot_outcome(outcome: runner.RunOutcome, workdir: str | os.PathLike) -> Path:
    """Plots the predictions of each trained variant's model with the most training examples (the first seed
    among them) on the run's (one) test set.

    Writes and returns ``<workdir>/fig8_repeated_pushes.png``.
    """
    (examples,) = outcome.test_sets.values()
    predictions = {}
    for sweep in outcome.sweeps:
        result = sweep.result
        for variant in sweep.variants:
            k = largest_model(result.specs, variant)
            spec = result.specs[k]
            options = None if spec.variant is None else np.asarray(ERROR_OPTIONS[variant], np.float32)
            label = f"{variant} ({len(spec.train_indices)} examples, seed {spec.seed})"
            predictions[label] = evaluate.predict(result.model, result.model_state(k), examples,
                                                  outcome.spec.train.eval_batch_size, options)
    return plot(predictions, examples, Path(workdir) / "fig8_repeated_pushes.png")
