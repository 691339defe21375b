"""Training configurations per scale (`pushjax.data.SCALES`): `smoke` (tests, seconds), `cpu` (a laptop), `paper`."""

from __future__ import annotations

import dataclasses
import importlib
import typing
from collections.abc import Mapping

from pushjax.data.configs import DatasetConfig
from pushjax.models import ModelConfig
from pushjax.train import train_state


@dataclasses.dataclass(frozen=True)
class TrainConfig:
    """Everything a training run needs besides the data.

    Attributes:
      model: the architecture (its `variant` is usually overridden per run).
      learning_rate: Adam step size (the initial one with a decaying schedule).
      schedule: the learning-rate schedule (`pushjax.train.train_state.SCHEDULES`): ``"constant"`` (the paper's) or
        ``"cosine"`` (decayed over `num_steps`, so resuming a sweep with another `num_steps` changes the rest of its
        schedule).
      batch_size: examples per step and model.
      num_steps: optimisation steps per model.
      weight_decay: lambda of the 0.5 * |w|^2 kernel penalty.
      log_every: steps between metric rows in the log (and progress-bar updates).
      checkpoint_every: steps between checkpoints (the last step is always saved).
      eval_batch_size: examples per evaluation batch.
      curve_examples: examples per model and split of the learning curves (`pushjax.train.curves`).
    """

    model: ModelConfig
    learning_rate: float = 1e-4
    schedule: str = "constant"
    batch_size: int = 32
    num_steps: int = 75_000
    weight_decay: float = 1e-3
    log_every: int = 100
    checkpoint_every: int = 5_000
    eval_batch_size: int = 256
    curve_examples: int = 1024

    def __post_init__(self):
        for name in ("batch_size", "num_steps", "log_every", "checkpoint_every", "eval_batch_size",
                     "curve_examples"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name}: expected a positive integer, got {getattr(self, name)}")
        if self.learning_rate <= 0:
            raise ValueError(f"learning_rate: expected > 0, got {self.learning_rate}")
        if self.schedule not in train_state.SCHEDULES:
            raise ValueError(f"schedule: expected one of {', '.join(train_state.SCHEDULES)}, got {self.schedule!r}")

    def with_variant(self, variant: str, view: str | None = None) -> "TrainConfig":
        """This config with the model's variant (and optionally view) replaced."""
        model = dataclasses.replace(self.model, variant=variant, view=view or self.model.view)
        return dataclasses.replace(self, model=model)


def get_config(dataset: DatasetConfig) -> TrainConfig:
    """The `TrainConfig` for training on `dataset`.

    The dataset's scale picks the architecture and schedule (``pushjax/train/configs/<scale>.py``), its camera
    the model's view and its glimpse size the model's (the glimpse is cut from the dataset's images, so its
    size in pixels belongs to the data).
    """
    config = importlib.import_module(f"pushjax.train.configs.{dataset.scale}").get_config()
    model = dataclasses.replace(config.model, view=dataset.camera, glimpse_size=dataset.glimpse_size)
    return dataclasses.replace(config, model=model)


FIXED_BY_RUN = ("model.variant", "model.view")
"""Fields a run sets itself (its variants and its dataset's camera), which `override` does not take."""


def _field_types(config_type: type, prefix: str = "") -> dict[str, type]:
    types = {}
    for name, field_type in typing.get_type_hints(config_type).items():
        if dataclasses.is_dataclass(field_type):
            types.update(_field_types(field_type, f"{prefix}{name}."))
        elif f"{prefix}{name}" not in FIXED_BY_RUN:
            types[f"{prefix}{name}"] = field_type
    return types


OVERRIDABLE_FIELDS: dict[str, type] = _field_types(TrainConfig)
"""Dotted field path (``learning_rate``, ``model.head_features``) -> its type: what `override` takes."""


def _parse(path: str, field_type: type, text: str) -> object:
    """`text` as a value of `field_type` (int, float, str or a tuple of ints); ValueError naming `path`."""
    try:
        if typing.get_origin(field_type) is tuple:
            return tuple(int(item) for item in text.split(",") if item.strip())
        return field_type(text)
    except ValueError:
        expected = {int: "an integer", float: "a number"}.get(field_type, "comma-separated integers")
        raise ValueError(f"config.{path}: expected {expected}, got {text!r}") from None


def override(config: TrainConfig, overrides: Mapping[str, str]) -> TrainConfig:
    """`config` with fields replaced from the command line (``--config.<path>=<text>``).

    Args:
      config: the scale's config.
      overrides: dotted field path (a key of `OVERRIDABLE_FIELDS`) -> its new value as text (tuples of ints comma
        separated, e.g. ``"64,32"``).

    Raises:
      ValueError: one line naming ``config.<path>``: a field that does not exist, a value of the wrong type or one
        the config rejects.
    """
    values = {}
    for path, text in overrides.items():
        if path not in OVERRIDABLE_FIELDS:
            fixed = " (set by the run itself)" if path in FIXED_BY_RUN else ""
            raise ValueError(f"config.{path}: no such training-config field{fixed}; "
                             f"expected one of {', '.join(OVERRIDABLE_FIELDS)}")
        values[path] = _parse(path, OVERRIDABLE_FIELDS[path], text)
    model_values = {path.removeprefix("model."): value for path, value in values.items() if path.startswith("model.")}
    try:
        model = dataclasses.replace(config.model, **model_values)
    except ValueError as error:
        raise ValueError(f"config.model.{error}") from None
    try:
        return dataclasses.replace(config, model=model, **{path: value for path, value in values.items()
                                                           if not path.startswith("model.")})
    except ValueError as error:
        raise ValueError(f"config.{error}") from None
