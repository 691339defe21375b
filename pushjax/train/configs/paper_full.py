"""``paper_full`` scale (issue 30, part 4): ``cpu_full``'s training at the paper's widths.

The criterion-driven schedule of ``cpu_full`` (constant 10^-3 until the validation score stops improving, then a short
decay) with `pushjax.models.ModelConfig`'s defaults, the paper's widths: with the dataset's 80 x 80 px glimpses, about
1.8 M parameters in the prediction part. Only the images and the widths differ from ``cpu_full``'s models.
"""

import dataclasses

from pushjax.models import ModelConfig
from pushjax.train.configs import cpu_full
from pushjax.train.configs.train_config import TrainConfig


def get_config() -> TrainConfig:
    return dataclasses.replace(cpu_full.get_config(), model=ModelConfig())
