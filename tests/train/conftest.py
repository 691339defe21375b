"""The smoke datasets the training tests run on, built once per session."""

import pytest

from pushjax import train
from pushjax.data import load

FIELDS = ("depth", "point_cloud", *train.MODEL_INPUT_FIELDS, *train.EVALUATION_FIELDS)


def _examples(smoke_data, experiment):
    splits = load(experiment, "smoke", data_dir=smoke_data(experiment))
    return {name: train.examples_from_source(split, FIELDS) for name, split in splits.items()}


@pytest.fixture(scope="session")
def smoke(smoke_data):
    """split -> examples of the smoke ``data_efficiency`` dataset (top-down depth, 64 x 64)."""
    return _examples(smoke_data, "data_efficiency")


@pytest.fixture(scope="session")
def smoke_viewpoint(smoke_data):
    """split -> examples of the smoke ``viewpoint`` dataset (free camera, point clouds)."""
    return _examples(smoke_data, "viewpoint")


@pytest.fixture(scope="module")
def examples(smoke):
    """The training split of `smoke`."""
    return smoke["train"]
