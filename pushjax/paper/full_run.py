"""Table 1 at the paper's composition and sizes (issue 30): one model per unit, each recorded as it finishes.

The run ``data_efficiency_full`` trains on the ``data_efficiency`` dataset at ``cpu_full`` scale (all objects on all
four surfaces at 20 mm/s, 190 080 training and 38 016 test examples from 528 test sequences, 64 x 64 images):
neural, hybrid and error at every size of `SIZES`, simple and neural_dyn at `SIDE_SIZES`, seeds `SEEDS` (a different
training subset per seed; at the full split every seed trains on the same examples, with its own initialisation and
batch order), and `WIDE_VARIANTS` once at the paper's widths at the full split. At ``paper_full`` scale the same
pushes, subsets and test sequences are rendered at the paper's images and every model has the paper's widths (a GPU's
run). Each model trains by the convergence criterion of `pushjax.train.convergence` (constant rate until its validation
score stops improving, within a budget growing with the size, then a short decay), a stopping rule of the one trainer
(`pushjax.train.sweep`), or by the paper's fixed budget.

A unit of work is one model; `run` reads the training rows the models it may train use (`read_training_examples`: the
whole split once one trains on it) and trains them in order, one or a few at once (threads sharing those rows; a
model's record does not depend on how many). When it is trained and evaluated, its record -- the test row of ``results.json``
(per-sequence sums included, for the bootstrap), the criterion's verdict, its steps and validation curve -- is written
to ``<workdir>/models/<key>.json`` (a few tens of KiB), and ``results.json``, ``results.md`` and the figures are
assembled again from every record present. A later run with the same work directory skips every model that has a
record, so the run resumes across sittings and fresh checkouts as long as the records are kept (committed); a
model interrupted before its record is written continues from its training state, saved every 1 000 steps to
``<workdir>/in_training/<key>/`` (the trainer's work directory of that model: ``checkpoints/``, ``metrics.csv``;
removed once the record is written, kept under a fixed budget to be continued further), to the same
parameters and record as without the interruption. Commit that folder with the records when a sitting ends (a few
hundred KiB per model, a few MiB for the wide ones) and a fresh checkout continues those models too. The dataset is rebuilt from its
seed when missing; the digests of the build the baselines were scored on are kept in ``<workdir>/dataset.sha256``, a run
on another build (a rebuild on other hardware may differ in its last bits) says so, and every record names its build
(``dataset_sha256``) and the digest of its final parameters (``params_sha256``). Each trained model's parameters go to ``<workdir>/checkpoints/<key>/`` (not committed), from which
``pushjax.load_model(workdir, model=key)`` loads it to predict; models recorded before the run kept them have none.
"""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import json
import shutil
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import jax
import numpy as np

from pushjax import outputs, provenance as provenance_lib, train as train_lib
from pushjax.models import ModelConfig
from pushjax.paper import runner, spec as spec_lib
from pushjax.train import convergence

NAME = "data_efficiency_full"
FULL = 190_080
"""The training split of ``data_efficiency`` at ``cpu_full`` scale, examples."""
SIZES = (2_500, 5_000, 10_000, 20_000, 50_000, 100_000, FULL)
SIDE_SIZES = (2_500, 20_000, FULL)
SEEDS = (0, 1, 2)
MAIN_VARIANTS = ("neural", "hybrid", "error")
SIDE_VARIANTS = ("simple", "neural_dyn")
WIDE_VARIANTS = ("neural", "hybrid")
"""Trained once (seed 0) at the full split with the paper's widths (`pushjax.models.ModelConfig`'s defaults)."""
SCALE = "cpu_full"
CHECKPOINTS = "checkpoints"
"""The work directory's folder of one checkpoint folder per trained model (named by its key)."""
IN_TRAINING = "in_training"
"""The work directory's folder of the training state of each model being trained (named by its key)."""
DATASET_DIGESTS = "dataset.sha256"
"""The work directory's record of the dataset build its baselines were scored on: the sha256 of every data file
(``sha256sum`` format, `pushjax.provenance.file_digests`), written with ``baselines.json``."""


@dataclasses.dataclass(frozen=True)
class Unit:
    """One model of the run."""

    variant: str
    size: int
    seed: int
    wide: bool = False

    @property
    def key(self) -> str:
        return f"{self.variant}_{self.size}_seed{self.seed}" + ("_wide" if self.wide else "")

    @property
    def model(self) -> str:
        """The model's name in ``results.json``: the variant, ``_wide`` for the paper's widths."""
        return self.variant + ("_wide" if self.wide else "")


def plan(sizes: Sequence[int] = SIZES, seeds: Sequence[int] = SEEDS, side_sizes: Sequence[int] = SIDE_SIZES,
         wide: bool = True, variants: Sequence[str] | None = None) -> list[Unit]:
    """Every model of the run in the order it trains: by size, then variant, then seed; the wide models last.
    With `variants`, only the models of those variants."""
    units = []
    for size in sizes:
        size_variants = MAIN_VARIANTS + (SIDE_VARIANTS if size in side_sizes else ())
        units += [Unit(variant, size, seed) for variant in size_variants for seed in seeds]
    if wide:
        units += [Unit(variant, max(sizes), seeds[0], wide=True) for variant in WIDE_VARIANTS]
    if variants is not None:
        unknown = sorted(set(variants) - {*MAIN_VARIANTS, *SIDE_VARIANTS})
        if unknown:
            raise ValueError(f"variants: {', '.join(unknown)} not trained by this run; choose from "
                             f"{', '.join((*MAIN_VARIANTS, *SIDE_VARIANTS))}")
        units = [unit for unit in units if unit.variant in variants]
    return units


def select(units: Sequence[Unit], keys: Sequence[str]) -> list[Unit]:
    """The `units` named by `keys`, in the order of `keys`; raises ``ValueError`` naming a key not among them."""
    by_key = {unit.key: unit for unit in units}
    unknown = [key for key in keys if key not in by_key]
    if unknown:
        raise ValueError(f"{', '.join(unknown)} not in the plan; its models are {', '.join(by_key)}")
    return [by_key[key] for key in dict.fromkeys(keys)]


def setup(sizes: Sequence[int] = SIZES) -> spec_lib.Setup:
    return spec_lib.Setup(NAME, "data_efficiency", (*MAIN_VARIANTS, *SIDE_VARIANTS, "zero", "physics"),
                          sizes=tuple(sizes))


def make_spec(data_dir: str | None = None, *, sizes: Sequence[int] = SIZES, seeds: Sequence[int] = SEEDS,
              scale: str = SCALE, build: bool = True, workers: int | None = None,
              paper_training: bool = False) -> spec_lib.ExperimentSpec:
    """The run's `ExperimentSpec` (``sequential`` mode: each model is trained on its own, not stacked with others);
    with `paper_training`, the paper's learning rate and batch size replace the scale's
    (`pushjax.train.convergence.PAPER_SCHEDULE`'s models)."""
    overrides = None if not paper_training else {"learning_rate": repr(convergence.PAPER_LEARNING_RATE),
                                                 "batch_size": str(convergence.PAPER_BATCH_SIZE)}
    return spec_lib.make_spec(setup(sizes), scale, sizes=sizes, seeds=seeds, data_dir=data_dir, build=build,
                              workers=workers, mode="sequential", config_overrides=overrides)


def needs_training(unit: Unit, done: Mapping[str, dict], criterion: convergence.Criterion, split_size: int) -> bool:
    """Whether `unit` has no record in `done`, or, with a fixed budget, a record of fewer steps than the budget (it is
    continued from its kept training state)."""
    record = done.get(unit.key)
    if record is None:
        return True
    return not criterion.stop_on_plateau and record["row"]["steps"] < criterion.budget(min(unit.size, split_size))


def _write_json(path: Path, contents) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(path.name + ".partial")
    partial.write_text(json.dumps(contents, indent=1) + "\n")
    partial.replace(path)


def records(workdir: str | Path) -> dict[str, dict]:
    """key -> record of every finished model in ``<workdir>/models``."""
    folder = Path(workdir) / "models"
    return {path.stem: json.loads(path.read_text()) for path in sorted(folder.glob("*.json"))}


def train_config(spec: spec_lib.ExperimentSpec, unit: Unit) -> train_lib.TrainConfig:
    config = spec.train_config(unit.variant)
    if unit.wide:
        model = dataclasses.replace(ModelConfig(), variant=unit.variant, view=config.model.view,
                                    glimpse_size=config.model.glimpse_size)
        config = dataclasses.replace(config, model=model)
    return config


@dataclasses.dataclass(frozen=True)
class TrainingExamples:
    """The rows of the training split that the models to train read (all of it when one trains on the full split).

    Attributes:
      examples: {field: [M, ...] array} of split rows `rows`.
      rows: [M] sorted indices of those rows into the training split.
      split_size: examples in the training split.
    """

    examples: Mapping[str, np.ndarray]
    rows: np.ndarray
    split_size: int

    def model_spec(self, unit: Unit) -> train_lib.ModelSpec:
        """`unit`'s training subset (`pushjax.train.subset_specs` of the whole split) as indices into `examples`."""
        (model_spec,) = train_lib.subset_specs(self.split_size, (min(unit.size, self.split_size),), (unit.seed,))
        return dataclasses.replace(model_spec, train_indices=np.searchsorted(self.rows, model_spec.train_indices))


def read_training_examples(source, fields: Sequence[str], units: Sequence[Unit]) -> TrainingExamples:
    """The rows of the training split `source` in any of the `units`' subsets, read into memory.

    A model's batches depend only on its subset of the whole split, so models trained on these rows are the ones
    trained on the whole split in memory; at the smaller sizes far fewer rows are read (at 20 000 examples, the three
    seeds' subsets are about 55 000 of the 190 080)."""
    split_size = len(source)
    subsets = [spec.train_indices for unit in units for spec in train_lib.subset_specs(
        split_size, (min(unit.size, split_size),), (unit.seed,))]
    rows = np.unique(np.concatenate(subsets)) if subsets else np.zeros(0, dtype=np.int64)
    return TrainingExamples(train_lib.examples_from_source(source, fields, rows), rows, split_size)


def train_unit(spec: spec_lib.ExperimentSpec, unit: Unit, train_examples: TrainingExamples, validation: Mapping,
               test: Mapping, criterion: convergence.Criterion = convergence.CRITERION,
               log: Callable[[str], None] | None = None, checkpoint_dir: str | Path | None = None,
               resume_dir: str | Path | None = None, provenance: Mapping[str, str] | None = None) -> dict:
    """Trains and evaluates one model by `criterion` (`pushjax.train.sweep`, one model); returns its record. With
    `checkpoint_dir`, its parameters go to a checkpoint there (`pushjax.train.predictor.save_model`, replacing any
    earlier one); with `resume_dir`, it trains in that work directory of the trainer (its training state saved at
    every score, ``metrics.csv`` every score, TensorBoard) and a later call continues from it. `provenance` is the
    code's commit (and the diff of changed code, `pushjax.provenance.write_source_diff`) as the run started, and the
    dataset build's ``dataset_sha256`` (`check_dataset`); None: the checkout's commit now. The record's
    ``params_sha256`` is the digest of the model's final variables (`pushjax.provenance.tree_digest`), so that a
    retraining can be checked bit-identical without the checkpoint."""
    model_spec = train_examples.model_spec(unit)
    size = len(model_spec.train_indices)
    config = dataclasses.replace(train_config(spec, unit), log_every=criterion.eval_every)
    started = datetime.datetime.now(datetime.timezone.utc)
    resumed = train_lib.resumed_step(resume_dir)
    if resumed and log is not None:
        log(f"continues from step {resumed}")
    trained = train_lib.sweep(config, train_examples.examples, [model_spec], resume_dir, mode=spec.mode,
                              progress=False, criterion=criterion, validation=validation, log=log, keep_checkpoints=1)
    phases, state = trained.phases, trained.model_state(0)
    if checkpoint_dir is not None:
        shutil.rmtree(checkpoint_dir, ignore_errors=True)  # a model killed before its record was written
        train_lib.predictor.save_model(checkpoint_dir, phases.steps, config.model, model_spec, state)
    clock = time.monotonic()
    (metrics,) = trained.evaluate(test, config.eval_batch_size)
    row = runner.trained_row(unit.model, "train", "test", model_spec, 1.0, phases.steps, metrics,
                             converged=phases.converged, constant_steps=phases.constant_steps,
                             decay_steps=phases.decay_steps)
    return outputs.compact({
        "key": unit.key, "unit": dataclasses.asdict(unit), "row": runner.finite_or_none(row),
        "validation": [{"step": step, "trans_percent": trans, "rot_percent": rot}
                       for step, trans, rot in phases.validation],
        "criterion": dataclasses.asdict(criterion), "budget": criterion.budget(size),
        "parameters": int(sum(np.size(leaf) for leaf in jax.tree.leaves(state.params))),
        "train_seconds": round(phases.seconds, 1), "eval_seconds": round(time.monotonic() - clock, 1),
        "steps_per_second": phases.steps_per_second, "started": started.isoformat(timespec="seconds"),
        "device": device_description(),
        "params_sha256": provenance_lib.tree_digest(train_lib.predictor.checkpoint_variables(state)),
        **(provenance if provenance is not None else
           ({"commit": commit} if (commit := provenance_lib.git_commit()) else {})),
    })


def check_dataset(workdir: Path, digests: Mapping[str, str], log: Callable[[str], None]) -> str:
    """Compares the dataset build being read (`digests`, `pushjax.provenance.file_digests`) with the one the run's
    baselines were scored on (`DATASET_DIGESTS`, written with ``baselines.json``; a run whose baselines predate it has
    none, and this says so), logs a line where they differ, and returns the build's digest (the sha256 of its
    `DATASET_DIGESTS` text), which every record names."""
    build = hashlib.sha256(provenance_lib.digests_text(digests).encode()).hexdigest()
    path = workdir / DATASET_DIGESTS
    if not path.exists():
        log(f"{NAME}: {path} is missing (baselines scored before builds were recorded), so this build "
            f"({len(digests)} data files) cannot be compared with theirs; each record names its build by dataset_sha256")
        return build
    recorded = provenance_lib.parse_digests(path.read_text())
    differing = sorted(name for name in set(recorded) | set(digests) if recorded.get(name) != digests.get(name))
    if differing:
        log(f"{NAME}: the dataset build read here differs from the one the baselines were scored on ({path}) in "
            f"{len(differing)} of {len(set(recorded) | set(digests))} data files ({', '.join(differing[:3])}"
            f"{', …' if len(differing) > 3 else ''}); each record names its build by dataset_sha256")
    return build


def device_description() -> dict:
    """What trained a model: JAX's platform and device kind, and the precision of float32 matrix products (the
    GPU's default, TF32, is coarser than the CPU's)."""
    device = jax.devices()[0]
    return {"platform": device.platform, "kind": device.device_kind,
            "matmul_precision": str(jax.config.jax_default_matmul_precision or "default")}


def baseline_rows(spec: spec_lib.ExperimentSpec, test: Mapping) -> list[dict]:
    return [runner.finite_or_none(row) for row in runner._baseline_rows(spec, {"test": test}, 1.0)]


def assemble(spec: spec_lib.ExperimentSpec, workdir: str | Path, units: Sequence[Unit],
             criterion: convergence.Criterion = convergence.CRITERION) -> dict:
    """``results.json`` from the baselines and every finished model's record (schema of `pushjax.paper.runner`;
    trained rows carry ``converged``, ``constant_steps`` and ``decay_steps``; ``curves`` are the validation
    curves; ``progress`` says how many of the planned models are done)."""
    workdir = Path(workdir)
    done = records(workdir)
    baselines = json.loads((workdir / "baselines.json").read_text())
    rows = baselines + [record["row"] for key, record in done.items()]
    curves = [{"model": record["row"]["model"], "train_split": "train", "train_size": record["row"]["train_size"],
               "seed": record["row"]["seed"], "l_scale": 1.0, "step": point["step"], "split": "validation",
               "trans_percent": point["trans_percent"], "rot_percent": point["rot_percent"]}
              for record in done.values() for point in record["validation"]]
    config = spec.to_json()
    config["criterion"] = dataclasses.asdict(criterion)
    config["planned_models"] = [unit.key for unit in units]
    train_seconds = sum(record["train_seconds"] + record["eval_seconds"] for record in done.values())
    return {"name": NAME, "config": config, "rows": rows, "curves": curves,
            "progress": {"planned": len(units), "done": sum(unit.key in done for unit in units),
                         "missing": [unit.key for unit in units if unit.key not in done]},
            "provenance": {**({"commit": commit} if (commit := provenance_lib.git_commit()) else {}),
                           "model_seconds": round(train_seconds, 1)}}


def run(spec: spec_lib.ExperimentSpec, workdir: str | Path, units: Sequence[Unit], *,
        max_models: int | None = None, deadline: datetime.datetime | None = None,
        criterion: convergence.Criterion = convergence.CRITERION, progress: bool = True,
        publish: Callable[[dict], None] | None = None, log: Callable[[str], None] = print,
        models_at_once: int = 1) -> dict:
    """Trains the `units` that have no record in `workdir`, in order, writing each record when it is done.

    Args:
      spec: `make_spec`.
      workdir: the records (``models/``), ``baselines.json``, ``results.json``, the models' checkpoints
        (``checkpoints/``) and the training state of a model being trained (``in_training/``).
      units: `plan`.
      max_models: train at most this many models in this call (None: all).
      deadline: start no model after this time (UTC).
      criterion: the convergence criterion.
      progress: progress bars of the dataset build.
      publish: called with ``results.json``'s contents after it is written (e.g. tables and figures).
      log: progress lines.
      models_at_once: models trained at the same time, each in its own thread on the one copy of the training split
        (the next unit in order goes to the first thread that is free). A model's parameters and record do not
        depend on it; on 2 CPU cores two models at once train 1.15-1.4x the model-steps per second of one
        (BENCHMARKS.md), while each record's ``train_seconds`` and ``steps_per_second`` count the shared cores.
    """
    if models_at_once < 1:
        raise ValueError(f"models_at_once: expected at least 1, got {models_at_once}")
    log = _one_line_at_a_time(log)
    workdir = Path(workdir)
    fields = spec.example_fields()
    splits = runner.load_splits(spec, spec.dataset, progress)
    test = train_lib.examples_from_source(splits["test"], fields)
    digests = provenance_lib.file_digests(runner.dataset_folder(spec, spec.dataset))
    if not (workdir / "baselines.json").exists():
        _write_json(workdir / "baselines.json", outputs.compact(baseline_rows(spec, test)))
        (workdir / DATASET_DIGESTS).write_text(provenance_lib.digests_text(digests))
    dataset = check_dataset(workdir, digests, log)
    done = records(workdir)
    todo = [unit for unit in units if needs_training(unit, done, criterion, len(splits["train"]))]
    provenance = provenance_lib.write_source_diff(workdir, provenance_lib.source_state())  # the code this process runs
    log(f"{NAME}: {len(units) - len(todo)} of {len(units)} models recorded in {workdir}/models, {len(todo)} to train")
    if todo and (max_models is None or max_models > 0):
        validation = train_lib.examples_from_source(splits["validation"], fields)
        clock = time.monotonic()
        train_examples = read_training_examples(splits["train"], fields, todo[:max_models])
        log(f"{NAME}: read {len(train_examples.rows)} of the {train_examples.split_size} training examples (the "
            f"models to train read them) in {time.monotonic() - clock:.0f} s")
        queue = _UnitQueue(todo, max_models, deadline, log)
        written = threading.Lock()

        def train_queued() -> None:
            while (unit := queue.next()) is not None:
                log(f"{NAME}: training {unit.key} (budget "
                    f"{criterion.budget(min(unit.size, train_examples.split_size))} constant-rate steps)")
                try:
                    record = train_unit(spec, unit, train_examples, validation, test, criterion,
                                        lambda line, key=unit.key: log(f"[{key}] {line}"),
                                        workdir / CHECKPOINTS / unit.key, workdir / IN_TRAINING / unit.key,
                                        {**provenance, "dataset_sha256": dataset})
                except BaseException:
                    queue.stop()  # no thread starts another model
                    raise
                with written:
                    _write_json(workdir / "models" / f"{unit.key}.json", record)
                    if criterion.stop_on_plateau:  # a fixed budget keeps its state, to be continued further
                        shutil.rmtree(workdir / IN_TRAINING / unit.key)
                    row = record["row"]
                    log(f"{NAME}: recorded {unit.key}: {row['steps']} steps "
                        f"({'converged' if row['converged'] else 'budget'}), test trans {row['trans_percent']:.1f} % "
                        f"rot {row['rot_percent']:.1f} %, {record['train_seconds']:.0f} s at "
                        f"{record['steps_per_second']:.1f} steps/s")
                    results = write_results(spec, workdir, units, criterion)
                    if publish is not None:
                        publish(results)

        _in_threads(train_queued, models_at_once)
    results = write_results(spec, workdir, units, criterion)
    if publish is not None:
        publish(results)
    return results


class _UnitQueue:
    """The units still to train, handed out in order to the threads of `run` until `max_models` have started, the
    `deadline` has passed or a thread failed."""

    def __init__(self, todo: Sequence[Unit], max_models: int | None, deadline: datetime.datetime | None,
                 log: Callable[[str], None]):
        self._todo, self._max_models, self._deadline, self._log = list(todo), max_models, deadline, log
        self._started, self._stopped, self._lock = 0, False, threading.Lock()

    def next(self) -> Unit | None:
        with self._lock:
            if self._stopped or self._started == len(self._todo):
                return None
            unit = self._todo[self._started]
            if self._max_models is not None and self._started >= self._max_models:
                self._stopped = True
                return None
            if self._deadline is not None and datetime.datetime.now(datetime.timezone.utc) >= self._deadline:
                self._log(f"{NAME}: deadline {self._deadline.isoformat(timespec='minutes')} passed; stopping before "
                          f"{unit.key}")
                self._stopped = True
                return None
            self._started += 1
            return unit

    def stop(self) -> None:
        with self._lock:
            self._stopped = True


def _one_line_at_a_time(log: Callable[[str], None]) -> Callable[[str], None]:
    """`log` for several threads: one line at a time (``print`` from two threads can run their lines together)."""
    lock = threading.Lock()

    def locked(line: str) -> None:
        with lock:
            log(line)

    return locked


def _in_threads(work: Callable[[], None], count: int) -> None:
    """Runs `work` in `count` threads (in this one when `count` is 1) and re-raises the first error of any of them as
    soon as it happens. The threads are daemons: an interrupted or failed run exits without waiting for the other
    models being trained (their training state is saved every `convergence.Criterion.eval_every` steps)."""
    if count == 1:
        work()
        return
    errors: list[BaseException] = []

    def guarded() -> None:
        try:
            work()
        except BaseException as error:  # re-raised in the calling thread
            errors.append(error)

    threads = [threading.Thread(target=guarded, daemon=True, name=f"{NAME}-{index}") for index in range(count)]
    for thread in threads:
        thread.start()
    while not errors and any(thread.is_alive() for thread in threads):
        time.sleep(0.5)
    if errors:
        raise errors[0]


def with_models_of(results: Mapping, workdir: str | Path) -> dict:
    """`results` (a run's ``results.json``) with every trained cell (model, size) that the run in `workdir` recorded
    replaced by that run's models, and the baselines replaced by that run's (its test split), e.g. Table 1 with its
    models at the full split trained for the paper's 75 000 steps instead of to the criterion. Records which cells
    came from where in ``replaced``."""
    workdir = Path(workdir)
    other = [record["row"] for record in records(workdir).values()]
    cells = {(row["model"], row["train_size"]) for row in other}
    baselines = json.loads((workdir / "baselines.json").read_text())
    kept = [row for row in results["rows"]
            if row["kind"] == "trained" and (row["model"], row["train_size"]) not in cells]
    return {**results, "rows": baselines + kept + other,
            "curves": [curve for curve in results.get("curves", [])
                       if (curve["model"], curve["train_size"]) not in cells],
            "replaced": {"workdir": str(workdir), "cells": sorted([model, size] for model, size in cells),
                         "baselines": True}}


def write_results(spec: spec_lib.ExperimentSpec, workdir: str | Path, units: Sequence[Unit],
                  criterion: convergence.Criterion = convergence.CRITERION) -> dict:
    results = assemble(spec, workdir, units, criterion)
    _write_json(Path(workdir) / "results.json", results)
    return results
