"""Analytical physics models: the differentiable Lynch quasi-static pushing model."""

from pushjax.physics import effects, lynch

__all__ = ["effects", "lynch"]
