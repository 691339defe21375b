"""Figs. 7-8 style plots: what each variant predicts for one push seen under many scene transforms.

The ``repeated`` dataset holds one push (`pushjax.data.configs.REPEATED_PUSH`) under random scene rotations
and translations. Rotating every prediction back by its example's ``scene_transform`` puts them all in the
frame of the recorded push, so a perfect model would put every point on the true one.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from pushjax import data  # noqa: E402
from pushjax.experiments import runner, tables  # noqa: E402
from pushjax.models import VARIANTS  # noqa: E402
from pushjax.train import evaluate, train  # noqa: E402

DEFAULT_VARIANTS = ("neural", "hybrid", "simple", "error")
M_TO_MM = 1000.0


def to_push_frame(vectors: np.ndarray, scene_transforms: np.ndarray) -> np.ndarray:
    """[N, 2] world-axis vectors rotated back by the inverse of [N, 3, 3] planar scene transforms."""
    return np.einsum("nji,nj->ni", scene_transforms[:, :2, :2], vectors)


def plot(predictions: Mapping[str, Mapping[str, np.ndarray]], examples: Mapping[str, np.ndarray],
         path: str | os.PathLike) -> Path:
    """A row per variant: predicted object translations (mm) and predicted contacts with normals (mm).

    Args:
      predictions: variant -> `evaluate.predict` outputs on `examples`.
      examples: the ``repeated`` test split, with ``scene_transform``.
      path: the PNG to write.
    """
    transforms = examples["scene_transform"]
    true_motion = to_push_frame(examples["motion"][:, :2], transforms) * M_TO_MM
    true_contact = to_push_frame(examples["contact"], transforms) * M_TO_MM
    true_normal = to_push_frame(examples["normal"], transforms)
    figure, axes = plt.subplots(len(predictions), 2, figsize=(9, 3.8 * len(predictions)), squeeze=False)
    for (variant, outputs), (motion_axis, contact_axis) in zip(predictions.items(), axes):
        motion = to_push_frame(outputs["motion"][:, :2], transforms) * M_TO_MM
        motion_axis.scatter(motion[:, 0], motion[:, 1], s=8, alpha=0.6, label="predicted")
        motion_axis.scatter(true_motion[:, 0], true_motion[:, 1], marker="*", color="k", s=60, label="true")
        motion_axis.set_title(f"{variant}: object translation [mm]")
        motion_axis.set_aspect("equal", "datalim")
        contact_axis.scatter(true_contact[:, 0], true_contact[:, 1], marker="*", color="k", s=60, label="true")
        contact_axis.quiver(true_contact[:1, 0], true_contact[:1, 1], true_normal[:1, 0], true_normal[:1, 1],
                            color="k", width=0.006)
        if "contact" not in outputs:
            contact_axis.text(0.5, 0.5, f"{variant} predicts no contact", ha="center", va="center",
                              transform=contact_axis.transAxes)
            contact_axis.set_axis_off()
        else:
            contact = to_push_frame(outputs["contact"], transforms) * M_TO_MM
            contact_axis.scatter(contact[:, 0], contact[:, 1], s=8, alpha=0.6, label="predicted")
            if "normal" in outputs:
                normal = to_push_frame(outputs["normal"], transforms)
                contact_axis.quiver(contact[:, 0], contact[:, 1], normal[:, 0], normal[:, 1], alpha=0.4,
                                    width=0.003)
        contact_axis.set_title(f"{variant}: contact point and normal [mm]")
        contact_axis.set_aspect("equal", "datalim")
        motion_axis.legend(fontsize="small")
    figure.tight_layout()
    figure.savefig(path, dpi=100)
    plt.close(figure)
    return Path(path)


def run(workdir: str | os.PathLike, scale: str, *, variants: Sequence[str] = DEFAULT_VARIANTS,
        sizes: Sequence[int] = (), seeds: Sequence[int] = (0,), num_steps: int | None = None,
        data_dir: str | os.PathLike | None = None, build: bool = True, workers: int | None = None,
        mode: str | None = None, progress: bool = True) -> dict:
    """Trains `variants` on ``data_efficiency`` and plots their predictions on the ``repeated`` pushes.

    Arguments as in `runner.run`; one model per variant (the first of `sizes` and `seeds`). Writes
    ``<workdir>/fig8_repeated_pushes.png``, ``results.json`` (errors on the repeated pushes, as `runner.run`'s
    rows) and ``results.md``, and returns the results.
    """
    variants = runner.parse_models(variants, VARIANTS)
    sizes, seeds = runner.parse_sizes(sizes), runner.parse_seeds(seeds)
    dataset_config = data.get_config("data_efficiency", scale)
    train_splits = runner.load_splits("data_efficiency", scale, data_dir, build=build, workers=workers,
                                      progress=progress)
    repeated = runner.load_splits("repeated", scale, data_dir, build=build, workers=workers, progress=progress)
    workdir = Path(workdir)
    predictions, rows = {}, []
    for variant in variants:
        config = runner.make_train_config(scale, variant, dataset_config, num_steps)
        fields = runner.example_fields(config)
        train_examples = train.examples_from_source(train_splits["train"], fields)
        test_examples = train.examples_from_source(repeated["test"], (*fields, "scene_transform"))
        count = len(train_examples["motion"])
        size = runner.clip_sizes(sizes[:1], count)[0]
        specs = train.subset_specs(count, [size], [seeds[0]], (None,))
        result = train.sweep(config, train_examples, specs, workdir / variant, mode=mode or runner.default_mode(),
                             progress=progress)
        predictions[variant] = evaluate.predict(result.model, result.model_state(0), test_examples,
                                                config.eval_batch_size)
        rows.append({"model": variant, "kind": "trained", "train_split": "train", "test_split": "repeated",
                     "train_size": size, "seed": seeds[0], "l_scale": 1.0,
                     **evaluate.error_metrics(predictions[variant], test_examples)})
    plot(predictions, test_examples, workdir / "fig8_repeated_pushes.png")
    results = {
        "name": "visualize",
        "config": {"experiment": "repeated", "train_experiment": "data_efficiency", "scale": scale,
                   "variants": list(variants), "sizes": list(sizes), "seeds": list(seeds),
                   "num_steps": config.num_steps, "mode": mode or runner.default_mode(),
                   "data_dir": None if data_dir is None else str(data_dir),
                   "dataset": dataclasses.asdict(data.get_config("repeated", scale)),
                   "train": runner.train_config_dict(config)},
        "rows": [runner.finite_or_none(row) for row in rows],
    }
    (workdir / "results.json").write_text(json.dumps(results, indent=2))
    tables.write(results, workdir)
    return results
