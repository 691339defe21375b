"""Prediction errors as in Kloss et al.: translation (mm) and rotation (deg), absolute and as % of the
``zero`` baseline (predicting no motion), with a bootstrap over push sequences.
"""

from __future__ import annotations

import dataclasses

import numpy as np

METRIC_KEYS = ("trans_pct", "rot_pct", "trans_mm", "rot_deg")


@dataclasses.dataclass(frozen=True)
class WindowErrors:
    """Per-window errors of one model, all [N].

    Attributes:
      translation_mm: |predicted - measured| displacement of the nominal centre of mass, mm.
      rotation_deg: |predicted - measured| yaw change, deg.
      zero_translation_mm: the ``zero`` baseline's translation error (the measured displacement), mm.
      zero_rotation_deg: the ``zero`` baseline's rotation error, deg.
      sequence: push sequence index of each window.
    """

    translation_mm: np.ndarray
    rotation_deg: np.ndarray
    zero_translation_mm: np.ndarray
    zero_rotation_deg: np.ndarray
    sequence: np.ndarray


def window_errors(prediction: np.ndarray, target: np.ndarray, sequence: np.ndarray) -> WindowErrors:
    """Errors of [N, 3] predictions (dx m, dy m, dtheta rad) against [N, 3] targets."""
    prediction, target = np.asarray(prediction, np.float64), np.asarray(target, np.float64)
    return WindowErrors(
        translation_mm=1e3 * np.linalg.norm(prediction[:, :2] - target[:, :2], axis=1),
        rotation_deg=np.abs(np.degrees(prediction[:, 2] - target[:, 2])),
        zero_translation_mm=1e3 * np.linalg.norm(target[:, :2], axis=1),
        zero_rotation_deg=np.abs(np.degrees(target[:, 2])),
        sequence=np.asarray(sequence),
    )


def summarize(errors: WindowErrors) -> dict[str, float]:
    """{trans_pct, rot_pct, trans_mm, rot_deg}: mean errors, and their ratio to the zero baseline's in %."""
    return {
        "trans_pct": float(100 * errors.translation_mm.sum() / max(errors.zero_translation_mm.sum(), 1e-12)),
        "rot_pct": float(100 * errors.rotation_deg.sum() / max(errors.zero_rotation_deg.sum(), 1e-12)),
        "trans_mm": float(errors.translation_mm.mean()),
        "rot_deg": float(errors.rotation_deg.mean()),
    }


def combined(summary: dict[str, float]) -> float:
    """The selection score: translation + rotation error, each in % of the zero baseline."""
    return summary["trans_pct"] + summary["rot_pct"]


def bootstrap_combined(errors: list[WindowErrors], n_bootstrap: int = 1000, seed: int = 0) -> np.ndarray:
    """[B, M] combined scores of M models (same windows) on B resamplings of the push sequences.

    Sequences are drawn with replacement (counts from a multinomial), the same draws for every model,
    so differences between models are paired.
    """
    sequence = errors[0].sequence
    ids, index = np.unique(sequence, return_inverse=True)

    def per_sequence(values):
        return np.bincount(index, weights=values, minlength=len(ids))

    counts = np.random.default_rng(seed).multinomial(len(ids), np.full(len(ids), 1 / len(ids)), size=n_bootstrap)
    zero_t = counts @ per_sequence(errors[0].zero_translation_mm)
    zero_r = counts @ per_sequence(errors[0].zero_rotation_deg)
    scores = [100 * (counts @ per_sequence(e.translation_mm)) / np.maximum(zero_t, 1e-12)
              + 100 * (counts @ per_sequence(e.rotation_deg)) / np.maximum(zero_r, 1e-12) for e in errors]
    return np.stack(scores, axis=1)
