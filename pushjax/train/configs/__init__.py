"""Training configurations per scale (`pushjax.data.SCALES`): `smoke` (tests, seconds), `cpu` (a laptop),
`cpu_full` and `paper_full` (issue 30's run, trained by a convergence criterion), `paper`."""

from __future__ import annotations

import dataclasses
import math
import re
import typing
from collections.abc import Callable, Mapping

from pushjax.data.configs import DatasetConfig
from pushjax.train.configs import cpu, cpu_full, paper, paper_full, smoke
from pushjax.train.configs.train_config import TrainConfig

SCALE_CONFIGS: dict[str, Callable[[], TrainConfig]] = {
    "smoke": smoke.get_config, "cpu": cpu.get_config, "cpu_full": cpu_full.get_config,
    "paper_full": paper_full.get_config, "paper": paper.get_config}
"""Scale (`pushjax.data.SCALES`) -> its config (``pushjax/train/configs/<scale>.py``)."""


def get_config(dataset: DatasetConfig) -> TrainConfig:
    """The `TrainConfig` for training on `dataset`.

    The dataset's scale picks the architecture and schedule (``pushjax/train/configs/<scale>.py``), its camera
    the model's view and its glimpse size the model's (the glimpse is cut from the dataset's images, so its
    size in pixels belongs to the data).
    """
    config = SCALE_CONFIGS[dataset.scale]()
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
    """`text` as a value of `field_type`; ValueError naming ``config.<path>``.

    An int is a whole number (``"64"``), a float a finite number (``"3e-4"``; not ``nan`` or ``inf``), a tuple of
    ints one or more positive whole numbers separated by commas (``"64,32"``; not ``"64,,32"``, ``"64,"``, ``""`` or
    ``"64,-1"``), a str any text.
    """
    if typing.get_origin(field_type) is tuple:
        items = [item.strip() for item in text.split(",")]
        if not all(re.fullmatch(r"\+?[0-9]+", item) and int(item) > 0 for item in items):
            raise ValueError(f"config.{path}: expected comma-separated integers > 0 (e.g. 64,32; no empty item), "
                             f"got {text!r}")
        return tuple(int(item) for item in items)
    try:
        value = field_type(text)
    except ValueError:
        expected = {int: "an integer", float: "a number"}.get(field_type, f"a {field_type.__name__}")
        raise ValueError(f"config.{path}: expected {expected}, got {text!r}") from None
    if field_type is float and not math.isfinite(value):
        raise ValueError(f"config.{path}: expected a finite number, got {text!r}")
    return value


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
