"""Training batches from a random-access data source (e.g. ``tfds.data_source``), as dicts of NumPy arrays."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np


def batches(
    source: Sequence[dict[str, Any]],
    batch_size: int,
    seed: int,
    indices: Sequence[int] | np.ndarray | None = None,
    *,
    shuffle: bool = True,
    drop_remainder: bool = True,
    num_epochs: int | None = 1,
) -> Iterator[dict[str, np.ndarray]]:
    """Iterates over shuffled batches of ``source``.

    Args:
      source: random-access examples (``len`` and ``[i]``; ``__getitems__`` is used when present), each a dict
        of arrays, e.g. one split of ``pushjax.data.load(...)``.
      batch_size: examples per batch (>= 1).
      seed: seed of the shuffling; epoch ``e`` uses the permutation drawn from ``[seed, e]``.
      indices: the example indices to draw from (e.g. a subset for a data-size sweep); default all.
      shuffle: shuffle every epoch; False keeps the order of ``indices``.
      drop_remainder: drop the last, smaller batch of an epoch.
      num_epochs: passes over the data; None iterates forever.

    Yields:
      dicts of [batch_size, ...] NumPy arrays, one key per example field, with the dtypes of
      ``pushjax.data.schema`` (the TFDS reader returns scalar fields as Python numbers).
    """
    if not isinstance(batch_size, (int, np.integer)) or batch_size < 1:
        raise ValueError(f"batch_size: expected an integer >= 1, got {batch_size!r}")
    if num_epochs is not None and (not isinstance(num_epochs, (int, np.integer)) or num_epochs < 0):
        raise ValueError(f"num_epochs: expected None or an integer >= 0, got {num_epochs!r}")
    size = len(source)
    indices = np.arange(size) if indices is None else np.asarray(indices)
    if indices.ndim != 1 or (indices.size and (not np.issubdtype(indices.dtype, np.integer)
                                              or indices.min() < 0 or indices.max() >= size)):
        raise ValueError(f"indices: expected a 1-D array of integers in [0, {size}), got {indices!r}")
    if drop_remainder and len(indices) < batch_size:
        raise ValueError(f"indices: {len(indices)} examples cannot fill one batch of {batch_size}")
    read = getattr(source, "__getitems__", None) or (lambda keys: [source[int(key)] for key in keys])
    epoch = 0
    while num_epochs is None or epoch < num_epochs:
        order = np.random.default_rng([seed, epoch]).permutation(indices) if shuffle else indices
        stop = len(order) - len(order) % batch_size if drop_remainder else len(order)
        for begin in range(0, stop, batch_size):
            examples = read([int(key) for key in order[begin:begin + batch_size]])
            yield {name: np.asarray([example[name] for example in examples], dtype=_dtype(name, examples[0][name]))
                   for name in examples[0]}
        epoch += 1


def _dtype(name: str, value: Any):
    from pushjax.data.examples import ALL_FIELDS

    return ALL_FIELDS[name].dtype if name in ALL_FIELDS else np.asarray(value).dtype
