"""Smoke runs of every experiment binary, each made once per session (on the suite's `smoke_data`).

The binary tests check the runs; the notebook tests render them.
"""

import functools
import importlib

import pytest
from absl import flags

from tests.conftest import once_across_workers

SMOKE = ("--scale=smoke", "--num_steps=2")
TINY_CRITERION = "--criterion=eval_every=5;window=2;base_steps=10;steps_per_example=0;max_steps=10;min_decay_steps=2"
RUNS = {
    # binary: (datasets it reads, its flags besides SMOKE, --workdir and --data_dir)
    "data_efficiency_full": (("data_efficiency",), ("--sizes=40,80", "--side_sizes=80", "--seeds=0", "--nowide",
                                                    TINY_CRITERION)),
    "data_efficiency": (("data_efficiency",), ("--sizes=20,1000000", "--variants=hybrid,neural_dyn,zero,physics")),
    "new_pushes": (("new_pushes",), ("--sizes=50", "--variants=hybrid,zero")),
    "velocities": (("velocities",), ("--variants=hybrid,physics",)),
    "error_velocities": (("velocities",), ("--variants=error,error_norm,physics",)),
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
def smoke_results(smoke_data, shared_folder):
    """binary name -> the work directory of its smoke run (run once per test run, by whichever worker asks first);
    the parent holds them all."""
    results_dir = shared_folder / "results"
    results_dir.mkdir(exist_ok=True)

    @functools.cache
    def run(name):
        experiments, arguments = RUNS[name]
        for experiment in experiments:
            smoke_data(experiment)
        workdir = results_dir / name
        return once_across_workers(workdir, lambda: run_binary(
            name, *SMOKE, f"--data_dir={smoke_data(experiments[0])}", f"--workdir={workdir}", *arguments))

    return run
