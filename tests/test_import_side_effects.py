"""Importing pushjax changes nothing global, and reading results loads neither JAX nor TFDS nor MuJoCo."""

import os
import subprocess
import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]


def _run(script: str, **env: str) -> subprocess.CompletedProcess:
    clean = {key: value for key, value in os.environ.items() if key not in ("MUJOCO_GL", "MPLBACKEND")}
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPOSITORY,
                          env={**clean, "PYTHONPATH": str(REPOSITORY), **env})


def test_reading_and_tabulating_results_imports_no_jax_tfds_or_mujoco():
    script = ("import sys\n"
              "import pushjax.paper.tables, pushjax.paper.figures, pushjax.paper.findings, pushjax.paper.reference\n"
              "loaded = [name for name in ('jax', 'tensorflow_datasets', 'mujoco', 'tensorflow') if name in sys.modules]\n"
              "assert not loaded, loaded")
    result = _run(script)
    assert result.returncode == 0, result.stderr[-2000:]


def test_importing_every_module_sets_no_mujoco_gl_and_no_matplotlib_backend():
    script = ("import importlib, os, pkgutil, matplotlib, pushjax\n"
              "for module in pkgutil.walk_packages(pushjax.__path__, 'pushjax.'):\n"
              "    importlib.import_module(module.name)\n"
              "assert 'MUJOCO_GL' not in os.environ, os.environ['MUJOCO_GL']\n"
              "assert matplotlib.get_backend() == 'svg', matplotlib.get_backend()")
    result = _run(script, MPLBACKEND="svg")
    assert result.returncode == 0, result.stderr[-2000:]
