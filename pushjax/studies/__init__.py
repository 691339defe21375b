"""Studies: experiments that compose the layers below (the controller, the testbed and the loop) into one question.

Each study is a module with a frozen, validated config whose scales are defined once (``SCALES``), ``run(config,
workdir) -> results`` and ``write(results, workdir)``; its binary in ``experiments/`` is flags -> config -> run ->
write. :mod:`~pushjax.studies.adapt`: the controller learns from its own pushes (``python -m experiments.adapt``).
"""
