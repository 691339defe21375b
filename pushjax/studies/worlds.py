"""Worlds of the studies: the realistic testbed with one effect the controller's model does not declare, its
magnitude drawn from the world's seed (:func:`draw_world`, :data:`EFFECTS`), and the oracle model that knows it (the
model's effect named by :data:`pushjax.sim.effects.MODEL_EFFECT`):

``tilt``                  the table tilted by 2-4 degrees towards a uniform azimuth (``Effects.table_tilt_deg``);
``com_offset``            the centre of mass moved by 30-50 % of the distance from the centroid to the outline, in a
                          uniform direction (``Effects.com_offset``, object axes);
``pusher_friction``       a pusher-object coefficient of 0.08-0.15 instead of the nominal 0.25
                          (``Effects.pusher_friction``; the testbed still spreads it per push);
``friction_variability``  the pusher-object coefficient spread from push to push by a log-normal factor of spread
                          0.5-0.8 instead of the realistic profile's 0.2 (``Testbed.pusher_friction_sigma``).
"""

from __future__ import annotations

import dataclasses
import math
import zlib
from collections.abc import Sequence

import numpy as np
import shapely

from pushjax.geometry.objects import get_object
from pushjax.physics.model_file import AugmentedModel
from pushjax.sim.effects import MODEL_EFFECT, Effects
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION, get_surface
from pushjax.sim.testbed import REALISTIC, Testbed

__all__ = ["COM_OFFSET_SHARE", "EFFECTS", "FRICTION_SIGMA", "PUSHER_FRICTION", "TILT_DEG", "World", "draw_world"]

EFFECTS = ("tilt", "com_offset", "pusher_friction", "friction_variability")
"""The worlds' undeclared effects (see the module docstring)."""
TILT_DEG = (2.0, 4.0)
"""Range of the table's tilt, degrees (below the abs surface's friction angle of 7.4 degrees)."""
COM_OFFSET_SHARE = (0.3, 0.5)
"""Range of the centre of mass's offset, as a share of the distance from the centroid to the outline."""
PUSHER_FRICTION = (0.08, 0.15)
"""Range of the low pusher-object coefficient (nominal 0.25)."""
FRICTION_SIGMA = (0.5, 0.8)
"""Range of the push-to-push spread of the pusher-object coefficient (std of its log; realistic profile: 0.2)."""


@dataclasses.dataclass(frozen=True)
class World:
    """One world: an effect and its magnitude.

    Attributes:
      effect: from :data:`EFFECTS`.
      seed: the world's seed (its magnitude, goals and testbed draws).
      magnitude: the drawn magnitude in readable units (JSON-able; e.g. ``{"tilt_deg", "azimuth_deg"}``).
      effects: {object: the testbed's :class:`pushjax.sim.effects.Effects`}.
      testbed: the testbed profile.
      oracle: {object: the model that knows the effect (:class:`pushjax.physics.model_file.AugmentedModel`)}.
    """

    effect: str
    seed: int
    magnitude: dict
    effects: dict[str, Effects]
    testbed: Testbed
    oracle: dict[str, AugmentedModel]


def draw_world(effect: str, seed: int, objects: Sequence[str], surface: str = "abs",
               testbed: Testbed = REALISTIC) -> World:
    """The world of `effect` with seed `seed`: its magnitude drawn from ``default_rng([seed, crc32(effect)])`` (see
    the module docstring for the ranges), for `objects` on `surface`."""
    if effect not in EFFECTS:
        raise ValueError(f"effect: expected one of {','.join(EFFECTS)}, got {effect!r}")
    rng = np.random.default_rng([seed, zlib.crc32(effect.encode("utf-8"))])
    if effect == "tilt":
        tilt, azimuth = rng.uniform(*TILT_DEG), rng.uniform(0.0, 360.0)
        drift = math.tan(math.radians(tilt)) / get_surface(surface).object_friction
        downhill = [drift * math.cos(math.radians(azimuth)), drift * math.sin(math.radians(azimuth))]
        model_effect = MODEL_EFFECT["table_tilt_deg"]
        oracle = AugmentedModel.create((model_effect,), {model_effect: {"drift_force": downhill}},
                                       PUSHER_OBJECT_FRICTION)
        return World(effect, seed, {"tilt_deg": tilt, "azimuth_deg": azimuth, "drift_force": downhill},
                     {obj: Effects(table_tilt_deg=tilt, table_tilt_azimuth_deg=azimuth) for obj in objects}, testbed,
                     {obj: oracle for obj in objects})
    if effect == "com_offset":
        share, direction = rng.uniform(*COM_OFFSET_SHARE), rng.uniform(-math.pi, math.pi)
        offsets, model_effect = {}, MODEL_EFFECT["com_offset"]
        for obj in objects:
            shape = get_object(obj)
            inside = shape.polygon.exterior.distance(shapely.Point(*shape.centroid))
            offsets[obj] = [share * inside * math.cos(direction), share * inside * math.sin(direction)]
        return World(effect, seed, {"share_of_inradius": share, "direction_deg": math.degrees(direction),
                                    "offset_m": offsets},
                     {obj: Effects(com_offset=offsets[obj]) for obj in objects}, testbed,
                     {obj: AugmentedModel.create((model_effect,), {model_effect: {"offset": offsets[obj]}},
                                                 PUSHER_OBJECT_FRICTION) for obj in objects})
    if effect == "pusher_friction":
        mu = rng.uniform(*PUSHER_FRICTION)
        return World(effect, seed, {"pusher_friction": mu}, {obj: Effects(pusher_friction=mu) for obj in objects},
                     testbed, {obj: AugmentedModel.create((), {}, mu) for obj in objects})
    sigma = rng.uniform(*FRICTION_SIGMA)
    mean = PUSHER_OBJECT_FRICTION * math.exp(sigma ** 2 / 2)
    return World(effect, seed, {"pusher_friction_sigma": sigma, "mean_pusher_friction": mean},
                 {obj: Effects() for obj in objects}, dataclasses.replace(testbed, pusher_friction_sigma=sigma),
                 {obj: AugmentedModel.create((), {}, mean) for obj in objects})
