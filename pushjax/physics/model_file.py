"""A pushing model on disk: Lynch's model with composed effects, their parameters and the pusher friction.

``experiments.close_loop`` writes the model it selected as ``model.json``; the rollout, the filters and the
controller read it back (``python -m experiments.push_to_goal --models=lynch,loop --loop_model=W/model.json``):

    {"effects": ["limit_surface", "table_tilt"], "pusher_friction": 0.254,
     "params": {"limit_surface": {"rim": 0.19, "feet": 0.07}, "table_tilt": {"drift_force": [0.05, -0.01]}}}

Parameters are the effects' own (:data:`pushjax.physics.effects.EFFECTS`, SI units), not their readable values;
effects left out of ``params`` and parameters left out of an effect keep their "no effect" values.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np

from pushjax.physics import effects as effects_lib

__all__ = ["AugmentedModel", "read", "write"]


@dataclasses.dataclass(frozen=True)
class AugmentedModel:
    """Lynch's model with composed effects.

    Attributes:
      effects: effect names, in library order.
      params: {effect: {parameter: NumPy array}} for every composed effect, SI units.
      mu: pusher-object friction coefficient the model predicts with.
    """

    effects: tuple[str, ...]
    params: dict[str, dict[str, np.ndarray]]
    mu: float

    @classmethod
    def create(cls, effects, params: dict | None, mu: float) -> AugmentedModel:
        """The model with `params` filled up with "no effect" values; ValueError (one line) for unknown effects or
        parameters, values of the wrong shape or a mu that is not positive."""
        full = {name: {key: np.asarray(value, np.float64) for key, value in values.items()}
                for name, values in effects_lib.init_params(tuple(effects)).items()}
        for name, values in (params or {}).items():
            if name not in full:
                raise ValueError(f"params: effect {name!r} is not among the composed effects {tuple(full)}")
            for key, value in values.items():
                if key not in full[name]:
                    raise ValueError(f"params: {name} has no parameter {key!r}; it has {', '.join(full[name])}")
                array = np.asarray(value, np.float64)
                if array.shape != full[name][key].shape or not np.all(np.isfinite(array)):
                    raise ValueError(f"params: {name}.{key} expected {full[name][key].shape or 'a'} finite "
                                     f"value(s), got {np.shape(value)}")
                full[name][key] = array
        if not (np.isfinite(mu) and mu > 0):
            raise ValueError(f"pusher_friction: expected a positive number, got {mu}")
        return cls(effects=tuple(full), params=full, mu=float(mu))

    def as_dict(self) -> dict:
        return {"effects": list(self.effects), "pusher_friction": self.mu,
                "params": {name: {key: value.tolist() for key, value in values.items()}
                           for name, values in self.params.items()}}


def write(path: str | Path, model: AugmentedModel) -> Path:
    """Writes `model` to `path` (JSON); returns the path."""
    path = Path(path)
    path.write_text(json.dumps(model.as_dict(), indent=1) + "\n")
    return path


def read(path: str | Path) -> AugmentedModel:
    """The model in `path`.

    Raises:
      ValueError: the file is missing, not JSON or not a model; one line naming the file and the field.
    """
    path = Path(path)
    try:
        content = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as error:
        raise ValueError(f"{path}: expected a pushing model file (JSON): {error}") from None
    if not isinstance(content, dict) or not {"effects", "params", "pusher_friction"} <= set(content):
        raise ValueError(f"{path}: expected a JSON object with effects, params and pusher_friction")
    try:
        return AugmentedModel.create(content["effects"], content["params"], float(content["pusher_friction"]))
    except (TypeError, ValueError) as error:
        raise ValueError(f"{path}: {error}") from None
