"""Filters that track a pushed object's pose and infer latent physical parameters (pusher friction, limit-surface
ratio) from motion-capture poses, with the JAX rollout step as the process model: an extended (``ekf``) and an
unscented (``ukf``) Kalman filter and a particle filter (``particle``), sharing ``models``; ``metrics`` scores
them (pose RMSE, NEES and its chi-square band)."""

from pushjax.filter import ekf, metrics, models, particle, ukf

__all__ = ["ekf", "metrics", "models", "particle", "ukf"]
