"""Training data of a sweep: each model's subset and seed, its batch order, and in-memory batches.

The trainer holds a split in memory (`examples_from_source`) and assembles each batch by indexing it
(`gather` at `batch_indices`).

Determinism: model k's batch at step t is a pure function of (spec.seed, spec.train_indices, t)
(`batch_indices`), so a run resumed at any step replays exactly the batches of an uninterrupted run,
and a model trained alone draws the same batches as inside a sweep.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from pushjax.data import schema
from pushjax.models import ERROR_OPTIONS, ModelConfig

Batch = Mapping[str, Any]
"""{field: [B, ...] array}: a batch of B examples (schema fields)."""
Examples = Mapping[str, np.ndarray]
"""{field: [N, ...] NumPy array}: a split of N examples held in memory (schema fields)."""

MODEL_INPUT_FIELDS = (
    "pusher_pos", "pusher_pixel", "action", "object_pos", "motion", "contact", "normal",
    "contact_flag", "l", "mu", "camera_intrinsics", "camera_extrinsics",
)
"""Batch fields the models and losses read, besides the image (`ModelConfig.image_field`)."""
EVALUATION_FIELDS = ("push_velocity", "sequence_id")
"""Fields evaluation reads besides `model_fields`."""
_BATCH_ORDER_STREAM = 1
"""Separates the batch-order random stream from other uses of a model's seed."""
_READ_CHUNK = 1024
"""Examples read from a source per call."""


@dataclasses.dataclass(frozen=True, eq=False)
class ModelSpec:
    """One model of a sweep.

    Attributes:
      name: label in logs and results, e.g. ``"size=100/seed=2"``.
      train_indices: [N_k] int indices of its training examples into the training split.
      seed: initialisation and batch-order seed.
      variant: error-term variant (a key of `ERROR_OPTIONS`) to use for this model when the
        sweep's model variant is an error variant, or None for the config's variant.
    """

    name: str
    train_indices: np.ndarray
    seed: int
    variant: str | None = None

    def __post_init__(self):
        indices = np.asarray(self.train_indices)
        if indices.ndim != 1 or indices.size == 0 or not np.issubdtype(indices.dtype, np.integer):
            raise ValueError(f"train_indices of {self.name!r}: expected a non-empty 1-D integer array")
        if self.variant is not None and self.variant not in ERROR_OPTIONS:
            raise ValueError(f"variant of {self.name!r}: expected one of {tuple(ERROR_OPTIONS)} or None")


def subset_specs(
    num_examples: int, sizes: Sequence[int], seeds: Sequence[int], variants: Sequence[str | None] = (None,)
) -> list[ModelSpec]:
    """One `ModelSpec` per (size, seed, variant): a random training subset of `size` examples.

    The subset of (size, seed) is drawn without replacement by ``np.random.default_rng([seed, size])``
    and shared by the variants; the model's seed is `seed`.

    Args:
      num_examples: size of the training split (examples).
      sizes: training-set sizes (examples), each in [1, num_examples].
      seeds: subset (and model) seeds, >= 0.
      variants: error-term variants to mix (see `ModelSpec.variant`).

    Returns:
      len(sizes) * len(seeds) * len(variants) specs, ordered by size, then seed, then variant.
    """
    specs = []
    for size in sizes:
        if not 1 <= size <= num_examples:
            raise ValueError(f"sizes: expected sizes in [1, {num_examples}], got {size}")
        for seed in seeds:
            if seed < 0:
                raise ValueError(f"seeds: expected seeds >= 0, got {seed}")
            rng = np.random.default_rng([seed, size])
            indices = np.sort(rng.choice(num_examples, size, replace=False))
            for variant in variants:
                name = f"size={size}/seed={seed}" + (f"/{variant}" if variant else "")
                specs.append(ModelSpec(name, indices, seed, variant))
    return specs


@functools.lru_cache(maxsize=64)
def _epoch_permutation(seed: int, epoch: int, size: int) -> np.ndarray:
    return np.random.default_rng([seed, _BATCH_ORDER_STREAM, epoch]).permutation(size)


def batch_indices(spec: ModelSpec, step: int, batch_size: int) -> np.ndarray:
    """[batch_size] training-split indices of `spec`'s batch at `step`.

    The model walks through its subset in epochs, each a fresh permutation drawn from (seed, epoch);
    batch t holds positions t * batch_size ... of that endless sequence.

    Args:
      spec: the model.
      step: the optimisation step (>= 0), counted from 0.
      batch_size: examples per batch (>= 1).
    """
    size = len(spec.train_indices)
    positions = step * batch_size + np.arange(batch_size)
    epochs = positions // size
    order = np.empty(batch_size, dtype=np.int64)
    for epoch in np.unique(epochs):
        selected = epochs == epoch
        order[selected] = _epoch_permutation(spec.seed, int(epoch), size)[positions[selected] % size]
    return np.asarray(spec.train_indices)[order]


def model_fields(config: ModelConfig) -> tuple[str, ...]:
    """The batch fields a model of `config` and its loss read: its image and `MODEL_INPUT_FIELDS`."""
    return (config.image_field, *MODEL_INPUT_FIELDS)


def gather(examples: Examples, indices: np.ndarray, fields: Sequence[str]) -> dict[str, np.ndarray]:
    """The examples at `indices` of the chosen `fields`, as a batch.

    Args:
      examples: {field: [N, ...] array}, holding at least `fields`.
      indices: [...] int indices into the N examples.
      fields: the field names to keep.

    Returns:
      {field: [*indices.shape, ...] array}.
    """
    missing = [name for name in fields if name not in examples]
    if missing:
        raise ValueError(f"examples: missing fields {missing}")
    return {name: examples[name][indices] for name in fields}


def examples_from_source(source: Sequence[Mapping[str, Any]], fields: Sequence[str],
                         indices: Sequence[int] | None = None) -> dict[str, np.ndarray]:
    """The examples of a random-access source (e.g. a `pushjax.data.load` split) as in-memory arrays.

    Args:
      source: ``len`` and ``[i]`` (``__getitems__`` when present) giving dicts of arrays.
      fields: the fields to keep (e.g. `model_fields` plus `EVALUATION_FIELDS`); names of
        `pushjax.data.schema.FIELDS`.
      indices: [N] indices of the examples to read, in the order of the result (None: all, in order).

    Returns:
      {field: [N, ...] array} with the dtypes of `pushjax.data.schema.FIELDS`, N = len(source) without `indices`.
    """
    count = len(source)
    keys = np.arange(count) if indices is None else np.asarray(indices, dtype=np.int64)
    if keys.size == 0:
        raise ValueError("source: expected at least one example" if count == 0 else "indices: expected at least one")
    if keys.min() < 0 or keys.max() >= count:
        raise ValueError(f"indices: expected indices in [0, {count}), got {keys.min()}..{keys.max()}")
    read = getattr(source, "__getitems__", None) or (lambda keys: [source[key] for key in keys])
    examples: dict[str, np.ndarray] = {}
    for start in range(0, keys.size, _READ_CHUNK):
        chunk = read(keys[start:start + _READ_CHUNK].tolist())
        for name in fields:
            values = np.asarray([example[name] for example in chunk], dtype=schema.FIELDS[name].dtype)
            if name not in examples:  # filled chunk by chunk: the split is in memory once, not also as a list
                examples[name] = np.empty((keys.size, *values.shape[1:]), values.dtype)
            examples[name][start:start + len(values)] = values
    return examples
