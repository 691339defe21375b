"""Small datasets for tests: build once into a directory, then read with ``tfds.data_source``.

In a pytest suite, build once per session::

    @pytest.fixture(scope="session")
    def smoke_source(tmp_path_factory):
        return pushjax.data.testing.smoke_dataset(tmp_path_factory.mktemp("data"))["train"]
"""

from __future__ import annotations

import os

from pushjax.data.builder import build, load
from pushjax.sim.testbed import DEFAULT_PROFILE


def smoke_dataset(directory: str | os.PathLike, experiment: str = "data_efficiency", seed: int = 0,
                  workers: int | None = 1, testbed: str = DEFAULT_PROFILE):
    """The ``smoke`` scale dataset of ``experiment`` (built under ``directory`` on first use, in seconds).

    Args:
      directory: TFDS data directory; also holds the raw sequence cache.
      experiment: one of ``pushjax.data.configs.EXPERIMENTS``.
      seed: dataset seed.
      workers: worker processes (default 1: build in this process, which is fastest at this size).
      testbed: testbed profile (``pushjax.sim.testbed.PROFILES``; default ``realistic``).

    Returns:
      split name -> ``tfds.data_source`` split (random access; elements are dicts of NumPy arrays).
    """
    build(experiment, "smoke", data_dir=directory, seed=seed, testbed=testbed, workers=workers, progress=False)
    return load(experiment, "smoke", data_dir=directory, seed=seed, testbed=testbed)
