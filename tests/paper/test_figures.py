"""The figures' legends name every line they draw."""

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
