"""The smoke datasets the training tests run on, built once per session."""

import pytest

from pushjax import train

FIELDS = ("depth", "point_cloud", *train.MODEL_INPUT_FIELDS, *train.EVALUATION_FIELDS)


@pytest.fixture(scope="session")
def data_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("data")


def _examples(data_dir, experiment):
    from pushjax.data import testing

    splits = testing.smoke_dataset(data_dir, experiment)
    return {name: train.examples_from_source(split, FIELDS) for name, split in splits.items()}


@pytest.fixture(scope="session")
def smoke(data_dir):
    """split -> examples of the smoke ``data_efficiency`` dataset (top-down depth, 64 x 64)."""
    return _examples(data_dir, "data_efficiency")


@pytest.fixture(scope="session")
def smoke_viewpoint(data_dir):
    """split -> examples of the smoke ``viewpoint`` dataset (free camera, point clouds)."""
    return _examples(data_dir, "viewpoint")


@pytest.fixture(scope="module")
def examples(smoke):
    """The training split of `smoke`."""
    return smoke["train"]
