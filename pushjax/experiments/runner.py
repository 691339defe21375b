"""The experiment runner: find or build a dataset, sweep-train model variants, evaluate them and the baselines.

Every experiment binary under ``experiments/`` is `run` with its variants, splits and baselines, followed by
`pushjax.experiments.tables` and `pushjax.experiments.figures`. `run` writes ``results.json`` to the work
directory::

    {"name": ..., "config": {everything that defines the run, incl. the dataset and training configs},
     "rows": [{"model", "kind" ("trained" | "baseline"), "train_split", "test_split", "train_size", "seed",
               "l_scale", <metrics of pushjax.train.evaluate.error_metrics>}, ...]}

Baseline rows have ``train_size`` and ``seed`` null. Metrics that are undefined (NaN) are written as null.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import jax
import numpy as np

from pushjax import data
from pushjax.experiments import baselines as baselines_lib
from pushjax.models import ERROR_OPTIONS, VARIANTS
from pushjax.train import configs as train_configs
from pushjax.train import evaluate, train

Examples = Mapping[str, np.ndarray]
MODELS = (*VARIANTS, *baselines_lib.BASELINES)


def parse_sizes(values: Sequence[str | int]) -> tuple[int, ...]:
    """Training-set sizes from flag values; raises ``ValueError`` unless all are positive integers."""
    sizes = []
    for value in values:
        try:
            size = int(str(value).strip())
        except ValueError:
            size = 0
        if size < 1 or str(size) != str(value).strip():
            raise ValueError(f"sizes: expected positive integers, got {list(values)}")
        sizes.append(size)
    return tuple(sizes)


def parse_seeds(values: Sequence[str | int]) -> tuple[int, ...]:
    """Seeds from flag values; raises ``ValueError`` unless all are integers >= 0."""
    try:
        seeds = tuple(int(str(value).strip()) for value in values)
    except ValueError:
        seeds = (-1,)
    if not seeds or min(seeds) < 0:
        raise ValueError(f"seeds: expected integers >= 0, got {list(values)}")
    return seeds


def parse_models(values: Sequence[str], allowed: Sequence[str] = MODELS) -> tuple[str, ...]:
    """Model names from flag values; raises ``ValueError`` naming any that is not in `allowed`."""
    unknown = [value for value in values if value not in allowed]
    if unknown or not values:
        raise ValueError(f"variants: unknown {unknown or 'empty list'}; choose from {', '.join(allowed)}")
    return tuple(values)


def clip_sizes(sizes: Sequence[int], count: int, split: str = "train") -> tuple[int, ...]:
    """`sizes` with every size above `count` (the training split's examples) lowered to it, with a warning.

    Empty `sizes` means the whole split. Duplicates that clipping creates are dropped.
    """
    if not sizes:
        return (count,)
    too_large = [size for size in sizes if size > count]
    if too_large:
        warnings.warn(
            f"sizes: {too_large} exceed the {count} examples of training split {split!r}; clipped to {count}",
            stacklevel=2,
        )
    return tuple(dict.fromkeys(min(size, count) for size in sizes))


def check_data_dir(data_dir: str | os.PathLike | None) -> None:
    """Raises ``ValueError`` when `data_dir` is given but is not an existing directory."""
    if data_dir is not None and not Path(data_dir).is_dir():
        raise ValueError(f"data_dir: {data_dir} is not an existing directory")


def load_splits(experiment: str, scale: str, data_dir: str | os.PathLike | None = None, *, seed: int = 0,
                build: bool = True, workers: int | None = None, progress: bool = True):
    """The splits of a dataset (split name -> random-access source), built first when `build` and missing.

    Raises ``ValueError`` when `data_dir` is given but is not an existing directory.
    """
    check_data_dir(data_dir)
    if build:
        data.build(experiment, scale, data_dir=data_dir, seed=seed, workers=workers, progress=progress)
    return data.load(experiment, scale, data_dir=data_dir, seed=seed)


def make_train_config(scale: str, variant: str, dataset_config, num_steps: int | None = None
                      ) -> train_configs.TrainConfig:
    """The training config of `scale` for `variant` on a dataset (its camera and glimpse size)."""
    config = train_configs.get_config(scale).with_variant(variant, dataset_config.camera)
    return dataclasses.replace(
        config,
        model=dataclasses.replace(config.model, glimpse_size=dataset_config.glimpse_size),
        num_steps=num_steps or config.num_steps,
    )


def example_fields(config: train_configs.TrainConfig) -> tuple[str, ...]:
    """Every field training, evaluation and the baselines read."""
    return tuple(dict.fromkeys(
        (*train.model_fields(config.model), *train.EVALUATION_FIELDS, *baselines_lib.BASELINE_FIELDS)
    ))


def default_mode() -> str:
    """The sweep mode that is fastest on this backend: ``sequential`` on CPU, else ``vmap``."""
    return "sequential" if jax.default_backend() == "cpu" else "vmap"


def train_and_evaluate(
    config: train_configs.TrainConfig, train_examples: Examples, test_sets: Mapping[str, Examples],
    workdir: str | os.PathLike, *, sizes: Sequence[int] = (), seeds: Sequence[int] = (0,),
    variants: Sequence[str | None] = (None,), mode: str | None = None, progress: bool = True,
    train_split: str = "train",
) -> list[dict]:
    """One sweep of ``config.model.variant`` over (size, seed[, error variant]), evaluated on every test set.

    Args:
      config: training config (its model's variant is trained).
      train_examples: {field: [N, ...]} training split.
      test_sets: test split name -> examples.
      workdir: the sweep's checkpoints and ``metrics.csv``.
      sizes: training-set sizes (clipped to N with a warning; empty: N).
      seeds: subset and initialisation seeds.
      variants: per-model error variants (``ERROR_OPTIONS`` keys) trained side by side, or ``(None,)``.
      mode: sweep mode (default `default_mode`).
      progress: show progress bars.
      train_split: the training split's name, for the warning.

    Returns:
      one row per (model, test set): name, variant, train_size, seed, test_split and the test metrics.
    """
    count = len(train_examples["motion"])
    specs = train.subset_specs(count, clip_sizes(sizes, count, train_split), list(seeds), tuple(variants))
    result = train.sweep(config, train_examples, specs, workdir, mode=mode or default_mode(), progress=progress)
    rows = []
    for test_split, test_examples in test_sets.items():
        for spec, metrics in zip(specs, evaluate.evaluate_sweep(result, test_examples, config.eval_batch_size)):
            rows.append({"name": spec.name, "variant": spec.variant or config.model.variant,
                         "train_size": len(spec.train_indices), "seed": spec.seed, "test_split": test_split,
                         **metrics})
    return rows


def _scale_l(examples: Examples, l_scale: float) -> Examples:
    return examples if l_scale == 1.0 else {**examples, "l": examples["l"] * np.float32(l_scale)}


def train_config_dict(config: train_configs.TrainConfig) -> dict:
    """The training config as JSON; the model's variant is per row."""
    config_dict = dataclasses.asdict(config)
    del config_dict["model"]["variant"]
    return config_dict


def finite_or_none(row: Mapping) -> dict:
    """`row` with NaN and infinite numbers replaced by None (strict JSON)."""
    return {key: None if isinstance(value, float) and not math.isfinite(value) else value
            for key, value in row.items()}


def run(
    name: str, experiment: str, scale: str, workdir: str | os.PathLike, *, variants: Sequence[str],
    baselines: Sequence[str] = baselines_lib.BASELINES, train_splits: Sequence[str] = ("train",),
    test_splits: Sequence[str] = ("test",), sizes: Sequence[int] = (), seeds: Sequence[int] = (0,),
    l_scales: Sequence[float] = (1.0,), l_scaled_models: Sequence[str] | None = None,
    num_steps: int | None = None, data_dir: str | os.PathLike | None = None,
    build: bool = True, workers: int | None = None, mode: str | None = None, progress: bool = True,
) -> dict:
    """Trains `variants` and evaluates them and `baselines`; writes and returns ``results.json``.

    Args:
      name: the experiment's name (``data_efficiency``, ``error_variants``, ...), for tables and figures.
      experiment: the dataset experiment (`pushjax.data.EXPERIMENTS`).
      scale: dataset and training scale (``smoke``, ``cpu``, ``paper``).
      workdir: output folder; each sweep trains in ``<workdir>/<train_split>/l<l_scale>/<variant>``.
      variants: model variants to train; error variants among them train side by side in one sweep.
      baselines: `baselines.BASELINES` to evaluate.
      train_splits: training splits, each trained separately.
      test_splits: test splits, every model is evaluated on each.
      sizes: training-set sizes (clipped to each split's size with a warning; empty: the whole split).
      seeds: subset and initialisation seeds.
      l_scales: factors applied to the limit-surface ratio ``l`` of all examples (Table 5: 1.5, 3).
      l_scaled_models: the variants and baselines run at factors other than 1 (default: all).
      num_steps: overrides the scale's training steps.
      data_dir: TFDS data directory (must exist when given; default TFDS's).
      build: build the dataset when it is missing.
      workers: dataset build processes (None: the builder's default).
      mode: sweep mode (default `default_mode`).
      progress: show progress bars.
    """
    variants, baselines = tuple(variants), tuple(baselines)
    parse_models(variants + baselines)
    sizes, seeds = parse_sizes(sizes), parse_seeds(seeds)
    if any(not l_scale > 0 for l_scale in l_scales):
        raise ValueError(f"l_scales: expected positive factors, got {list(l_scales)}")
    dataset_config = data.get_config(experiment, scale)
    splits = load_splits(experiment, scale, data_dir, build=build, workers=workers, progress=progress)
    for split in (*train_splits, *test_splits):
        if split not in splits:
            raise ValueError(f"split: {split!r} is not a split of {experiment}; choose from {sorted(splits)}")
    base_config = make_train_config(scale, (variants or ("hybrid",))[0], dataset_config, num_steps)
    fields = example_fields(base_config)
    test_sets = {split: train.examples_from_source(splits[split], fields) for split in test_splits}
    error_group = tuple(v for v in variants if v in ERROR_OPTIONS)
    groups = [(v,) for v in variants if v not in ERROR_OPTIONS] + ([error_group] if error_group else [])
    workdir = Path(workdir)
    rows = []
    for l_scale in l_scales:
        scaled_tests = {split: _scale_l(examples, l_scale) for split, examples in test_sets.items()}
        included = (lambda model: True) if l_scale == 1.0 or l_scaled_models is None else (
            lambda model: model in l_scaled_models)
        for baseline in filter(included, baselines):
            for test_split, examples in scaled_tests.items():
                metrics = evaluate.error_metrics(baselines_lib.predictions(baseline, examples), examples)
                rows.append({"model": baseline, "kind": "baseline", "train_split": None, "test_split": test_split,
                             "train_size": None, "seed": None, "l_scale": l_scale, **metrics})
        for train_split in train_splits:
            train_examples = _scale_l(train.examples_from_source(splits[train_split], fields), l_scale)
            split_sizes = clip_sizes(sizes, len(train_examples["motion"]), train_split)
            for group in groups:
                group = tuple(filter(included, group))
                if not group:
                    continue
                config = make_train_config(scale, group[0], dataset_config, num_steps)
                sweep_rows = train_and_evaluate(
                    config, train_examples, scaled_tests, workdir / train_split / f"l{l_scale:g}" / "_".join(group),
                    sizes=split_sizes, seeds=seeds, variants=group if len(group) > 1 else (None,), mode=mode,
                    progress=progress, train_split=train_split,
                )
                for row in sweep_rows:
                    row.pop("name")
                    rows.append({"model": row.pop("variant"), "kind": "trained", "train_split": train_split,
                                 "l_scale": l_scale, **row})
    results = {
        "name": name,
        "config": {
            "experiment": experiment, "scale": scale, "variants": list(variants), "baselines": list(baselines),
            "train_splits": list(train_splits), "test_splits": list(test_splits), "sizes": list(sizes),
            "seeds": list(seeds), "l_scales": list(l_scales),
            "l_scaled_models": None if l_scaled_models is None else list(l_scaled_models),
            "num_steps": base_config.num_steps,
            "mode": mode or default_mode(), "data_dir": None if data_dir is None else str(data_dir),
            "dataset": dataclasses.asdict(dataset_config),
            "train": train_config_dict(base_config),
        },
        "rows": [finite_or_none(row) for row in rows],
    }
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "results.json").write_text(json.dumps(results, indent=2))
    return results
