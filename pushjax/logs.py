"""Known log noise filtered out of pushjax's binaries and model loading, without hiding real warnings.

Two lines appear on every run although nothing is wrong: JAX's probe for a TPU on a machine without one (``Unable to
initialize backend 'tpu': ... libtpu.so ...``, at INFO, shown because absl's binaries log INFO), and orbax's
``Given directory is read only=...`` each time a checkpoint is opened to read it (``pushjax.train.predictor``).
`quiet_known_noise` drops exactly those messages, matched by their start, from the loggers that emit them; every
other record, of any level, passes.
"""

from __future__ import annotations

import logging

KNOWN_NOISE = {
    "jax._src.xla_bridge": ("Unable to initialize backend 'tpu'",),
    "absl": ("Given directory is read only",),
}
"""Logger name -> the starts of the messages dropped from it."""


class _DropMessages(logging.Filter):
    def __init__(self, starts: tuple[str, ...]):
        super().__init__()
        self.starts = starts

    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith(self.starts) and not record.getMessage().startswith(self.starts)


def quiet_known_noise() -> None:
    """Installs the filters of `KNOWN_NOISE` (once: calling it again changes nothing)."""
    for name, starts in KNOWN_NOISE.items():
        logger = logging.getLogger(name)
        if not any(isinstance(existing, _DropMessages) for existing in logger.filters):
            logger.addFilter(_DropMessages(starts))
