"""Analytical physics models: the differentiable Lynch quasi-static pushing model and the exact limit surface."""

from pushjax.physics import effects, limit_surface, lynch

__all__ = ["effects", "limit_surface", "lynch"]
