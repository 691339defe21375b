"""Test-wide setup: headless MuJoCo rendering and the optional ../shared reference data."""

import os
import pathlib

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")

SHARED = pathlib.Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared_dir() -> pathlib.Path:
    """The reference data folder beside the repository; tests that need it skip without it."""
    if not (SHARED / "data").is_dir():
        pytest.skip(f"reference data not found at {SHARED}")
    return SHARED
