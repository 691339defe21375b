"""The figures' legends name every line they draw."""

import json

import pytest

from pushjax.paper import figures


def _curve_rows(train_splits, l_scales, sizes=(100,), seeds=(0, 1)):
    return [{"model": "hybrid", "train_split": train_split, "train_size": size, "seed": seed, "l_scale": l_scale,
             "step": step, "split": "train", "trans_percent": 50.0 / step, "rot_percent": 80.0 / step}
            for train_split in train_splits for l_scale in l_scales for size in sizes for seed in seeds
            for step in (1, 2, 3)]


def _legend_of_curves_figure(curves, tmp_path, monkeypatch) -> list[str]:
    drawn = []
    monkeypatch.setattr(figures.plt, "close", drawn.append)
    assert figures.curves_figure(curves, tmp_path / "curves.png").stat().st_size > 0
    [figure] = drawn
    return [text.get_text() for text in figure.axes[0].get_legend().get_texts()]


@pytest.mark.parametrize("train_splits, l_scales, expected", [
    (("train",), (1.0,), ["100 examples, train", "1,000 examples, train"]),
    (("train_20", "train_20_50"), (1.0,), ["train_20, 100 examples, train", "train_20, 1,000 examples, train",
                                          "train_20_50, 100 examples, train", "train_20_50, 1,000 examples, train"]),
    (("train",), (1.0, 3.0), ["100 examples, l x1, train", "100 examples, l x3, train", "1,000 examples, l x1, train",
                              "1,000 examples, l x3, train"]),
])
def test_learning_curves_name_the_training_split_and_l_where_they_vary(train_splits, l_scales, expected, tmp_path,
                                                                        monkeypatch):
    legend = _legend_of_curves_figure(_curve_rows(train_splits, l_scales, sizes=(100, 1000)), tmp_path, monkeypatch)
    assert sorted(legend) == sorted(expected)


def test_fig5_of_the_full_run_shows_the_papers_end_points(tmp_path, monkeypatch):
    tables_file = tmp_path / "paper_tables.json"
    tables_file.write_text(json.dumps({"table1_data_efficiency": {
        "2500": {"neural": {"trans": [33.6, 0.2], "rot": [62.5, 0.4]}},
        "190000": {"neural": {"trans": [17.4, 0.1], "rot": [33.4, 0.3]}}}}))
    monkeypatch.setenv("PUSHJAX_PAPER_TABLES", str(tables_file))
    assert figures.paper_table1_points() == {"neural": [(2500.0, {"trans_percent": 33.6, "rot_percent": 62.5}),
                                                        (190000.0, {"trans_percent": 17.4, "rot_percent": 33.4})]}
    rows = [{"model": "neural", "kind": "trained", "train_split": "train", "test_split": "test", "train_size": size,
             "seed": 0, "l_scale": 1.0, "trans_percent": 30.0, "rot_percent": 50.0} for size in (2500, 20000)]
    drawn = []
    monkeypatch.setattr(figures.plt, "close", drawn.append)
    figures.plot({"name": "data_efficiency_full", "rows": rows}, tmp_path)
    labels = drawn[0].axes[0].get_legend_handles_labels()[1]
    assert sorted(labels) == ["neural", "neural (paper)"]
    assert [tick.get_text() for tick in drawn[0].axes[0].get_xticklabels()] == ["2.5k", "20k", "190k"]


def test_log_ticks_merge_sizes_within_five_percent():
    assert figures._log_ticks({2500.0, 190080.0, 190000.0, 500.0}) == ([500.0, 2500.0, 190000.0],
                                                                       ["500", "2.5k", "190k"])
