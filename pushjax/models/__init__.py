"""Flax models of Kloss et al.: perception (glimpse, object locator) and the prediction heads."""

from pushjax.models.networks import (
    ERROR_OPTIONS,
    MLP,
    PHYSICS_VARIANTS,
    VARIANTS,
    VIEWS,
    ModelConfig,
    PushModel,
    count_parameters,
)
from pushjax.models.perception import GlimpseEncoder, ObjectLocator, extract_glimpses, spatial_softmax

__all__ = [
    "ERROR_OPTIONS",
    "MLP",
    "PHYSICS_VARIANTS",
    "VARIANTS",
    "VIEWS",
    "GlimpseEncoder",
    "ModelConfig",
    "ObjectLocator",
    "PushModel",
    "count_parameters",
    "extract_glimpses",
    "spatial_softmax",
]
