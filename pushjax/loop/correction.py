"""Fallback: a learned, probabilistic error-correction term on top of the (augmented) analytical model.

Like the ``error`` variant of Kloss et al., a small MLP maps the model's inputs to a correction that is
added to the model's prediction; here it predicts a distribution, not a point: a mean correction and a
variance per output (heteroscedastic, in the spirit of the heteroscedastic GP of Bauza & Rodriguez 2017
on the MIT data): the mean is trained on the same robust loss as the effects (:mod:`pushjax.loop.fit`), the
variance by the Gaussian negative log-likelihood of the mean's error. Everything is expressed in the object
frame (the inputs turned by ``-object_yaw``, the correction turned back), so the term does not have to
learn the symmetry of the table plane. The last layer starts at zero, so the untrained term is "no
correction" with unit variance in units of the ``zero`` baseline. It is trained with Adam and
early-stopped on the loss of a fifth of the fit push sequences.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Sequence

import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np
import optax

from pushjax import planar
from pushjax.loop.fit import padded_size, zero_scales
from pushjax.loop.windows import Examples, split_by_sequence


LOG_VARIANCE_RANGE = (-12.0, 6.0)
"""Clip of the predicted log variances (units of the zero baseline squared)."""


class ErrorTerm(nn.Module):
    """MLP from standardised features [..., F] to the mean correction [..., :3] and its log variance
    [..., 3:] per output, in units of the zero baseline."""

    hidden: Sequence[int] = (64, 64)

    @nn.compact
    def __call__(self, features: jax.Array) -> jax.Array:
        x = features
        for width in self.hidden:
            x = nn.gelu(nn.Dense(width)(x))
        return nn.Dense(6, kernel_init=nn.initializers.zeros)(x)


@dataclasses.dataclass(frozen=True)
class CorrectionConfig:
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

    def __call__(self, examples: Examples, prediction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The predictive distribution given the model's [N, 3] ``prediction`` on ``examples``.

        Returns:
          ([N, 3] mean: the corrected prediction, world axes (m, m, rad); [N, 3] standard deviation along
          the object's axes and of the rotation (m, m, rad)).
        """
        features = (_features(examples, prediction) - self.mean) / self.std
        output = np.asarray(ErrorTerm(self.hidden).apply({"params": self.params}, jnp.asarray(features, jnp.float32)),
                            np.float64)
        units = np.array([self.scales[0], self.scales[0], self.scales[1]])
        std = np.exp(0.5 * np.clip(output[:, 3:], *LOG_VARIANCE_RANGE)) * units
        return _add(examples, prediction, output[:, :3], self.scales), std


def _features(examples: Examples, prediction: np.ndarray) -> np.ndarray:
    inputs = examples.inputs
    yaw = np.asarray(inputs.object_yaw, np.float64)
    prediction = np.asarray(prediction, np.float64)
    return np.column_stack([
        planar.rotate(np.asarray(inputs.contact), -yaw), planar.rotate(np.asarray(inputs.normal), -yaw),
        planar.rotate(np.asarray(inputs.action), -yaw), planar.rotate(np.asarray(inputs.pusher_motion), -yaw),
        inputs.gap, inputs.l, inputs.mu, inputs.s, inputs.push_speed, inputs.time_after_stop, inputs.object_position,
        planar.rotate(prediction[:, :2], -yaw), prediction[:, 2],
    ])


def _add(examples: Examples, prediction: np.ndarray, correction: np.ndarray, scales) -> np.ndarray:
    yaw = np.asarray(examples.inputs.object_yaw, np.float64)
    translation = planar.rotate(scales[0] * correction[:, :2], yaw)
    return np.asarray(prediction, np.float64) + np.column_stack([translation, scales[1] * correction[:, 2]])


def fit_error_correction(
    fit: Examples,
    prediction: np.ndarray,
    settings: CorrectionConfig = CorrectionConfig(),
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
    size = padded_size(len(fit))
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
    """The mean's robust error (the effects' loss) plus the Gaussian negative log-likelihood of the variance
    given the mean (the mean's gradient stopped there, so a large variance does not stall the mean)."""
    output = model.apply({"params": params}, x)
    error = output[:, :3] - y
    log_variance = jnp.clip(output[:, 3:], *LOG_VARIANCE_RANGE)
    robust = jnp.sqrt(jnp.sum(error[:, :2] ** 2, axis=-1) + 1e-4) + jnp.sqrt(error[:, 2] ** 2 + 1e-4)
    likelihood = 0.5 * jnp.sum(jax.lax.stop_gradient(error) ** 2 * jnp.exp(-log_variance) + log_variance, axis=-1)
    return robust + likelihood


@functools.partial(jax.jit, static_argnames="settings")
def _train(params, x, y, train, validation, settings: CorrectionConfig):
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
