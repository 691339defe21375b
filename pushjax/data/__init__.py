"""The TFDS push datasets: configurations, the example schema, examples cut from push sequences, the builder.

:mod:`~pushjax.data.configs` defines every dataset (experiment, scale, seed, testbed) and its split plan,
:mod:`~pushjax.data.schema` the fields of an example, :mod:`~pushjax.data.examples` cuts a recorded push sequence
into examples and :mod:`~pushjax.data.builder` simulates, renders and writes the datasets and reads them back.
The raw MIT file layout the sequences are cached in lives in :mod:`pushjax.mit`.
"""

from pushjax.data import builder, configs, examples, schema
from pushjax.data.builder import PushEffects, build, config_name, dataset_name, load
from pushjax.data.configs import (
    DEFAULT_SCALE,
    EXPERIMENTS,
    SCALES,
    DatasetConfig,
    SplitPlan,
    get_config,
    plan_splits,
)
from pushjax.data.examples import ALL_FIELDS, EXTRA_FIELDS, sequence_examples
from pushjax.data.schema import FIELDS, Field

__all__ = [
    "ALL_FIELDS",
    "DEFAULT_SCALE",
    "DatasetConfig",
    "EXPERIMENTS",
    "EXTRA_FIELDS",
    "FIELDS",
    "Field",
    "PushEffects",
    "SCALES",
    "SplitPlan",
    "build",
    "builder",
    "config_name",
    "configs",
    "dataset_name",
    "examples",
    "get_config",
    "load",
    "plan_splits",
    "schema",
    "sequence_examples",
]
