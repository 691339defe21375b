"""Training configs: one per dataset scale, imported explicitly (no string imports the layer test cannot see)."""

import dataclasses

from pushjax.data.configs import SCALES, get_config as dataset_config
from pushjax.models import ModelConfig
from pushjax.train import configs


def test_every_dataset_scale_has_its_training_config():
    assert tuple(configs.SCALE_CONFIGS) == SCALES
    for scale in SCALES:
        config = configs.get_config(dataset_config("data_efficiency", scale))
        assert config == configs.override(configs.SCALE_CONFIGS[scale](), {
            "model.glimpse_size": str(config.model.glimpse_size)})


def test_paper_full_trains_as_cpu_full_at_the_papers_widths():
    cpu_full, paper_full = (configs.get_config(dataset_config("data_efficiency", scale))
                            for scale in ("cpu_full", "paper_full"))
    assert dataclasses.replace(paper_full, model=cpu_full.model) == cpu_full
    assert paper_full.model == dataclasses.replace(ModelConfig(), glimpse_size=80)
