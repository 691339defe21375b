"""Support surfaces of the MIT Push Dataset and the friction coefficients used to simulate them.

The dataset (Yu, Bauza, Fazeli & Rodriguez, "More than a Million Ways to Be Pushed", IROS 2016) pushes
stainless-steel plates with a steel pusher tip on four surface materials: ABS, delrin (POM), plywood and
polyurethane (``pu``). Yu et al. measured the plate–surface friction by dragging the plates across each
surface at constant speed and dividing the force-torque sensor reading by the plate's weight (their
``analyze/get_friction_coefficient.py`` and ``analyze/plot_friction_vs_vel.py`` in
``github.com/mcubelab/push-est-public``: μ = |f| / (m g), averaged over the sliding part, rect1 with
m = 0.8374 kg, speeds 10–500 mm/s); they report the coefficients per material as a function of speed and
of the position on the surface, with a spread of several hundredths across the surface.

Provenance of the numbers below (read this before relying on them):

* The paper's friction figures and table could not be retrieved in this environment. The values are
  ESTIMATES chosen inside the ranges reported for the dataset and its follow-ups (Yu et al. 2016;
  Bauza & Rodriguez, "A probabilistic data-driven model for planar pushing", ICRA 2017; Ma & Rodriguez,
  "Friction variability in planar pushing data", IROS 2018; Kloss et al., IJRR 2022, who train on ABS):
  the two hard polymers are the slipperiest (ABS ≈ 0.13, delrin ≈ 0.15), plywood is intermediate
  (≈ 0.25) and polyurethane the most frictional (≈ 0.35).
* The pusher–object coefficient (steel tip on steel plate) is an ESTIMATE of 0.25, the value commonly
  used with this dataset for the quasi-static model; it does not depend on the support surface.
* Surface colours are those of the dataset's own visualisation (``config/surface_db.py`` in the
  repository above); the texture patterns are invented so that the four surfaces are distinguishable
  in colour images.

Callers who know better coefficients change them through :class:`pushjax.sim.effects.Effects`
(``pusher_friction``) or by adding a :class:`Surface`.
"""

from __future__ import annotations

import dataclasses

PUSHER_OBJECT_FRICTION = 0.25
"""Coulomb coefficient between the steel pusher tip and a steel plate (estimate, see module doc)."""


@dataclasses.dataclass(frozen=True)
class Surface:
    """A support surface material.

    Attributes:
      name: the dataset's surface name (``abs``, ``delrin``, ``plywood``, ``pu``).
      object_friction: Coulomb coefficient between a steel plate and this surface.
      rgb: base colour in [0, 1]^3 (MIT visualisation colour).
      texture: MuJoCo procedural texture ``builtin`` (``flat``, ``checker`` or ``gradient``).
      mark: MuJoCo texture ``mark`` (``none``, ``edge``, ``cross`` or ``random``).
      rgb2: second texture colour in [0, 1]^3.
    """

    name: str
    object_friction: float
    rgb: tuple[float, float, float]
    texture: str
    mark: str
    rgb2: tuple[float, float, float]


SURFACES = {
    "abs": Surface("abs", 0.13, (0.05, 0.05, 0.05), "flat", "random", (0.25, 0.25, 0.25)),
    "delrin": Surface("delrin", 0.15, (0.9, 0.9, 0.9), "checker", "none", (0.82, 0.82, 0.8)),
    "plywood": Surface("plywood", 0.25, (0.976, 0.912, 0.788), "gradient", "random", (0.72, 0.56, 0.36)),
    "pu": Surface("pu", 0.35, (0.796, 0.553, 0.015), "checker", "edge", (0.6, 0.4, 0.0)),
}
"""The four surfaces of the dataset, by name."""

SURFACE_NAMES = tuple(SURFACES)


def get_surface(name: str) -> Surface:
    """The surface called ``name`` (one of :data:`SURFACE_NAMES`)."""
    if name not in SURFACES:
        raise ValueError(f"surface: expected one of {', '.join(SURFACE_NAMES)}, got {name!r}")
    return SURFACES[name]
