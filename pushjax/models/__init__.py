"""Flax models of Kloss et al.: perception (glimpse, object locator) and the prediction heads."""

from pushjax.models.config import VARIANTS, VIEWS, ModelConfig
from pushjax.models.heads import ERROR_OPTIONS, HEADS, MLP, PHYSICS_VARIANTS
from pushjax.models.networks import PushModel, count_parameters
from pushjax.models.perception import GlimpseEncoder, ObjectLocator, extract_glimpses, spatial_softmax

__all__ = [
    "ERROR_OPTIONS",
    "MLP",
    "PHYSICS_VARIANTS",
    "VARIANTS",
    "VIEWS",
    "GlimpseEncoder",
    "HEADS",
    "ModelConfig",
    "ObjectLocator",
    "PushModel",
    "count_parameters",
    "extract_glimpses",
    "spatial_softmax",
]
