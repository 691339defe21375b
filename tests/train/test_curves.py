"""Learning curves (pushjax.train.curves): written at every checkpoint, resumed to the same file."""

import dataclasses

import numpy as np

from pushjax import train
from pushjax.models import PushModel
from pushjax.train import curves
from tests.tiny_configs import TINY_SMOKE


def _sweep(config, examples, validation, workdir):
    specs = train.subset_specs(len(examples["motion"]), [100], [0])
    learning_curves = curves.LearningCurves(workdir / "curves.csv", PushModel(config.model), specs, examples,
                                            {"validation": validation}, max_examples=32, batch_size=32)
    return train.sweep(config, examples, specs, workdir, mode="sequential", progress=False,
                       checkpoint_callback=learning_curves)


def test_curves_at_every_checkpoint_and_resume_to_the_same_file(smoke, tmp_path):
    # TINY_SMOKE's learning rate: the single-model step the other hybrid sweeps of tests/train compile (predictor,
    # tensorboard, the mesh and 2-process references), one program for all; the errors fall by a fifth in 40 steps.
    config = dataclasses.replace(TINY_SMOKE.with_variant("hybrid"), num_steps=40, checkpoint_every=20, log_every=20)
    examples, validation = smoke["train"], smoke["validation"]
    _sweep(config, examples, validation, tmp_path / "whole")
    rows = curves.read(tmp_path / "whole" / "curves.csv")
    assert sorted({row["step"] for row in rows}) == [0, 20, 40]
    assert {(row["model"], row["split"]) for row in rows} == {(0, "train"), (0, "validation")}
    assert all(np.isfinite(row["trans_percent"]) and row["rot_percent"] > 0 for row in rows)
    first = {(row["model"], row["split"]): row["trans_percent"] for row in rows if row["step"] == 0}
    last = {(row["model"], row["split"]): row["trans_percent"] for row in rows if row["step"] == 40}
    assert np.mean([last[key] for key in last]) < np.mean([first[key] for key in first])

    _sweep(dataclasses.replace(config, num_steps=20), examples, validation, tmp_path / "resumed")
    _sweep(config, examples, validation, tmp_path / "resumed")
    assert (tmp_path / "resumed" / "curves.csv").read_text() == (tmp_path / "whole" / "curves.csv").read_text()
