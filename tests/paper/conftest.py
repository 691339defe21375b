"""Smoke runs of every experiment binary, each made once per session (on the suite's `smoke_data`).

The binary tests check the runs; the notebook tests render them.
"""

import functools
import importlib

import pytest
from absl import flags

SMOKE = ("--scale=smoke", "--num_steps=2")
RUNS = {
    # binary: (datasets it reads, its flags besides SMOKE, --workdir and --data_dir)
    "data_efficiency": (("data_efficiency",), ("--sizes=20,1000000", "--variants=hybrid,neural_dyn,zero,physics")),
    "new_pushes": (("new_pushes",), ("--sizes=50", "--variants=hybrid,zero")),
    "velocities": (("velocities",), ("--variants=hybrid,physics",)),
    "objects": (("objects",), ("--variants=hybrid,zero",)),
    "error_variants": (("data_efficiency",), ("--sizes=50", "--variants=error,error_grad,physics")),
    "viewpoint": (("viewpoint",), ("--sizes=50",)),
    "visualize": (("data_efficiency", "repeated"), ("--sizes=50", "--variants=hybrid,neural")),
}


def run_binary(name, *arguments):
    """Parses `arguments` as the command line of ``experiments.<name>`` and runs its ``main``."""
    module = importlib.import_module(f"experiments.{name}")
    flags.FLAGS.unparse_flags()
    try:
        flags.FLAGS(["test", *arguments])
        return module.main(["test"])
    finally:
        flags.FLAGS.unparse_flags()


@pytest.fixture(scope="session")
def smoke_results(smoke_data, tmp_path_factory):
    """binary name -> the work directory of its smoke run (run on first request); the parent holds them all."""
    results_dir = tmp_path_factory.mktemp("results")

    @functools.cache
    def run(name):
        experiments, arguments = RUNS[name]
        for experiment in experiments:
            smoke_data(experiment)
        workdir = results_dir / name
        run_binary(name, *SMOKE, f"--data_dir={smoke_data(experiments[0])}", f"--workdir={workdir}", *arguments)
        return workdir

    return run
