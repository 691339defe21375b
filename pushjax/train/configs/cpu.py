"""CPU scale: a reduced architecture and schedule that trains in tens of minutes on a laptop."""

from pushjax.models import ModelConfig
from pushjax.train.configs import TrainConfig


def get_config() -> TrainConfig:
    model = ModelConfig(glimpse_features=(16, 16, 8), glimpse_kernel=3, locator_conv_features=(8, 16, 16, 16),
                        locator_deconv_features=(16, 8), head_features=(256, 64), error_features=(128, 32))
    return TrainConfig(model=model, learning_rate=3e-4, batch_size=32, num_steps=5_000, log_every=50,
                       checkpoint_every=500, eval_batch_size=128)
