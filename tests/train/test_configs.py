"""Training configs: one per dataset scale, imported explicitly (no string imports the layer test cannot see)."""

from pushjax.data.configs import SCALES, get_config as dataset_config
from pushjax.train import configs


def test_every_dataset_scale_has_its_training_config():
    assert tuple(configs.SCALE_CONFIGS) == SCALES
    for scale in SCALES:
        config = configs.get_config(dataset_config("data_efficiency", scale))
        assert config == configs.override(configs.SCALE_CONFIGS[scale](), {
            "model.glimpse_size": str(config.model.glimpse_size)})
