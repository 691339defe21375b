"""Training losses (Kloss et al., Sec. III-D and V-B). Each returns ``(loss, metrics)``.

Errors are Euclidean distances in mm and absolute angles in degrees, averaged over the batch:

* ``trans``: |predicted - true centre-of-mass translation| [mm];
* ``mag``: ||predicted translation| - |true translation|| [mm] (keeps s from collapsing early);
* ``rot``: |predicted - true yaw change| [deg];
* ``pos``: |predicted - true object position| [mm];
* ``reg``: 0.5 * sum of squared kernel weights (biases and batch-norm parameters excluded).

2-D loss: trans + mag + rot + pos + weight_decay * reg. 3-D loss: s-weighted (ground-truth contact
flag) trans and rot of the motion given contact + pos + 10 * binary cross-entropy of the predicted
contact indicator + weight_decay * reg.
"""

from __future__ import annotations

from collections.abc import Mapping

import jax
import jax.numpy as jnp
import optax

from pushjax.models import heads
from pushjax.planar import M_TO_MM

CONTACT_WEIGHT = 10.0
LOSS_3D_PREDICTIONS = frozenset({"motion_given_contact", "s_logit"})
"""The model outputs that `loss_3d` reads besides the object position."""

Metrics = dict[str, jax.Array]


def _distance_mm(predicted: jax.Array, target: jax.Array) -> jax.Array:
    """[B] Euclidean distance [mm] of [B, 2] points [m], with a finite gradient at zero distance."""
    difference = (predicted - target) * M_TO_MM
    return jnp.sqrt(jnp.sum(difference**2, axis=-1) + 1e-6)


def _norm_mm(vectors: jax.Array) -> jax.Array:
    return jnp.sqrt(jnp.sum((vectors * M_TO_MM) ** 2, axis=-1) + 1e-6)


def _rotation_error_deg(predicted: jax.Array, target: jax.Array) -> jax.Array:
    return jnp.abs(jnp.rad2deg(predicted - target))


def weight_penalty(params: Mapping) -> jax.Array:
    """0.5 * sum of squares of every `kernel` leaf of a Flax parameter tree."""
    total = jnp.zeros(())
    for path, leaf in jax.tree_util.tree_leaves_with_path(params):
        if getattr(path[-1], "key", None) == "kernel":
            total = total + 0.5 * jnp.sum(leaf**2)
    return total


def loss_2d(
    predictions: Mapping[str, jax.Array], batch: Mapping[str, jax.Array], params: Mapping,
    weight_decay: float,
) -> tuple[jax.Array, Metrics]:
    """Top-down training loss.

    Args:
      predictions: `PushModel` outputs: `motion` [B, 3] (m, m, rad), `object_pos` [B, 2] [m] unless
        the model has no perception (``neural_dyn``: no ``pos`` term).
      batch: `motion` [B, 3], `object_pos` [B, 2].
      params: the model's parameters, for the weight penalty.
      weight_decay: lambda of the weight penalty (paper: 0.001).

    Returns:
      (scalar loss, metrics {loss, trans, mag, rot, pos, reg} in mm / degrees).
    """
    motion, target = predictions["motion"], batch["motion"]
    metrics = {
        "trans": jnp.mean(_distance_mm(motion[:, :2], target[:, :2])),
        "mag": jnp.mean(jnp.abs(_norm_mm(motion[:, :2]) - _norm_mm(target[:, :2]))),
        "rot": jnp.mean(_rotation_error_deg(motion[:, 2], target[:, 2])),
        "pos": _position_error(predictions, batch),
        "reg": weight_penalty(params),
    }
    loss = metrics["trans"] + metrics["mag"] + metrics["rot"] + metrics["pos"] + weight_decay * metrics["reg"]
    return loss, {"loss": loss, **metrics}


def loss_3d(
    predictions: Mapping[str, jax.Array], batch: Mapping[str, jax.Array], params: Mapping,
    weight_decay: float,
) -> tuple[jax.Array, Metrics]:
    """Free-viewpoint training loss of the physics variants.

    Args:
      predictions: `motion_given_contact` [B, 3] (m, m, rad), `s_logit` [B], `object_pos` [B, 2] [m].
      batch: `motion` [B, 3], `contact_flag` [B], `object_pos` [B, 2].
      params: the model's parameters, for the weight penalty.
      weight_decay: lambda of the weight penalty (paper: 0.001).

    Returns:
      (scalar loss, metrics {loss, trans, rot, pos, contact_bce, reg}); trans and rot are the
      contact-flag-weighted batch means [mm, deg].
    """
    motion, target = predictions["motion_given_contact"], batch["motion"]
    weight = batch["contact_flag"]
    metrics = {
        "trans": jnp.mean(weight * _distance_mm(motion[:, :2], target[:, :2])),
        "rot": jnp.mean(weight * _rotation_error_deg(motion[:, 2], target[:, 2])),
        "pos": _position_error(predictions, batch),
        "contact_bce": jnp.mean(optax.sigmoid_binary_cross_entropy(predictions["s_logit"], weight)),
        "reg": weight_penalty(params),
    }
    loss = (
        metrics["trans"] + metrics["rot"] + metrics["pos"] + CONTACT_WEIGHT * metrics["contact_bce"]
        + weight_decay * metrics["reg"]
    )
    return loss, {"loss": loss, **metrics}


def _position_error(predictions, batch) -> jax.Array:
    if "object_pos" not in predictions:
        return jnp.zeros(())
    return jnp.mean(_distance_mm(predictions["object_pos"], batch["object_pos"]))


def loss_for(variant: str, view: str):
    """The loss of a `PushModel` of `variant` in `view`, by what its head predicts there.

    `loss_3d` if it predicts the motion given contact and the contact indicator separately (the
    physics variants with s in the free view), else `loss_2d`.
    """
    if LOSS_3D_PREDICTIONS <= heads.HEADS[variant].output_names(view):
        return loss_3d
    return loss_2d
