"""Test-wide setup: headless MuJoCo rendering, the smoke datasets and the optional ../shared reference data."""

import functools
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


@pytest.fixture(scope="session")
def smoke_data(tmp_path_factory):
    """experiment -> the TFDS data directory holding its smoke dataset (built on first request, once per session)."""
    from pushjax.data import testing

    data_dir = tmp_path_factory.mktemp("smoke_data")

    @functools.cache
    def build(experiment):
        testing.smoke_dataset(data_dir, experiment)
        return data_dir

    return build
