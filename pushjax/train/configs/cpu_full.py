"""``cpu_full`` scale (issue 30): the ``cpu`` architecture, trained by a convergence criterion.

Adam at a constant 10^-3 until the validation score stops improving (`pushjax.train.convergence.CRITERION`), then a
short cosine decay to 10^-5; `num_steps` is the budget's cap at the full split (the criterion's budget grows with the
training-set size). `pushjax.paper.full_run` trains with `pushjax.train.sweep` under that criterion.
"""

import dataclasses

from pushjax.train.configs import cpu
from pushjax.train.configs.train_config import TrainConfig


def get_config() -> TrainConfig:
    return dataclasses.replace(cpu.get_config(), schedule="constant", learning_rate=1e-3, num_steps=60_000,
                               checkpoint_every=1_000)
