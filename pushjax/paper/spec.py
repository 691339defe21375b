"""What one run of a paper experiment trains and evaluates, resolved once from the flags.

`make_spec` turns an experiment's `Setup` (what the paper's table or figure needs) and the user's choices
(scale, sizes, seeds, ...) into a frozen `ExperimentSpec`: the dataset configs, the training config, the
splits, variants and baselines. Everything below (`pushjax.paper.runner`, the tables and figures) reads the
spec and never re-derives it from names.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import jax

from pushjax.data import configs as data_configs
from pushjax.models import ERROR_OPTIONS, VARIANTS
from pushjax.sim.testbed import DEFAULT_PROFILE
from pushjax.paper.baselines import BASELINES, BASELINE_FIELDS
from pushjax.train import EVALUATION_FIELDS, SWEEP_MODES, TrainConfig, model_fields
from pushjax.train import configs as train_configs

MODELS = (*VARIANTS, *BASELINES)
"""Everything an experiment can report: the trained variants and the baselines."""


@dataclasses.dataclass(frozen=True)
class Setup:
    """What one of the paper's experiments runs, before the user's choices.

    Attributes:
      name: the experiment's name, which also picks its tables and figures.
      experiment: the dataset experiment trained on (`pushjax.data.EXPERIMENTS`).
      models: variants to train and baselines to evaluate, by default.
      train_splits: training splits, each trained separately.
      test_splits: test splits; every model is evaluated on each.
      test_experiment: the dataset experiment the test splits come from (None: `experiment`).
      sizes: training-set sizes by default (empty: the whole split).
      l_scales: factors applied to the limit-surface ratio ``l`` of all examples (Table 5).
      l_scaled_models: the models run at factors other than 1 (None: all).
      test_fields: example fields kept in the test sets besides those the models read (e.g. for plots).
    """

    name: str
    experiment: str
    models: tuple[str, ...]
    train_splits: tuple[str, ...] = ("train",)
    test_splits: tuple[str, ...] = ("test",)
    test_experiment: str | None = None
    sizes: tuple[int, ...] = ()
    l_scales: tuple[float, ...] = (1.0,)
    l_scaled_models: tuple[str, ...] | None = None
    test_fields: tuple[str, ...] = ()


_PAPER_SIZES = (2_500, 190_000)
_VELOCITY_TESTS = tuple(f"test_{v:g}" for v in data_configs.TEST_VELOCITIES)
SETUPS = {setup.name: setup for setup in (
    Setup("data_efficiency", "data_efficiency", (*VARIANTS, *BASELINES), sizes=_PAPER_SIZES),
    Setup("new_pushes", "new_pushes", ("neural", "neural_dyn", "hybrid", "simple", "error", *BASELINES),
          sizes=_PAPER_SIZES),
    Setup("velocities", "velocities", ("neural", "neural_dyn", "simple", "hybrid", "error", *BASELINES),
          tuple(data_configs.VELOCITY_TRAIN_SETS), _VELOCITY_TESTS),
    Setup("error_velocities", "velocities", ("neural", "hybrid", *ERROR_OPTIONS, *BASELINES), ("train_20",),
          _VELOCITY_TESTS),
    Setup("objects", "objects", ("neural", "hybrid", "error", *BASELINES),
          tuple(data_configs.OBJECT_TRAIN_SETS), tuple(data_configs.OBJECT_TEST_SETS)),
    Setup("error_variants", "data_efficiency", ("hybrid", *ERROR_OPTIONS, *BASELINES), sizes=_PAPER_SIZES,
          l_scales=(1.0, 1.5, 3.0), l_scaled_models=("physics", "hybrid", "error")),
    Setup("viewpoint", "viewpoint", ("hybrid", *BASELINES)),
    Setup("rollouts", "velocities", ("neural", "hybrid", "error", *BASELINES), ("train_20",), _VELOCITY_TESTS),
    Setup("visualize", "data_efficiency", ("neural", "hybrid", "simple", "error"), test_experiment="repeated",
          test_fields=("scene_transform",)),
)}
"""The paper's experiments, one per binary under ``experiments/``."""


@dataclasses.dataclass(frozen=True)
class ExperimentSpec:
    """One run, fully resolved: what to train on which data, what to evaluate on which splits.

    Attributes:
      name: the experiment's name (`Setup.name`).
      dataset: the training dataset's config.
      test_dataset: the test splits' dataset config (usually `dataset`).
      train: the training config of every variant, the variant aside (view and glimpse size from the
        dataset, the scale's schedule or the user's number of steps).
      variants: model variants to train; error variants train side by side in one sweep.
      baselines: baselines to evaluate (`pushjax.paper.baselines.BASELINES`).
      train_splits: training splits, each trained separately.
      test_splits: splits of `test_dataset`; every model is evaluated on each.
      sizes: training-set sizes (clipped to each split's size; empty: the whole split).
      seeds: subset and initialisation seeds.
      l_scales: factors applied to the limit-surface ratio ``l`` of all examples.
      l_scaled_models: models run at factors other than 1 (None: all).
      test_fields: extra example fields kept in the test sets.
      data_dir: TFDS data directory (None: TFDS's default).
      build: build a dataset when it is missing.
      workers: dataset build processes (None: the builder's default).
      mode: sweep mode (`pushjax.train.SWEEP_MODES`).
    """

    name: str
    dataset: data_configs.DatasetConfig
    test_dataset: data_configs.DatasetConfig
    train: TrainConfig
    variants: tuple[str, ...]
    baselines: tuple[str, ...]
    train_splits: tuple[str, ...]
    test_splits: tuple[str, ...]
    sizes: tuple[int, ...]
    seeds: tuple[int, ...]
    l_scales: tuple[float, ...]
    l_scaled_models: tuple[str, ...] | None
    test_fields: tuple[str, ...]
    data_dir: str | None
    build: bool
    workers: int | None
    mode: str
    config_overrides: tuple[tuple[str, str], ...] = ()

    @property
    def scale(self) -> str:
        return self.dataset.scale

    def train_config(self, variant: str) -> TrainConfig:
        """The training config of `variant`."""
        return self.train.with_variant(variant)

    def sweep_groups(self) -> list[tuple[str, ...]]:
        """The variants trained together: one sweep per variant, the error variants in one shared sweep."""
        errors = tuple(variant for variant in self.variants if variant in ERROR_OPTIONS)
        return [(variant,) for variant in self.variants if variant not in ERROR_OPTIONS] + ([errors] if errors else [])

    def sweep_groups_at(self, l_scale: float) -> list[tuple[str, ...]]:
        """`sweep_groups` limited to the variants run with the limit-surface ratio scaled by `l_scale`."""
        groups = [tuple(variant for variant in group if self.runs_at(variant, l_scale)) for group in self.sweep_groups()]
        return [group for group in groups if group]

    def runs_at(self, model: str, l_scale: float) -> bool:
        """Whether `model` is run with the limit-surface ratio scaled by `l_scale`."""
        return l_scale == 1.0 or self.l_scaled_models is None or model in self.l_scaled_models

    def example_fields(self) -> tuple[str, ...]:
        """Every example field that training, evaluation and the baselines read."""
        return tuple(dict.fromkeys((*model_fields(self.train.model), *EVALUATION_FIELDS, *BASELINE_FIELDS)))

    def test_split_label(self, split: str) -> str:
        """The name of a test split in results: ``<experiment>/<split>`` when it is not the training dataset's."""
        experiment = self.test_dataset.experiment
        return split if experiment == self.dataset.experiment else f"{experiment}/{split}"

    def to_json(self) -> dict:
        """The spec as the ``config`` of ``results.json``, in JSON's own types (lists, not tuples)."""
        train = dataclasses.asdict(self.train)
        del train["model"]["variant"]  # per row
        config = {
            "experiment": self.dataset.experiment, "scale": self.scale, "testbed": self.dataset.testbed,
            "variants": list(self.variants),
            "baselines": list(self.baselines), "train_splits": list(self.train_splits),
            "test_splits": list(self.test_splits), "sizes": list(self.sizes), "seeds": list(self.seeds),
            "l_scales": list(self.l_scales),
            "l_scaled_models": None if self.l_scaled_models is None else list(self.l_scaled_models),
            "num_steps": self.train.num_steps, "mode": self.mode, "data_dir": self.data_dir,
            "dataset": dataclasses.asdict(self.dataset), "train": train,
            "config_overrides": dict(self.config_overrides),
        }
        if self.test_dataset != self.dataset:
            config["test_dataset"] = dataclasses.asdict(self.test_dataset)
        return json.loads(json.dumps(config))


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


def check_data_dir(data_dir: str | os.PathLike | None) -> None:
    """Raises ``ValueError`` when `data_dir` is given but is not an existing directory."""
    if data_dir is not None and not Path(data_dir).is_dir():
        raise ValueError(f"data_dir: {data_dir} is not an existing directory")


@functools.cache
def split_names(experiment: str) -> tuple[str, ...]:
    """The splits of `experiment`'s datasets, which are the same at every scale (read from the smallest's plan)."""
    return tuple(data_configs.plan_splits(data_configs.get_config(experiment, "smoke"), "").splits)


def check_splits(setup: Setup) -> None:
    """Raises ``ValueError`` naming a training or test split of `setup` that its datasets do not have."""
    for field, experiment, names in (("train_split", setup.experiment, setup.train_splits),
                                     ("test_split", setup.test_experiment or setup.experiment, setup.test_splits)):
        known = split_names(experiment)
        unknown = [name for name in names if name not in known]
        if unknown:
            raise ValueError(f"{field}: {', '.join(map(repr, unknown))} is not a split of {experiment}; "
                             f"choose from {', '.join(known)}")


def default_mode() -> str:
    """The sweep mode that is fastest on this backend: ``sequential`` on CPU, else ``vmap``."""
    return "sequential" if jax.default_backend() == "cpu" else "vmap"


def make_spec(
    setup: Setup, scale: str = data_configs.DEFAULT_SCALE, *, models: Sequence[str] = (),
    sizes: Sequence[int | str] = (), seeds: Sequence[int | str] = (0,), num_steps: int | None = None,
    data_dir: str | os.PathLike | None = None, build: bool = True, workers: int | None = None,
    mode: str | None = None, testbed: str = DEFAULT_PROFILE, config_overrides: Mapping[str, str] | None = None,
    min_test_sequences: int = 0,
) -> ExperimentSpec:
    """The `ExperimentSpec` of `setup` with the user's choices; raises ``ValueError`` naming a bad one.

    Args:
      setup: the experiment (`SETUPS`).
      scale: dataset and training scale (`pushjax.data.SCALES`).
      models: variants and baselines replacing the setup's (empty: the setup's).
      sizes: training-set sizes replacing the setup's (empty: the setup's).
      seeds: subset and initialisation seeds.
      num_steps: training steps replacing the scale's.
      data_dir: TFDS data directory, must exist when given (None: TFDS's default).
      build: build a dataset when it is missing.
      workers: dataset build processes (None: the builder's default).
      mode: sweep mode (None: `default_mode`).
      testbed: the testbed profile the datasets are simulated with (`pushjax.sim.testbed.PROFILES`).
      config_overrides: training-config fields replaced after the scale's config and `num_steps`, as text
        (`pushjax.train.configs.override`: ``{"learning_rate": "3e-4", "model.head_features": "64,32"}``).
      min_test_sequences: 0, or evaluate on the test splits grown to this many sequences, a dataset of their own
        that shares no sequence with the training and validation splits (`pushjax.data.configs.get_config`).
    """
    models = parse_models(models or setup.models)
    sizes = parse_sizes(sizes or setup.sizes)
    seeds = parse_seeds(seeds)
    check_data_dir(data_dir)
    check_splits(setup)
    if num_steps is not None and num_steps < 1:
        raise ValueError(f"num_steps: expected a positive integer, got {num_steps}")
    if mode is not None and mode not in SWEEP_MODES:
        raise ValueError(f"mode: expected one of {', '.join(SWEEP_MODES)}, got {mode!r}")
    if workers is not None and workers < 1:
        raise ValueError(f"workers: expected a positive integer, got {workers}")
    dataset = data_configs.get_config(setup.experiment, scale, testbed=testbed)
    test_dataset = dataset
    if setup.test_experiment or min_test_sequences:
        test_dataset = data_configs.get_config(setup.test_experiment or setup.experiment, scale, testbed=testbed,
                                               min_test_sequences=min_test_sequences)
    train = train_configs.get_config(dataset)
    train = dataclasses.replace(train, num_steps=num_steps or train.num_steps)
    train = train_configs.override(train, config_overrides or {})
    return ExperimentSpec(
        name=setup.name, dataset=dataset, test_dataset=test_dataset, train=train,
        variants=tuple(model for model in models if model in VARIANTS),
        baselines=tuple(model for model in models if model in BASELINES),
        train_splits=setup.train_splits, test_splits=setup.test_splits, sizes=sizes, seeds=seeds,
        l_scales=setup.l_scales, l_scaled_models=setup.l_scaled_models, test_fields=setup.test_fields,
        data_dir=None if data_dir is None else os.fspath(data_dir), build=build, workers=workers,
        mode=mode or default_mode(), config_overrides=tuple((config_overrides or {}).items()),
    )
