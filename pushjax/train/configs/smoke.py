"""Smoke scale: tiny networks that train in seconds on 2 CPU cores (tests, CI)."""

from pushjax.models import ModelConfig
from pushjax.train.configs.train_config import TrainConfig


def get_config() -> TrainConfig:
    model = ModelConfig(glimpse_features=(8, 8, 8), glimpse_kernel=3, locator_conv_features=(8, 8, 8, 8),
                        locator_deconv_features=(8, 8), head_features=(64, 32), error_features=(32, 16))
    return TrainConfig(model=model, learning_rate=1e-3, batch_size=16, num_steps=200, log_every=20,
                       checkpoint_every=50, eval_batch_size=64, curve_examples=64)
