"""Studies: harnesses and experiments that compose the layers below (the controller, the filters, the testbed and the
loop) into one question.

:mod:`~pushjax.studies.episode`: a controller closed on the MuJoCo testbed (one goal); :mod:`~pushjax.studies.tracking`:
the filters on simulated testbed pushes (``python -m experiments.track``); :mod:`~pushjax.studies.push_to_goal`: every
model and planner pushed to goals, and its report (``python -m experiments.push_to_goal``);
:mod:`~pushjax.studies.worlds`: worlds with one undeclared effect and their oracles; :mod:`~pushjax.studies.adapt`:
the controller learns from its own pushes (``python -m experiments.adapt``), a frozen, validated config whose scales are
defined once (``SCALES``), ``run(config, workdir) -> results`` and ``write(results, workdir)``, its binary in
``experiments/`` flags -> config -> run -> write.
"""
