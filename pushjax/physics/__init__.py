"""Analytical physics models: the differentiable Lynch quasi-static pushing model."""

from pushjax.physics import lynch

__all__ = ["lynch"]
