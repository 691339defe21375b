"""The paper's experiments: train the models of an `ExperimentSpec` in sweeps, evaluate them and the baselines, write
results.

The binaries of the paper's experiments under ``experiments/`` (and ``train`` and ``visualize``) call `run`; the
paper-composition run (`pushjax.paper.full_run`) trains one model at a time by a stopping rule instead, with the same
trainer (`pushjax.train.sweep`) and the same rows (`trained_row`). `run` writes ``results.json`` to the work directory,
in one schema everywhere::

    {"name": <the experiment>,
     "config": <ExperimentSpec.to_json(): the dataset and training configs, splits, sizes, seeds, ...>,
     "rows": [{"model", "kind" ("trained" | "baseline"), "train_split", "test_split", "train_size", "seed",
               "l_scale", "steps", <metrics of pushjax.train.evaluate.error_metrics>}, ...]}

``steps`` is the number of optimisation steps the model has actually taken (a checkpoint can be ahead of the
requested number). Baseline rows have ``train_split``, ``train_size``, ``seed`` and ``steps`` null. Metrics that
are undefined (NaN) are written as null; ``sequences`` holds each row's per-sequence error sums (the unit of the
standard errors, `pushjax.paper.statistics`). Besides ``rows``:

* ``curves``: the learning curves, [{"model", "train_split", "train_size", "seed", "l_scale", "step", "split"
  ("train": the model's own training examples, or "validation"), "trans_percent", "rot_percent"}, ...]
  (`pushjax.train.curves`; a dataset without a validation split gives the training curve only);
* ``provenance``: {"commit": the git commit of the code (with ``+changes`` when the tree differed from it; absent
  when unknown, e.g. for an installed pushjax, `pushjax.provenance.git_commit`),
  "invocations": [{"commit", "started" (UTC, ISO 8601), "wall_s", "finished"}, ...] every call of `run` on this
  work directory, a resumed one included, "wall_s": their sum}. A call is recorded in
  ``<workdir>/invocations.jsonl`` when it starts and brought up to date after every sweep, so a call that was
  stopped counts up to its last finished sweep (``"finished": false``).

Each sweep trains in ``<workdir>/<train_split>/l<l_scale>/<variants>`` (checkpoints, ``metrics.csv``,
``curves.csv`` and TensorBoard event files under ``tensorboard/``), so an interrupted run resumes where it stopped;
``tensorboard --logdir=<workdir>`` shows every model of every sweep.
"""

from __future__ import annotations

import dataclasses
import datetime
import json
import math
import os
import time
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from pushjax import data
from pushjax import provenance as provenance_lib
from pushjax import train as train_lib
from pushjax.paper import baselines as baselines_lib, paths
from pushjax.paper.spec import ExperimentSpec
from pushjax.models import PushModel
from pushjax.train import curves as curves_lib, evaluate

Examples = Mapping[str, np.ndarray]


@dataclasses.dataclass(frozen=True)
class TrainedSweep:
    """One trained sweep of a run: its variants, training split, ``l`` factor and the trained models."""

    variants: tuple[str, ...]
    train_split: str
    l_scale: float
    result: train_lib.SweepResult


@dataclasses.dataclass(frozen=True)
class RunOutcome:
    """What `run` returns: the spec, the ``results.json`` content, the trained sweeps and the test sets they met."""

    spec: ExperimentSpec
    results: dict
    sweeps: list[TrainedSweep]
    test_sets: dict[str, Examples]


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


class DatasetUnavailableError(ValueError):
    """A dataset the run needs is not built and the run's settings do not let it be built, or its folder cannot be
    read (`pushjax.data.builder.DatasetFolderError`); names the setting."""


def _other_versions(folder: Path) -> str:
    """``; found version 2.0.0 beside it, ...`` when `folder`'s parent holds datasets of other versions, else ``""``."""
    parent = folder.parent
    versions = sorted(child.name for child in parent.iterdir() if child != folder and
                      (child / "dataset_info.json").is_file()) if parent.is_dir() else []
    if not versions:
        return ""
    return (f"; found version{'s' * (len(versions) > 1)} {', '.join(versions)} beside it, which this pushjax does not "
            f"read")


def load_splits(spec: ExperimentSpec, dataset: data.DatasetConfig, progress: bool = True):
    """split name -> random-access source of `dataset`, built first when the spec allows it and it is missing.

    Logs which dataset (name, version, folder) it reused or built (`pushjax.data.build`). Raises
    `DatasetUnavailableError` before building anything when `dataset` is missing and ``spec.build`` is off (naming
    the versions of it found beside the one this pushjax reads), when it is missing and its data directory is not
    writable, or when its folder holds a dataset TFDS cannot read (a damaged ``dataset_info.json``, or one of
    another version).
    """
    identity = dict(seed=dataset.seed, testbed=dataset.testbed, min_test_sequences=dataset.min_test_sequences)
    builder = _builder(spec, dataset)
    if not builder.is_prepared():
        name = data.dataset_name(dataset.experiment, dataset.scale, **identity)
        if not spec.build:
            raise DatasetUnavailableError(f"build: dataset {name} is not built (looked in {builder.data_dir}"
                                          f"{_other_versions(Path(builder.data_dir))}) and --nobuild forbids building "
                                          "it; --build builds it there")
        try:
            paths.check_writable_folder(builder.data_dir_root)
        except ValueError as error:
            message = f"dataset {name} is not built and cannot be built in {builder.data_dir_root}: {error}"
            raise DatasetUnavailableError(f"data_dir: {message}") from None
    if train_lib.distributed.is_writer():  # with several processes, process 0 builds and the others wait
        data.build(dataset.experiment, dataset.scale, data_dir=spec.data_dir, workers=spec.workers, progress=progress,
                   **identity)
    train_lib.distributed.wait_for_all(f"dataset {builder.builder_config.name} ready")
    return data.load(dataset.experiment, dataset.scale, data_dir=spec.data_dir, **identity)


def dataset_folder(spec: ExperimentSpec, dataset: data.DatasetConfig) -> Path:
    """The folder `load_splits` reads `dataset` from (its data files, `pushjax.provenance.file_digests`)."""
    return Path(_builder(spec, dataset).data_dir)


def _builder(spec: ExperimentSpec, dataset: data.DatasetConfig) -> data.PushEffects:
    try:
        return data.PushEffects(config=data.config_name(dataset.experiment, dataset.scale, dataset.testbed),
                                data_dir=spec.data_dir, seed=dataset.seed, min_test_sequences=dataset.min_test_sequences)
    except data.builder.DatasetFolderError as error:
        raise DatasetUnavailableError(str(error)) from None


def _split_sources(splits: Mapping, names: Sequence[str], dataset: data.DatasetConfig) -> list:
    for name in names:
        if name not in splits:
            raise ValueError(f"split: {name!r} is not a split of {dataset.experiment}; choose from {sorted(splits)}")
    return [splits[name] for name in names]


def _scale_l(examples: Examples, l_scale: float) -> Examples:
    return examples if l_scale == 1.0 else {**examples, "l": examples["l"] * np.float32(l_scale)}


def finite_or_none(row: Mapping) -> dict:
    """`row` with NaN and infinite numbers replaced by None (strict JSON)."""
    return {key: None if isinstance(value, float) and not math.isfinite(value) else value
            for key, value in row.items()}


def train_sweep(spec: ExperimentSpec, variants: Sequence[str], train_examples: Examples, workdir: str | os.PathLike,
                train_split: str = "train", progress: bool = True, label: str = "",
                curve_sets: Mapping[str, Examples] | None = None) -> train_lib.SweepResult:
    """Trains `variants` side by side for every (size, seed) of `spec` (error variants share one sweep).

    Args:
      spec: the run.
      variants: one variant, or several error variants (`pushjax.models.ERROR_OPTIONS`).
      train_examples: {field: [N, ...]} the training split.
      workdir: the sweep's checkpoints, ``metrics.csv`` and ``curves.csv``.
      train_split: the training split's name, for the warning when sizes are clipped.
      progress: show progress bars.
      label: what the progress bar says before the models' description (e.g. which sweep of a run).
      curve_sets: split name -> examples the learning curves are measured on besides each model's training
        examples (e.g. {"validation": ...}); None: none.
    """
    count = len(train_examples["motion"])
    per_model_variants = tuple(variants) if len(variants) > 1 else (None,)
    specs = train_lib.subset_specs(count, clip_sizes(spec.sizes, count, train_split), spec.seeds, per_model_variants)
    description = f"{label}{train_lib.describe_specs(variants[0], specs)} on {train_split}"
    config = spec.train_config(variants[0])
    learning_curves = curves_lib.LearningCurves(
        Path(workdir) / "curves.csv", PushModel(config.model), specs, train_examples, curve_sets or {},
        config.curve_examples, config.eval_batch_size, Path(workdir) / train_lib.metrics_log.TENSORBOARD_DIR)
    return train_lib.sweep(config, train_examples, specs, workdir, mode=spec.mode, progress=progress,
                           description=description, checkpoint_callback=learning_curves)


@dataclasses.dataclass(frozen=True)
class PlannedSweep:
    """One sweep of a run: its variants, training split and l factor, and its progress label."""

    l_scale: float
    train_split: str
    variants: tuple[str, ...]
    label: str


def plan_sweeps(spec: ExperimentSpec, train_splits: Sequence[str]) -> list[PlannedSweep]:
    """The sweeps `run` trains, in order, each labelled with its number among them (``sweep 2/5: ``)."""
    keys = [(l_scale, train_split, variants) for l_scale in spec.l_scales for train_split in train_splits
            for variants in spec.sweep_groups_at(l_scale)]
    return [PlannedSweep(l_scale, train_split, variants,
                         f"sweep {number}/{len(keys)}" + (f", l x{l_scale:g}" if l_scale != 1.0 else "") + ": ")
            for number, (l_scale, train_split, variants) in enumerate(keys, start=1)]


def trained_row(model: str, train_split: str, test_split: str, spec: train_lib.ModelSpec, l_scale: float, steps: int,
                metrics: Mapping, **training) -> dict:
    """The ``results.json`` row of one trained model (`spec`'s subset and seed, `steps` trained) on `test_split`:
    `metrics` of `pushjax.train.evaluate.evaluate`, after `training`'s fields (e.g. a criterion's verdict)."""
    return {"model": model, "kind": "trained", "train_split": train_split, "test_split": test_split,
            "train_size": len(spec.train_indices), "seed": spec.seed, "l_scale": l_scale, "steps": steps, **training,
            **metrics}


def _trained_rows(spec: ExperimentSpec, sweep: TrainedSweep, test_sets: Mapping[str, Examples]) -> list[dict]:
    result = sweep.result
    rows = []
    for test_split, examples in test_sets.items():
        metrics = result.evaluate(examples, spec.train.eval_batch_size)
        for k, (model, model_metrics) in enumerate(zip(result.specs, metrics)):
            rows.append(trained_row(model.variant or sweep.variants[0], sweep.train_split, test_split, model,
                                    sweep.l_scale, int(result.steps_trained[k]), model_metrics))
    return rows


def _curve_rows(sweep: TrainedSweep, workdir: Path) -> list[dict]:
    path = workdir / "curves.csv"
    if not path.exists():
        return []
    specs = sweep.result.specs
    return [{"model": specs[row["model"]].variant or sweep.variants[0], "train_split": sweep.train_split,
             "train_size": len(specs[row["model"]].train_indices), "seed": specs[row["model"]].seed,
             "l_scale": sweep.l_scale, "step": row["step"], "split": row["split"],
             "trans_percent": row["trans_percent"], "rot_percent": row["rot_percent"]}
            for row in curves_lib.read(path)]


def _record_sitting(workdir: Path, provenance: Mapping[str, str], started: datetime.datetime, wall_s: float,
                    finished: bool) -> dict:
    """Writes this call of `run` (of the code `provenance` names: its commit and, for changed code, the diff beside
    the results, `pushjax.provenance.write_source_diff`) into ``<workdir>/invocations.jsonl``, replacing its earlier
    record, and returns the provenance of ``results.json``: every call's record and their wall time."""
    workdir.mkdir(parents=True, exist_ok=True)
    log = workdir / "invocations.jsonl"
    record = {**provenance, "started": started.isoformat(timespec="seconds"), "wall_s": round(wall_s, 1),
              "finished": finished}
    invocations = [json.loads(line) for line in log.read_text().splitlines() if line.strip()] if log.exists() else []
    invocations = [entry for entry in invocations if entry["started"] != record["started"]] + [record]
    partial = log.with_name(log.name + ".partial")
    partial.write_text("".join(json.dumps(entry) + "\n" for entry in invocations))
    partial.replace(log)
    return {**provenance, "invocations": invocations,
            "wall_s": round(sum(entry["wall_s"] for entry in invocations), 1)}


def _baseline_rows(spec: ExperimentSpec, test_sets: Mapping[str, Examples], l_scale: float) -> list[dict]:
    rows = []
    for baseline in spec.baselines:
        if not spec.runs_at(baseline, l_scale):
            continue
        for test_split, examples in test_sets.items():
            metrics = evaluate.error_metrics(baselines_lib.predictions(baseline, examples), examples)
            rows.append({"model": baseline, "kind": "baseline", "train_split": None, "test_split": test_split,
                         "train_size": None, "seed": None, "l_scale": l_scale, "steps": None, **metrics})
    return rows


def run(spec: ExperimentSpec, workdir: str | os.PathLike, progress: bool = True) -> RunOutcome:
    """Trains the spec's variants and evaluates them and its baselines; writes ``<workdir>/results.json``
    (process 0 of several, `pushjax.train.distributed`).

    Args:
      spec: the run (`pushjax.paper.spec.make_spec`).
      workdir: output folder (see the module docstring).
      progress: show progress bars.
    """
    workdir = Path(workdir)
    started, clock = datetime.datetime.now(datetime.timezone.utc), time.monotonic()
    writer = train_lib.distributed.is_writer()
    provenance = provenance_lib.write_source_diff(workdir, provenance_lib.source_state()) if writer else {}

    def record_sitting(finished: bool = False) -> dict | None:
        return _record_sitting(workdir, provenance, started, time.monotonic() - clock, finished) if writer else None

    record_sitting()
    fields = spec.example_fields()
    splits = load_splits(spec, spec.dataset, progress)
    train_sources = _split_sources(splits, spec.train_splits, spec.dataset)
    curve_sets = ({"validation": train_lib.examples_from_source(splits["validation"], fields)}
                  if "validation" in splits else {})
    if spec.test_dataset != spec.dataset:
        splits = load_splits(spec, spec.test_dataset, progress)
    test_sources = _split_sources(splits, spec.test_splits, spec.test_dataset)
    test_sets = {spec.test_split_label(name): train_lib.examples_from_source(source, (*fields, *spec.test_fields))
                 for name, source in zip(spec.test_splits, test_sources)}
    rows, sweeps, curve_rows = [], [], []
    train_sets = {name: train_lib.examples_from_source(source, fields)
                  for name, source in zip(spec.train_splits, train_sources)}
    planned = plan_sweeps(spec, tuple(train_sets))
    for l_scale in spec.l_scales:
        scaled_tests = {name: _scale_l(examples, l_scale) for name, examples in test_sets.items()}
        rows += _baseline_rows(spec, scaled_tests, l_scale)
        for planned_sweep in (planned_sweep for planned_sweep in planned if planned_sweep.l_scale == l_scale):
            variants, train_split = planned_sweep.variants, planned_sweep.train_split
            sweep_dir = workdir / train_split / f"l{l_scale:g}" / "_".join(variants)
            result = train_sweep(spec, variants, _scale_l(train_sets[train_split], l_scale), sweep_dir, train_split,
                                 progress, planned_sweep.label,
                                 {name: _scale_l(examples, l_scale) for name, examples in curve_sets.items()})
            sweep = TrainedSweep(variants, train_split, l_scale, result)
            sweeps.append(sweep)
            rows += _trained_rows(spec, sweep, scaled_tests)
            curve_rows += _curve_rows(sweep, sweep_dir)
            record_sitting()
    results = {"name": spec.name, "config": spec.to_json(), "rows": [finite_or_none(row) for row in rows],
               "curves": [finite_or_none(row) for row in curve_rows]}
    if writer:
        results["provenance"] = record_sitting(finished=True)
        (workdir / "results.json").write_text(json.dumps(results, indent=2))
    return RunOutcome(spec, results, sweeps, test_sets)
