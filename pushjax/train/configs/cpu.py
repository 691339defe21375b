"""CPU scale: a reduced architecture and schedule that trains on a laptop.

Adam from 10^-3 with a cosine decay over 10 000 steps (the paper: a constant 10^-4 for 75 000 steps): with 5 000
steps at a constant 3 * 10^-4, `neural` at the largest size still underfitted (its training error equalled its
test error); the learning curves in RESULTS.md show where this schedule ends.
"""

from pushjax.models import ModelConfig
from pushjax.train.configs.train_config import TrainConfig


def get_config() -> TrainConfig:
    model = ModelConfig(glimpse_features=(16, 16, 8), glimpse_kernel=3, locator_conv_features=(8, 16, 16, 16),
                        locator_deconv_features=(16, 8), head_features=(256, 64), error_features=(128, 32))
    return TrainConfig(model=model, learning_rate=1e-3, schedule="cosine", batch_size=32,
                       num_steps=10_000, log_every=50, checkpoint_every=500, eval_batch_size=128, curve_examples=1024)
