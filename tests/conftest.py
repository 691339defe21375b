"""Test-wide setup: headless MuJoCo rendering and the optional ../shared reference data."""

import os
import pathlib

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")
# The tests compile hundreds of tiny programs once each, so compiling dominates their time; LLVM's cheapest
# optimisation level compiles faster and computes the same functions up to float rounding (set before anything
# imports jax; subprocesses inherit it).
if "--xla_backend_optimization_level" not in os.environ.get("XLA_FLAGS", ""):
    os.environ["XLA_FLAGS"] = f"{os.environ.get('XLA_FLAGS', '')} --xla_backend_optimization_level=0".strip()

SHARED = pathlib.Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared_dir() -> pathlib.Path:
    """The reference data folder beside the repository; tests that need it skip without it."""
    if not (SHARED / "data").is_dir():
        pytest.skip(f"reference data not found at {SHARED}")
    return SHARED
