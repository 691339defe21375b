import csv
import json

import numpy as np
import pytest
from absl import app, flags

from experiments import train as train_cli


def _run(*arguments):
    flags.FLAGS.unparse_flags()
    try:
        flags.FLAGS(["train", *arguments])
        return train_cli.main(["train"])
    finally:
        flags.FLAGS.unparse_flags()


def test_cli_trains_a_sweep_and_writes_results(smoke_data, tmp_path):
    data_dir = smoke_data("data_efficiency")
    exit_status = _run("--variant=hybrid", "--experiment=data_efficiency", "--scale=smoke", f"--workdir={tmp_path}",
                       "--sizes=100,200", "--seeds=0,1", "--num_steps=10", f"--data_dir={data_dir}", "--nobuild")
    assert exit_status is None  # app.run exits with main's return value: anything else is a failed run
    results = json.loads((tmp_path / "results.json").read_text())
    rows = results["rows"]
    assert [(row["train_size"], row["seed"]) for row in rows] == [(100, 0), (100, 1), (200, 0), (200, 1)]
    assert {row["steps"] for row in rows} == {10}
    for row in rows:
        for name in ("trans_percent", "trans_percent_se", "rot_percent", "pos_mm", "contact_mm",
                     "normal_deg", "s", "push_velocity_deg"):
            assert np.isfinite(row[name]), name
    with (tmp_path / "train" / "l1" / "hybrid" / "metrics.csv").open() as file:
        assert {int(row["step"]) for row in csv.DictReader(file)} == {10}


def test_mixing_error_variants_needs_an_error_variant(tmp_path):
    with pytest.raises(app.UsageError, match="mix_error_variants"):
        _run("--variant=hybrid", "--mix_error_variants", "--scale=smoke", f"--workdir={tmp_path}")
