import csv

import numpy as np

from pushjax.train.metrics_log import MetricsLog

NAMES = ["size=10/seed=0", "size=20/seed=0"]


def _rows(path):
    with path.open(newline="") as file:
        return list(csv.DictReader(file))


def _log_steps(log, steps):
    for step in steps:
        log.append(step, NAMES, {"loss": np.array([step, 2.0 * step]), "trans": np.array([1 / 3, 0.5])})


def test_one_row_per_step_and_model(tmp_path):
    path = tmp_path / "metrics.csv"
    _log_steps(MetricsLog(path, resume_step=0), [5, 10])
    rows = _rows(path)
    assert [(row["step"], row["model"], row["name"]) for row in rows] == [
        ("5", "0", NAMES[0]), ("5", "1", NAMES[1]), ("10", "0", NAMES[0]), ("10", "1", NAMES[1])
    ]
    assert list(rows[0]) == ["step", "model", "name", "loss", "trans"]
    assert rows[3]["loss"] == "20" and rows[0]["trans"] == "0.333333"  # 6 significant digits


def test_resume_drops_the_rows_after_the_restored_step(tmp_path):
    path = tmp_path / "metrics.csv"
    _log_steps(MetricsLog(path, resume_step=0), [5, 10, 15, 20, 25])  # killed after step 25
    resumed = MetricsLog(path, resume_step=20)  # the newest checkpoint is at step 20
    assert [int(row["step"]) for row in _rows(path)] == [5, 5, 10, 10, 15, 15, 20, 20]
    _log_steps(resumed, [25, 30])
    uninterrupted = tmp_path / "uninterrupted.csv"
    _log_steps(MetricsLog(uninterrupted, resume_step=0), [5, 10, 15, 20, 25, 30])
    assert path.read_text() == uninterrupted.read_text()  # one header, same rows


def test_a_fresh_run_replaces_an_old_log(tmp_path):
    path = tmp_path / "metrics.csv"
    _log_steps(MetricsLog(path, resume_step=0), [5, 10])
    MetricsLog(path, resume_step=0)
    assert not path.exists()
    _log_steps(MetricsLog(path, resume_step=0), [5])
    assert [int(row["step"]) for row in _rows(path)] == [5, 5]


def test_resume_before_the_first_logged_step_starts_a_new_file(tmp_path):
    path = tmp_path / "metrics.csv"
    _log_steps(MetricsLog(path, resume_step=0), [10])
    log = MetricsLog(path, resume_step=5)
    assert not path.exists()
    _log_steps(log, [10])
    assert [int(row["step"]) for row in _rows(path)] == [10, 10]
