"""Test-wide setup: headless MuJoCo rendering, the smoke datasets and the optional ../shared reference data."""

import functools
import os
import pathlib
import subprocess
import sys

import filelock
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")

SHARED = pathlib.Path(__file__).resolve().parents[1].parent / "shared"


FAST_COMPILE_XLA_FLAG = "--xla_cpu_use_fusion_emitters=false"
"""XLA:CPU's older loop emitters instead of its fusion emitters: the same programs compile in about half the time
and run as fast (BENCHMARKS.md, "Build and test-suite timings"), and about half of the suite's CPU time is compilation."""


def _use_fast_compile_flag() -> None:
    """Adds :data:`FAST_COMPILE_XLA_FLAG` to ``XLA_FLAGS`` (which the workers and the tests' subprocesses inherit)
    where the installed jaxlib knows it: XLA aborts the process on a flag it does not know, and a later jaxlib may
    drop this one. Checked once, in the process that starts the workers."""
    flags = os.environ.get("XLA_FLAGS", "")
    if "xla_cpu_use_fusion_emitters" in flags or os.environ.get("PYTEST_XDIST_WORKER"):
        return
    probe = subprocess.run([sys.executable, "-c", "import jax; jax.numpy.zeros(1).block_until_ready()"],
                           env={**os.environ, "XLA_FLAGS": f"{flags} {FAST_COMPILE_XLA_FLAG}".strip(),
                                "JAX_PLATFORMS": "cpu"}, capture_output=True, timeout=120)
    if probe.returncode == 0:
        os.environ["XLA_FLAGS"] = f"{flags} {FAST_COMPILE_XLA_FLAG}".strip()


def pytest_configure(config):
    """XLA's faster-compiling CPU emitters (:func:`_use_fast_compile_flag`), and one persistent XLA compilation cache
    for every pytest-xdist worker (in pytest's cache folder), set before anything compiles: the loop's data sets compile the same fitting programs, the exact limit surface's in 10-20 s
    each, and without the cache every data set compiles them again. The tests' subprocesses (binaries, notebook
    kernels) get it through the environment, e.g. ``experiments.push_to_goal --scale=smoke`` the controller programs
    that tests/studies/test_episode.py compiles."""
    _use_fast_compile_flag()
    if getattr(config, "cache", None) is None:
        return
    import jax

    cache = os.environ.setdefault("JAX_COMPILATION_CACHE_DIR", str(config.cache.mkdir("xla_compilation_cache")))
    os.environ.setdefault("JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS", "1")
    jax.config.update("jax_compilation_cache_dir", cache)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", float(os.environ[
        "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS"]))


@pytest.fixture(scope="session")
def shared_dir() -> pathlib.Path:
    """The reference data folder beside the repository; tests that need it skip without it."""
    if not (SHARED / "data").is_dir():
        pytest.skip(f"reference data not found at {SHARED}")
    return SHARED


def _shared_folder(tmp_path_factory) -> pathlib.Path:
    """A folder all pytest-xdist workers of this run share (the parent of each worker's own base folder)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def once_across_workers(path: pathlib.Path, make) -> pathlib.Path:
    """Calls ``make()`` the first time any worker asks for `path` (under a file lock; a marker says it is done),
    so every worker reuses what one of them made."""
    with filelock.FileLock(f"{path}.lock"):
        done = path.with_name(f"{path.name}.done")
        if not done.exists():
            make()
            done.touch()
    return path


@pytest.fixture(scope="session")
def smoke_data(tmp_path_factory):
    """experiment -> the TFDS data directory holding its smoke dataset (built once per test run, by whichever
    worker asks first; the others wait for it and reuse it)."""
    from pushjax.data import testing

    data_dir = _shared_folder(tmp_path_factory) / "smoke_data"

    @functools.cache
    def build(experiment):
        # One lock for all experiments: their datasets share the raw push cache in `data_dir`.
        with filelock.FileLock(f"{data_dir}.lock"):
            done = data_dir / f".{experiment}.done"
            if not done.exists():
                testing.smoke_dataset(data_dir, experiment)
                done.touch()
        return data_dir

    return build


@pytest.fixture(scope="session")
def shared_folder(tmp_path_factory) -> pathlib.Path:
    """A folder all pytest-xdist workers of this run share (for results made once, see `once_across_workers`)."""
    return _shared_folder(tmp_path_factory)
