"""Seed aggregation and table layout of pushjax.paper.tables, on hand-made rows."""

import json
import math

import pytest

from pushjax.paper import reference, tables


def _row(model, size, seed, trans, trans_se):
    return {"model": model, "kind": "trained" if size else "baseline", "train_split": "train", "test_split": "test",
            "train_size": size, "seed": seed, "l_scale": 1.0, "trans_percent": trans, "trans_percent_se": trans_se,
            "rot_percent": 2 * trans, "rot_percent_se": None}


def test_aggregate_averages_seeds_and_combines_standard_errors():
    [row] = tables.aggregate([_row("hybrid", 100, 0, 10.0, 3.0), _row("hybrid", 100, 1, 20.0, 4.0)])
    assert row["seeds"] == [0, 1]
    assert row["trans_percent"] == pytest.approx(15.0)
    # Rows without per-sequence sums: their own errors stand for the test set's (one test set: averaged, not
    # shrunk), the seeds' spread is sd / sqrt(2) = 5.
    assert row["trans_percent_se_sequences"] == pytest.approx(3.5)
    assert row["trans_percent_se_seeds"] == pytest.approx(5.0)
    assert row["trans_percent_se"] == pytest.approx(math.hypot(3.5, 5.0))
    assert row["rot_percent_se_sequences"] is None and row["rot_percent_se"] == pytest.approx(10.0)


def test_the_convergence_table_counts_every_seed(tmp_path, monkeypatch):
    monkeypatch.setenv("PUSHJAX_PAPER_TABLES", str(tmp_path / "absent.json"))
    rows = [{**_row("neural", 2500, seed, 30.0, 1.0), "converged": seed == 1, "steps": steps}
            for seed, steps in ((0, 11000), (1, 9000), (2, 11000))]
    results = {"name": "data_efficiency_full", "rows": rows,
               "config": {"experiment": "data_efficiency", "scale": "cpu_full", "seeds": [0, 1, 2],
                          "criterion": {"window": 5, "eval_every": 1000, "min_improvement": 0.01}}}
    assert "| neural | 1/3 met, 10,333 steps |" in tables.markdown(results)


def test_pivot_table_repeats_baselines_in_every_size_column():
    rows = [_row("zero", None, None, 100.0, 1.0), _row("hybrid", 100, 0, 10.0, 1.0), _row("hybrid", 2500, 0, 5.0, 0.5)]
    table = tables.pivot_table(tables.aggregate(rows), ["model"], "train_size")
    assert "| model | train_size=100 | train_size=2500 |" in table
    assert "| zero | 100.0 ± 1.0 / 200.0 | 100.0 ± 1.0 / 200.0 |" in table
    assert "| hybrid | 10.0 ± 1.0 / 20.0 | 5.0 ± 0.5 / 10.0 |" in table


_PAPER = {"table1_data_efficiency": {"2500": {"hybrid": {"trans": [25.4, 0.17], "rot": [45.5, 0.36]}},
                                     "190000": {"hybrid": {"trans": [19.3, 0.13], "rot": [36.1, 0.3]}},
                                     "physics": {"trans": [18.95, 0.13], "rot": [35.4, 0.3]}},
          "table2_state_errors_190k": {"hybrid": {"contact_mm": [4.4, 0.01], "normal_deg": [3.6, 0.024]}}}


def _data_efficiency_results():
    rows = [_row("physics", None, None, 20.0, 1.0), _row("hybrid", 2500, 0, 30.0, 1.0),
            _row("hybrid", 19800, 0, 22.0, 1.0)]
    return {"name": "data_efficiency", "rows": rows,
            "config": {"experiment": "data_efficiency", "scale": "cpu", "testbed": "realistic", "seeds": [0]}}


def test_tables_put_the_papers_value_beside_ours(tmp_path, monkeypatch):
    paper = tmp_path / "paper_tables.json"
    paper.write_text(json.dumps(_PAPER))
    monkeypatch.setenv(reference.ENVIRONMENT_VARIABLE, str(paper))
    table = tables.markdown(_data_efficiency_results())
    assert "| model | train_size=2500 | paper | train_size=19800 | paper |" in table
    # Our largest size stands for the paper's 190 k; the baseline's paper value fills every column.
    assert "| hybrid | 30.0 ± 1.0 / 60.0 | 25.4 / 45.5 | 22.0 ± 1.0 / 44.0 | 19.3 / 36.1 |" in table
    assert "| physics | 20.0 ± 1.0 / 40.0 | 18.95 / 35.4 | 20.0 ± 1.0 / 40.0 | 18.95 / 35.4 |" in table
    assert "| hybrid | – | – | – | – | – | – / 4.4 / 3.6 / – / – |" in table


def test_tables_without_the_papers_file_have_no_paper_column(tmp_path, monkeypatch):
    monkeypatch.setenv(reference.ENVIRONMENT_VARIABLE, str(tmp_path / "absent.json"))
    assert reference.tables() == {}
    table = tables.markdown(_data_efficiency_results())
    assert "paper" not in table.replace("pushjax.paper", "")


def test_the_title_says_when_the_test_splits_were_grown():
    results = _data_efficiency_results()
    assert "grown" not in tables.markdown(results)
    results["config"]["test_dataset"] = {"experiment": "data_efficiency", "min_test_sequences": 150}
    assert tables.markdown(results).startswith(
        "# data_efficiency (data_efficiency dataset, cpu scale, realistic testbed, seeds [0]; "
        "test splits grown to at least 150 sequences)\n")


def _sequence_row(model, seed, trans_mm):
    """A trained row at 190 080 examples whose 4 test sequences each had a zero-motion error of 10 mm and 10°."""
    count = len(trans_mm)
    sequences = {"id": list(range(count)), "count": [1] * count, "trans_mm": trans_mm, "trans_zero_mm": [10.0] * count,
                 "rot_deg": [2 * value for value in trans_mm], "rot_zero_deg": [10.0] * count}
    trans = 10.0 * sum(trans_mm) / count
    return {**_row(model, 190080, seed, trans, 1.0), "rot_percent": 2 * trans, "sequences": sequences}


def test_the_widths_table_pairs_the_wide_models_with_their_twins():
    rows = [_sequence_row("neural", 0, [3.0, 2.0, 2.0, 1.0]), _sequence_row("hybrid", 0, [2.0, 2.0, 2.0, 2.0]),
            _sequence_row("neural", 1, [2.0, 2.0, 2.0, 2.0]), _sequence_row("hybrid", 1, [2.0, 2.0, 2.0, 2.0]),
            _sequence_row("neural_wide", 0, [4.0, 2.0, 2.0, 2.0]), _sequence_row("hybrid_wide", 0, [1.0] * 4)]
    table = tables.widths_table(rows)
    lines = {line.split(" | ")[0].removeprefix("| "): line for line in table.splitlines() if line.startswith("| ")}
    # neural_wide - neural: 25 - 20 % in translation, paired over the sequences.
    assert lines["neural_wide − neural"].startswith("| neural_wide − neural | 5.0 ± ")
    # neural − hybrid: 20 - 20 at our widths, 25 - 10 at the paper's widths; the change is their difference.
    assert lines["neural − hybrid, our widths (seed 0)"].startswith("| neural − hybrid, our widths (seed 0) | 0.0 ± ")
    assert "widths (seed 0) | 15.0 ± " in lines["neural − hybrid, the paper's widths (seed 0)"]
    assert "(paper's − ours) | 15.0 ± " in lines["change of neural − hybrid (paper's − ours)"]
    assert tables.widths_table([row for row in rows if not row["model"].endswith("_wide")]) == ""
