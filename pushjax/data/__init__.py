"""Push data: the raw MIT layout (`mit_push`), the example schema, and the TFDS push datasets.

The dataset API (``PushEffects``, ``build``, ``load``, ``batches``, ``get_config``, ...) is imported on first
use, so that ``pushjax.sim`` can import ``pushjax.data.mit_push`` without loading TFDS or the builders.
"""

import importlib

_LAZY = {
    "PushEffects": "pushjax.data.builder",
    "build": "pushjax.data.builder",
    "load": "pushjax.data.builder",
    "dataset_name": "pushjax.data.builder",
    "batches": "pushjax.data.batches",
    "DatasetConfig": "pushjax.data.configs",
    "get_config": "pushjax.data.configs",
    "plan_splits": "pushjax.data.configs",
    "EXPERIMENTS": "pushjax.data.configs",
    "SCALES": "pushjax.data.configs",
    "ALL_FIELDS": "pushjax.data.examples",
    "EXTRA_FIELDS": "pushjax.data.examples",
    "sequence_examples": "pushjax.data.examples",
}

__all__ = sorted(_LAZY)


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'pushjax.data' has no attribute {name!r}")
