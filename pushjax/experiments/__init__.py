"""The paper's experiments behind ``experiments/*.py``.

* `pushjax.experiments.runner`: find or build a dataset, sweep-train variants, evaluate them and the baselines,
  write ``results.json``.
* `pushjax.experiments.baselines`: the ``zero`` and ``physics`` baselines.
* `pushjax.experiments.tables` / `pushjax.experiments.figures`: paper-style markdown tables and PNG figures.
* `pushjax.experiments.visualize`: predictions on the repeated push (Figs. 7-8).
* `pushjax.experiments.cli`: the binaries' shared absl flags and ``main``.

Submodules are imported explicitly so that reading results (tables, figures) does not load JAX or TFDS.
"""
