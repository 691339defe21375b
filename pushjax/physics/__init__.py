"""Analytical physics models: the differentiable Lynch quasi-static pushing model."""

from pushjax.physics import effects, lynch, rollout

__all__ = ["effects", "lynch", "rollout"]
