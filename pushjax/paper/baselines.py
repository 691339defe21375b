"""The baselines of Kloss et al.: ``zero`` (no motion) and ``physics`` (Lynch's model on the true state)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from pushjax.physics import lynch

BASELINES = ("zero", "physics")
BASELINE_FIELDS = ("motion", "object_pos", "contact", "normal", "contact_flag", "action_from_contact", "l", "mu",
                   "push_velocity")
"""The example fields `predictions` reads."""


def predictions(name: str, examples: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """What baseline ``name`` predicts for every example.

    Args:
      name: ``"zero"`` (object motion 0) or ``"physics"`` (`lynch.predict` on the true contact point, normal,
        ``l`` and ``mu`` and, as the paper feeds it, the pusher's motion from first contact on
        (``action_from_contact``, not the whole window's), scaled by the true contact flag; a scaled ``l`` in
        `examples` gives Table 5).
      examples: {field: [N, ...]} with at least `BASELINE_FIELDS` (SI units).

    Returns:
      {"motion": [N, 3] (m, m, rad)}; ``physics`` also gives the true state it used, so its state errors are 0.
    """
    motion = np.asarray(examples["motion"])
    if name == "zero":
        return {"motion": np.zeros_like(motion)}
    if name == "physics":
        predicted = lynch.predict(examples["contact"], examples["normal"], examples["action_from_contact"], examples["l"],
                                  examples["mu"], examples["contact_flag"])
        return {"motion": np.asarray(predicted, motion.dtype)}
    raise ValueError(f"name: expected one of {BASELINES}, got {name!r}")
