"""How closely slow simulated pushes follow the quasi-static pushing model of Lynch et al. (1992).

For random 0.5 s windows of simulated 20 mm/s pushes, the contact state at the window's start is annotated
from the recorded object pose and pusher position (:func:`pushjax.geometry.contact.annotate`, with the pusher
displacement over the window as the action) and fed to :func:`pushjax.physics.lynch.predict` with the
uniform-pressure limit-surface ratio of the object and the simulated pusher–object friction coefficient. The
prediction is compared with the simulated displacement of the centre of mass over the window.

This module imports JAX (through the model); :mod:`pushjax.sim` itself does not.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from pushjax import planar
from pushjax.geometry.contact import annotate
from pushjax.geometry.objects import get_object, limit_surface_ratio
from pushjax.mit.files import PushParams
from pushjax.mit.protocol import push_duration, sample_push
from pushjax.physics import lynch
from pushjax.sim import scene
from pushjax.sim.effects import Effects
from pushjax.sim.push import SAMPLE_RATE, simulator

WINDOW_DURATION = 0.5
"""Length of a prediction window in s."""


@dataclasses.dataclass(frozen=True)
class Agreement:
    """Quasi-static agreement over a set of windows (displacements of the centre of mass, m).

    Attributes:
      simulated: [W, 2] simulated displacement per window.
      predicted: [W, 2] displacement predicted by the quasi-static model.
      median_error: median of ``|predicted - simulated|``.
      median_motion: median of ``|simulated|``.
    """

    simulated: np.ndarray
    predicted: np.ndarray
    median_error: float
    median_motion: float

    @property
    def relative_error(self) -> float:
        """``median_error / median_motion``."""
        return self.median_error / self.median_motion


def quasi_static_agreement(obj: str, surface: str = "abs", pushes: int = 30, windows_per_push: int = 8,
                           velocity: float = 20.0, seed: int = 0, support: str = "grid") -> Agreement:
    """Compares simulated pushes with the quasi-static model's prediction over random windows.

    Args:
      obj: object name.
      surface: surface name.
      pushes: number of simulated pushes, drawn from the MIT grid at ``velocity``.
      windows_per_push: windows drawn per push (start uniform while the pusher moves; windows in which the
        pusher never touches the object are dropped).
      velocity: pusher velocity in mm/s.
      seed: seed of the push and window draws.
      support: support mode of the simulated object.

    Returns:
      The :class:`Agreement` over the kept windows.
    """
    shape = get_object(obj)
    sim = simulator(obj, surface, Effects(), support)
    l = limit_surface_ratio(shape)
    mu = scene.pusher_friction()
    window = round(WINDOW_DURATION * SAMPLE_RATE)
    rng = np.random.default_rng(seed)
    simulated, predicted = [], []
    for _ in range(pushes):
        params: PushParams = sample_push(shape, surface, rng, velocities=(velocity,))
        recording = sim.run(params)
        moving_samples = int(push_duration(params) * SAMPLE_RATE)
        starts = rng.integers(0, max(1, moving_samples - window), size=windows_per_push)
        pose0 = recording.true_object_pose[starts, 1:]
        pose1 = recording.true_object_pose[starts + window, 1:]
        tip0 = recording.tip_pose[starts, 1:3]
        action = recording.tip_pose[starts + window, 1:3] - tip0
        contact = annotate(shape, pose0, tip0, action)
        keep = np.asarray(contact.touches)
        if not np.any(keep):
            continue
        prediction = np.asarray(lynch.predict(contact.contact_rel_com, contact.normal, contact.action_from_contact,
                                              l, mu))[..., :2]
        simulated.append((planar.centre_of_mass(shape.centroid, pose1) - planar.centre_of_mass(shape.centroid, pose0))[keep])
        predicted.append(prediction[keep])
    simulated = np.concatenate(simulated)
    predicted = np.concatenate(predicted)
    return Agreement(
        simulated=simulated,
        predicted=predicted,
        median_error=float(np.median(np.linalg.norm(predicted - simulated, axis=1))),
        median_motion=float(np.median(np.linalg.norm(simulated, axis=1))),
    )

