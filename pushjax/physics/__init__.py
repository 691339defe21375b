"""Analytical physics models: the differentiable Lynch quasi-static pushing model, the exact limit surface, rollouts."""

from pushjax.physics import effects, limit_surface, lynch, rollout

__all__ = ["effects", "limit_surface", "lynch", "rollout"]
