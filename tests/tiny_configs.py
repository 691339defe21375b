"""The training config the unit tests of models and trainer run on.

The smoke scale's config (`pushjax.train.configs.smoke`) with a 12 px glimpse instead of the smoke dataset's
20 px: the tests' tolerances (e.g. vmapped against sequential training, where Adam amplifies float rounding of
near-zero gradients) were set on this model, which is also the cheaper one.
"""

import dataclasses

from pushjax.data import configs as data_configs
from pushjax.train.configs import get_config

_SMOKE = get_config(data_configs.get_config("data_efficiency", "smoke"))
TINY_SMOKE = dataclasses.replace(_SMOKE, model=dataclasses.replace(_SMOKE.model, glimpse_size=12))
