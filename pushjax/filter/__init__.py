"""Filters that track a pushed object's pose and infer latent physical parameters (pusher friction, limit-surface
ratio) from motion-capture poses, with the JAX rollout step as the process model: an extended (``ekf``) and an
unscented (``ukf``) Kalman filter (both also fuse a second stream of position readings, ``models.PositionSensor``,
e.g. a trained perception's: ``pushjax.sensing.perception``) and a particle filter (``particle``), sharing ``models``, and a
constant-velocity baseline (``constant_velocity``); ``metrics`` scores them (pose RMSE, NEES and its chi-square
band); ``noise`` learns the EKF's noise magnitudes through the differentiable filter; ``observations`` holds what
they are given about a push (``TrackedPush``, ``PositionStream``). The algorithms only, no MuJoCo: the study that runs
them on simulated testbed pushes is ``pushjax.studies.tracking``."""

from pushjax.filter import constant_velocity, ekf, metrics, models, noise, observations, particle, ukf

__all__ = ["constant_velocity", "ekf", "metrics", "models", "noise", "observations", "particle", "ukf"]
