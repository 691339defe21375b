"""Fallback: a learned error-correction term on top of the (augmented) analytical model.

Like the ``error`` variant of Kloss et al., a small MLP maps the model's inputs to a correction that is
added to the model's prediction. Everything is expressed in the object frame (the inputs turned by
``-object_yaw``, the correction turned back), so the term does not have to learn the symmetry of the
table plane. The last layer starts at zero, so the untrained term is "no correction". It is trained
with Adam on the same loss as the effects (:mod:`pushjax.loop.fit`) and early-stopped on a fifth of
the fit push sequences.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Sequence

import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np
import optax

from pushjax import planar
from pushjax.loop.fit import PAD_MULTIPLE, zero_scales
from pushjax.loop.windows import Examples, split_by_sequence


class ErrorTerm(nn.Module):
    """MLP from standardised features [..., F] to a correction [..., 3] in units of the zero baseline."""

    hidden: Sequence[int] = (64, 64)

    @nn.compact
    def __call__(self, features: jax.Array) -> jax.Array:
        x = features
        for width in self.hidden:
            x = nn.gelu(nn.Dense(width)(x))
        return nn.Dense(3, kernel_init=nn.initializers.zeros)(x)


@dataclasses.dataclass(frozen=True)
class CorrectionSettings:
    """Training settings: Adam ``steps`` (full batch) at ``learning_rate`` with ``weight_decay``,
    validation every ``eval_every`` steps, ``hidden`` layer widths."""

    steps: int = 2000
    learning_rate: float = 3e-3
    weight_decay: float = 1e-4
    eval_every: int = 100
    hidden: tuple[int, ...] = (64, 64)


@dataclasses.dataclass(frozen=True)
class ErrorCorrection:
    """A trained error term.

    Attributes:
      params: the MLP's parameters.
      mean, std: [F] feature standardisation.
      scales: (m, rad) output units.
      hidden: layer widths.
    """

    params: dict
    mean: np.ndarray
    std: np.ndarray
    scales: tuple[float, float]
    hidden: tuple[int, ...]

    def __call__(self, examples: Examples, prediction: np.ndarray) -> np.ndarray:
        """[N, 3] corrected predictions of the model's [N, 3] ``prediction`` on ``examples``."""
        features = (_features(examples, prediction) - self.mean) / self.std
        correction = np.asarray(ErrorTerm(self.hidden).apply({"params": self.params}, jnp.asarray(features, jnp.float32)))
        return _add(examples, prediction, correction, self.scales)


def _features(examples: Examples, prediction: np.ndarray) -> np.ndarray:
    inputs = examples.inputs
    yaw = np.asarray(inputs.object_yaw, np.float64)
    prediction = np.asarray(prediction, np.float64)
    return np.column_stack([
        planar.rotate(np.asarray(inputs.contact), -yaw), planar.rotate(np.asarray(inputs.normal), -yaw),
        planar.rotate(np.asarray(inputs.action), -yaw), planar.rotate(np.asarray(inputs.pusher_motion), -yaw),
        inputs.gap, inputs.l, inputs.mu, inputs.s, inputs.push_speed, inputs.time_after_stop,
        planar.rotate(prediction[:, :2], -yaw), prediction[:, 2],
    ])


def _add(examples: Examples, prediction: np.ndarray, correction: np.ndarray, scales) -> np.ndarray:
    yaw = np.asarray(examples.inputs.object_yaw, np.float64)
    translation = planar.rotate(scales[0] * correction[:, :2], yaw)
    return np.asarray(prediction, np.float64) + np.column_stack([translation, scales[1] * correction[:, 2]])


def fit_error_correction(
    fit: Examples,
    prediction: np.ndarray,
    settings: CorrectionSettings = CorrectionSettings(),
    seed: int = 0,
) -> ErrorCorrection:
    """Trains the error term on ``fit`` examples given the model's [N, 3] ``prediction`` on them."""
    train_mask = ~np.isin(fit.sequence, np.unique(split_by_sequence(fit, 0.2, seed)[1].sequence))
    features = _features(fit, prediction)
    mean = features[train_mask].mean(axis=0)
    std = np.maximum(features[train_mask].std(axis=0), 1e-9)
    scales = zero_scales(fit)
    yaw = np.asarray(fit.inputs.object_yaw, np.float64)
    # Residual in the object frame and output units: what the term has to predict.
    residual = np.asarray(fit.target, np.float64) - np.asarray(prediction, np.float64)
    target = np.column_stack([planar.rotate(residual[:, :2], -yaw) / scales[0], residual[:, 2] / scales[1]])
    # Padded like the effect fits (zero weight), so that data sets of similar size share one program.
    size = max(PAD_MULTIPLE, math.ceil(len(fit) / PAD_MULTIPLE) * PAD_MULTIPLE)
    index = np.concatenate([np.arange(len(fit)), np.zeros(size - len(fit), int)])
    real = np.arange(size) < len(fit)
    x = jnp.asarray(((features - mean) / std)[index], jnp.float32)
    y = jnp.asarray(target[index], jnp.float32)
    train = jnp.asarray(real & train_mask[index], jnp.float32)
    validation = jnp.asarray(real & ~train_mask[index], jnp.float32)
    params = ErrorTerm(settings.hidden).init(jax.random.key(seed), x[:1])["params"]
    history, validation = _train(params, x, y, train, validation, settings)
    best = int(np.argmin(np.asarray(validation)))
    return ErrorCorrection(params=jax.device_get(jax.tree.map(lambda leaf: leaf[best], history)),
                           mean=mean, std=std, scales=scales, hidden=tuple(settings.hidden))


def _window_loss(model, params, x, y):
    error = model.apply({"params": params}, x) - y
    return jnp.sqrt(jnp.sum(error[:, :2] ** 2, axis=-1) + 1e-4) + jnp.sqrt(error[:, 2] ** 2 + 1e-4)


@functools.partial(jax.jit, static_argnames="settings")
def _train(params, x, y, train, validation, settings: CorrectionSettings):
    """Adam on the windows weighted by ``train``; the parameters and the loss on the ``validation``
    windows every ``settings.eval_every`` steps, stacked."""
    model = ErrorTerm(settings.hidden)
    optimiser = optax.adamw(optax.cosine_decay_schedule(settings.learning_rate, settings.steps),
                            weight_decay=settings.weight_decay)

    def loss(params, w):
        return jnp.sum(w * _window_loss(model, params, x, y)) / jnp.sum(w)

    def step(carry, _):
        params, state = carry
        updates, state = optimiser.update(jax.grad(loss)(params, train), state, params)
        return (optax.apply_updates(params, updates), state), None

    def chunk(carry, _):
        carry, _ = jax.lax.scan(step, carry, None, length=settings.eval_every)
        return carry, (carry[0], loss(carry[0], validation))

    _, (history, validation) = jax.lax.scan(chunk, (params, optimiser.init(params)), None,
                                            length=max(1, settings.steps // settings.eval_every))
    return history, validation
