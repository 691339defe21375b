"""Paper scale (Kloss et al., Sec. V-B): Adam 1e-4, batch 32, 75 k steps.

With the paper-scale datasets' 80 x 80 px glimpses, the prediction part (glimpse encoder + FC stack) has about
1.8 M parameters, 2.7 M with the error term.
"""

from pushjax.models import ModelConfig
from pushjax.train.configs.train_config import TrainConfig


def get_config() -> TrainConfig:
    return TrainConfig(
        model=ModelConfig(), learning_rate=1e-4, batch_size=32, num_steps=75_000, log_every=100,
        checkpoint_every=5_000, eval_batch_size=256,
    )
