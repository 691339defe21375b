import csv
import json

import numpy as np

from experiments import train as train_cli


def test_cli_trains_a_sweep_and_writes_results(smoke, data_dir, tmp_path):
    del smoke  # builds the dataset under data_dir
    results = train_cli.train_experiment(
        "hybrid", "data_efficiency", "smoke", tmp_path, sizes=[100, 200], seeds=[0, 1], num_steps=10,
        data_dir=data_dir, progress=False,
    )
    assert [row["name"] for row in results] == [
        "size=100/seed=0", "size=100/seed=1", "size=200/seed=0", "size=200/seed=1"
    ]
    assert json.loads((tmp_path / "results.json").read_text()) == results
    for row in results:
        for name in ("trans_percent", "trans_percent_se", "rot_percent", "pos_mm", "contact_mm",
                     "normal_deg", "s", "push_velocity_deg"):
            assert np.isfinite(row[name]), name
    with (tmp_path / "metrics.csv").open() as file:
        assert {int(row["step"]) for row in csv.DictReader(file)} == {10}
