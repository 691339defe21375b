"""The file names of the MIT Push Dataset's layout (Yu et al., IROS 2016) and the push parameters they encode.

A push file is named

    motion_surface=<surface>_shape=<object>_a=<acc>_v=<vel>_i=<side>_s=<point>_t=<angle>[_rep=<NNNN>].h5

(see :mod:`pushjax.mit.files`, which reads, writes, cleans and iterates the files and re-exports these names).
:class:`PushFileError` is the error of any push file that cannot be used, its name or its content.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from pathlib import Path

import numpy as np

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_FILE_NAME = re.compile(
    rf"motion_surface=(?P<surface>[^_=/]+)_shape=(?P<shape>[^_=/]+)"
    rf"_a=(?P<acceleration>{_NUMBER})_v=(?P<velocity>{_NUMBER})"
    rf"_i=(?P<side>{_NUMBER})_s=(?P<point>{_NUMBER})_t=(?P<angle>{_NUMBER})"
    rf"(?:_rep=(?P<repetition>\d+))?\.h5"
)
_FILE_NAME_TEMPLATE = (
    "motion_surface=<surface>_shape=<object>_a=<acc>_v=<vel>_i=<side>_s=<point>_t=<angle>[_rep=<NNNN>].h5"
)
_UNPARSEABLE_NAME = "unparseable file name"


class PushFileError(ValueError):
    """A push file that cannot be used; the message names the file.

    Attributes:
      path: the offending file.
      reason: a short category (e.g. ``"unreadable file"``, ``"missing dataset"``) used to count skipped files.
      detail: what is wrong, naming the field (e.g. ``"object_pose holds NaN or infinite values"``).
    """

    def __init__(self, path: str | os.PathLike, reason: str, detail: str):
        super().__init__(f"{os.fspath(path)}: {reason}: {' '.join(str(detail).split())}")
        self.path = Path(path)
        self.reason = reason
        self.detail = detail

    def __reduce__(self):
        # Pickled with its own arguments, so that it crosses from a worker process (a dataset build) intact.
        return type(self), (self.path, self.reason, self.detail)


@dataclasses.dataclass(frozen=True)
class PushParams:
    """The push parameters encoded in a file name, in the file name's units.

    Attributes:
      surface: support surface material, e.g. ``"abs"``.
      shape: object name, e.g. ``"rect1"``.
      acceleration: pusher acceleration, mm/s² (0 = constant velocity).
      velocity: pusher velocity, mm/s (> 0).
      side: index of the pushed object side (>= 0).
      point: contact point along that side, 0..1.
      angle: push direction relative to the side's inward normal, rad.
      repetition: repetition number of a repeated push, or None for a single push.
    """

    surface: str
    shape: str
    acceleration: float
    velocity: float
    side: int
    point: float
    angle: float
    repetition: int | None = None

    def __post_init__(self):
        for field in ("surface", "shape"):
            value = getattr(self, field)
            if not isinstance(value, str) or not value or re.search(r"[_=/\\]", value):
                raise ValueError(f"{field} must be a non-empty name without '_', '=', '/' or '\\', got {value!r}")
        if not isinstance(self.side, (int, np.integer)) or isinstance(self.side, bool) or self.side < 0:
            raise ValueError(f"side must be an integer >= 0, got {self.side!r}")
        for field in ("acceleration", "velocity", "point", "angle"):
            if not math.isfinite(getattr(self, field)):
                raise ValueError(f"{field} must be finite, got {getattr(self, field)!r}")
        if self.velocity <= 0:
            raise ValueError(f"velocity must be > 0 mm/s, got {self.velocity!r}")
        if not 0.0 <= self.point <= 1.0:
            raise ValueError(f"point must lie in [0, 1], got {self.point!r}")
        if self.repetition is not None and (
            not isinstance(self.repetition, (int, np.integer)) or isinstance(self.repetition, bool)
            or self.repetition < 0
        ):
            raise ValueError(f"repetition must be None or an integer >= 0, got {self.repetition!r}")
        # Plain Python numbers, so equal parameters compare, hash and print alike whatever types came in.
        for field in ("acceleration", "velocity", "point", "angle"):
            object.__setattr__(self, field, float(getattr(self, field)))
        object.__setattr__(self, "side", int(self.side))
        if self.repetition is not None:
            object.__setattr__(self, "repetition", int(self.repetition))

    @property
    def velocity_si(self) -> float:
        """Pusher velocity in m/s."""
        return self.velocity * 1e-3

    @property
    def acceleration_si(self) -> float:
        """Pusher acceleration in m/s²."""
        return self.acceleration * 1e-3


def _format_integral(value: float) -> str:
    """Integers as the dataset writes them ("20"); other values in Python's shortest round-trip form."""
    return str(int(value)) if float(value).is_integer() else repr(float(value))


def _format_3_decimals(value: float) -> str:
    text = f"{value:.3f}"
    return "0.000" if text == "-0.000" else text


def push_file_name(params: PushParams) -> str:
    """The canonical file name of a push, formatted as in the real dataset.

    ``a`` and ``v`` are written as integers when integral; ``i``, ``s`` and ``t`` with 3 decimals (``s`` and
    ``t`` are therefore rounded to 1e-3, as in the dataset); ``rep`` with 4 digits.
    """
    name = (
        f"motion_surface={params.surface}_shape={params.shape}"
        f"_a={_format_integral(params.acceleration)}_v={_format_integral(params.velocity)}"
        f"_i={params.side:.3f}_s={_format_3_decimals(params.point)}_t={_format_3_decimals(params.angle)}"
    )
    if params.repetition is not None:
        name += f"_rep={params.repetition:04d}"
    return name + ".h5"


def parse_push_file_name(name: str | os.PathLike) -> PushParams:
    """Parses a push file name (or a path to one; only its last component is read).

    Numbers may use any decimal or exponent formatting; the side index must be integral.

    Raises:
      PushFileError (a ValueError) naming the file if the name does not follow the layout.
    """
    file_name = Path(name).name
    match = _FILE_NAME.fullmatch(file_name)
    if match is None:
        raise PushFileError(name, _UNPARSEABLE_NAME, f"expected a name like {_FILE_NAME_TEMPLATE}")
    fields = match.groupdict()
    side = float(fields["side"])
    if not side.is_integer():
        raise PushFileError(name, _UNPARSEABLE_NAME, f"side index i={fields['side']} is not an integer")
    repetition = fields["repetition"]
    try:
        return PushParams(
            surface=fields["surface"],
            shape=fields["shape"],
            acceleration=float(fields["acceleration"]),
            velocity=float(fields["velocity"]),
            side=int(side),
            point=float(fields["point"]),
            angle=float(fields["angle"]),
            repetition=None if repetition is None else int(repetition),
        )
    except ValueError as error:
        raise PushFileError(name, _UNPARSEABLE_NAME, str(error)) from error


def push_file_path(root: str | os.PathLike, params: PushParams) -> Path:
    """``<root>/<surface>/<object>/<canonical file name>``."""
    return Path(root) / params.surface / params.shape / push_file_name(params)
