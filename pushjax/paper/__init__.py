"""The paper's experiments (Kloss, Schaal & Bohg) behind the binaries in ``experiments/``.

* `pushjax.paper.spec`: what each experiment runs (`SETUPS`) and the one resolved `ExperimentSpec` of a run.
* `pushjax.paper.runner`: a spec's run: train its variants in sweeps (`pushjax.train.sweep`), evaluate them and the
  baselines, write ``results.json``; `pushjax.paper.full_run`: the paper-composition run, one model at a time by a
  stopping rule of the same trainer.
* `pushjax.paper.baselines`: the ``zero`` and ``physics`` baselines.
* `pushjax.paper.tables` / `pushjax.paper.figures`: paper-style markdown tables and PNG figures.
* `pushjax.paper.findings`: which of the paper's qualitative findings hold.
* `pushjax.paper.visualize`: predictions on the repeated push (Figs. 7-8).
* `pushjax.paper.cli`: the binaries' shared absl flags and ``main``.

Submodules are imported explicitly so that reading results (tables, figures) does not load JAX or TFDS.
"""
