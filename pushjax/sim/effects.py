"""Effects injected into the simulated MIT pushes: what they change physically and how they are written.

Every effect is off by default. All but the tracking effects change the SIMULATION (the MuJoCo model), never
the recorded trajectories:

``com_offset`` (m, m)
    Moves the centre of mass by this vector in the object frame (the body's inertial position), keeping the
    mass and the rotational inertia about the centre of mass — a hidden weight inside the plate. The support
    normal forces redistribute accordingly (the plate rests on compliant contacts).
``pressure_rim`` (-)
    Non-uniform support pressure. Support point ``i`` at normalised distance ``rho_i`` in [0, 1] from the
    footprint centroid gets the weight ``w_i ∝ exp(pressure_rim * rho_i)`` (mean 1): > 0 loads the rim,
    < 0 the centre. The weight is realised as the support's friction coefficient (``mu_i ∝ w_i`` times the
    area the support stands for, mean ``mu``), since the limit surface depends on the support friction forces
    ``mu_i N_i`` only.
``friction_anisotropy`` (-, -)
    Multipliers of the object–surface coefficient along the object's x and y axes. The support contacts'
    tangent frames are tied to the object frame (see :mod:`pushjax.sim.scene`), so the friction ellipse turns
    with the object, as for a plate with a machined grain.
``table_tilt_deg``, ``table_tilt_azimuth_deg`` (deg, deg)
    Tilts the table: gravity gets the component ``g sin(tilt)`` in the table plane, pointing downhill along
    the azimuth (measured from the world x axis, counter-clockwise), and ``g cos(tilt)`` into the table.
``pusher_friction`` (-)
    Replaces the pusher–object Coulomb coefficient (default ``pushjax.sim.surfaces.PUSHER_OBJECT_FRICTION``).

Tracking effects model the motion-capture system and apply to the RECORDED object poses only:

``tracking_noise`` (m, rad)
    Standard deviations of i.i.d. Gaussian noise added to each recorded object x, y and yaw.
``tracking_bias`` (m, m, rad)
    A constant marker offset: the recorded frame is the tracked frame displaced by (dx, dy) in the object's
    axes and turned by dyaw.

Command-line syntax (:meth:`Effects.parse`): ``name=value`` items separated by ``;``, vector components by
``,``, e.g. ``com_offset=0.01,0.0;table_tilt_deg=1.0;pusher_friction=0.5``.

One physics, three vocabularies: these effects, the testbed profile's mechanisms (:class:`pushjax.sim.testbed.Testbed`)
and the pushing model's effects (:data:`pushjax.physics.effects.EFFECTS`) name the same physics differently (recorded
manifests and the ``--effects`` syntax keep the testbed's names). :data:`MODEL_EFFECT` is the one translation.
"""

from __future__ import annotations

import dataclasses
import json
import math
from typing import Any

_VECTOR_SIZES = {"com_offset": 2, "friction_anisotropy": 2, "tracking_noise": 2, "tracking_bias": 3}

MODEL_EFFECT: dict[str, str | None] = {
    # Effects (injected).
    "com_offset": "cof_offset",  # the moved centre of mass moves the support's centre of pressure
    "pressure_rim": "limit_surface",  # its rim parameter: the same exp(k rho) pressure over the footprint
    "friction_anisotropy": "anisotropic_friction",
    "table_tilt_deg": "table_tilt",  # with the azimuth, the drift force tan(tilt) / mu_surface downhill
    "table_tilt_azimuth_deg": "table_tilt",
    "pusher_friction": "pusher_friction",  # a scale of the nominal coefficient
    "tracking_noise": None,  # sensor noise: the loop's noise floor, not an effect
    "tracking_bias": "frame_offset",  # its (dx, dy); no effect turns the annotated outline (dyaw)
    # Testbed (pushjax.sim.testbed), drawn per surface, object or push.
    "pressure_plate_sigma": "limit_surface",  # an uneven load over the footprint: the exact surface of a pressure
    # The table's load is realised as the friction field is, the supports' coefficients where they are on the table:
    # a centre of friction that moves with the object. A field's correlation length belongs to its mechanism.
    "pressure_table_sigma": "friction_field",
    "pressure_table_length": "friction_field",
    "friction_field_sigma": "friction_field",
    "friction_field_length": "friction_field",
    "object_friction_sigma": None,  # a uniform scale of the support friction cancels in quasi-static pushing
    "friction_speed_gain": "friction_speed",
    "pusher_friction_sigma": None,  # a push-to-push spread: pushjax.loop.variability, not an effect
    "tracking_noise_xy": None,
    "tracking_noise_yaw": None,
    "timestamp_jitter": None,
    "drop_rate": None,
}
"""The testbed's names for the physics (every :class:`Effects` field and every
:class:`pushjax.sim.testbed.Testbed` field) -> the pushing model's effect (a key of
:data:`pushjax.physics.effects.EFFECTS`) that models it, or None where no effect does (checked both ways by
``tests/sim/test_vocabulary.py``). The one translation between the two vocabularies; ARCHITECTURE.md ("One physics,
three places") shows it as a table."""


@dataclasses.dataclass(frozen=True)
class Effects:
    """Effects of one simulated data set; the defaults reproduce the nominal MIT setup.

    Attributes are described in the module docstring; units: m, rad and degrees as named.
    """

    com_offset: tuple[float, float] = (0.0, 0.0)
    pressure_rim: float = 0.0
    friction_anisotropy: tuple[float, float] = (1.0, 1.0)
    table_tilt_deg: float = 0.0
    table_tilt_azimuth_deg: float = 0.0
    pusher_friction: float | None = None
    tracking_noise: tuple[float, float] = (0.0, 0.0)
    tracking_bias: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self):
        for name, size in _VECTOR_SIZES.items():
            value = getattr(self, name)
            try:
                vector = tuple(float(component) for component in value)
            except (TypeError, ValueError):
                raise ValueError(f"{name}: expected {size} numbers, got {value!r}") from None
            if len(vector) != size:
                raise ValueError(f"{name}: expected {size} numbers, got {len(vector)}")
            object.__setattr__(self, name, vector)
        for name in ("pressure_rim", "table_tilt_deg", "table_tilt_azimuth_deg"):
            object.__setattr__(self, name, as_float(name, getattr(self, name)))
        if self.pusher_friction is not None:
            object.__setattr__(self, "pusher_friction", as_float("pusher_friction", self.pusher_friction))
        for name in ("com_offset", "friction_anisotropy", "tracking_noise", "tracking_bias"):
            if not all(math.isfinite(v) for v in getattr(self, name)):
                raise ValueError(f"{name}: expected finite numbers, got {getattr(self, name)}")
        if min(self.friction_anisotropy) <= 0:
            raise ValueError(f"friction_anisotropy: expected multipliers > 0, got {self.friction_anisotropy}")
        if not 0.0 <= self.table_tilt_deg < 90.0:
            raise ValueError(f"table_tilt_deg: expected a tilt in [0, 90) degrees, got {self.table_tilt_deg}")
        if self.pusher_friction is not None and self.pusher_friction < 0:
            raise ValueError(f"pusher_friction: expected a coefficient >= 0, got {self.pusher_friction}")
        if min(self.tracking_noise) < 0:
            raise ValueError(f"tracking_noise: expected standard deviations >= 0, got {self.tracking_noise}")

    @property
    def physical(self) -> Effects:
        """These effects without the tracking (sensor) effects: what the MuJoCo model depends on."""
        return dataclasses.replace(self, tracking_noise=(0.0, 0.0), tracking_bias=(0.0, 0.0, 0.0))

    def to_dict(self) -> dict[str, Any]:
        """All fields as JSON-compatible values (tuples become lists)."""
        return {field.name: _jsonable(getattr(self, field.name)) for field in dataclasses.fields(self)}

    def to_json(self) -> str:
        """A canonical JSON string (sorted keys): equal effects give equal strings."""
        return json.dumps(self.to_dict(), sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> Effects:
        """Inverse of :meth:`to_json`; missing fields take their defaults, unknown fields are an error."""
        try:
            values = json.loads(text)
        except json.JSONDecodeError as error:
            raise ValueError(f"effects: not a JSON string ({error})") from None
        if not isinstance(values, dict):
            raise ValueError(f"effects: expected a JSON object, got {type(values).__name__}")
        return cls._from_mapping(values)

    @classmethod
    def parse(cls, spec: str) -> Effects:
        """Effects from the command-line syntax ``name=v[,v...];name=...`` (empty string: no effects).

        ``pusher_friction=none`` restores the default pusher friction.
        """
        values: dict[str, Any] = {}
        for name, text in parse_assignments(spec, "effects").items():
            components = [component.strip() for component in text.split(",")]
            if name in _VECTOR_SIZES:
                values[name] = components
            elif len(components) != 1:
                raise ValueError(f"{name}: expected one number, got {text!r}")
            elif name == "pusher_friction" and components[0].lower() == "none":
                values[name] = None
            else:
                values[name] = components[0]
        return cls._from_mapping(values)

    @classmethod
    def _from_mapping(cls, values: dict[str, Any]) -> Effects:
        return from_fields(cls, values, "effects: unknown effect(s)")


def from_fields(cls: type, values: dict[str, Any], unknown_message: str):
    """``cls(**values)`` for a dataclass `cls`, raising ``ValueError(unknown_message ...)`` naming unknown fields."""
    known = {field.name for field in dataclasses.fields(cls)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise ValueError(f"{unknown_message} {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    return cls(**values)


def parse_assignments(spec: str, what: str) -> dict[str, str]:
    """``{name: value text}`` of the command-line syntax ``name=value;name=value`` (empty string: ``{}``).

    Raises a ValueError starting with `what` (e.g. the flag) for an item without a value or a name given twice.
    """
    values: dict[str, str] = {}
    for item in filter(None, (part.strip() for part in spec.split(";"))):
        name, separator, text = item.partition("=")
        name = name.strip()
        if not separator or not text.strip():
            raise ValueError(f"{what}: expected 'name=value', got {item!r}")
        if name in values:
            raise ValueError(f"{what}: {name!r} given twice")
        values[name] = text.strip()
    return values


def as_float(name: str, value: Any) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name}: expected a finite number, got {value!r}")
    return number


def _jsonable(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value
