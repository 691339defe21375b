"""Is the testbed rate-independent? The same push at several speeds (by hand; not a timed test).

Quasi-static pushing with Coulomb friction is rate-independent: the path of a push does not depend on its speed, and
no model in ``pushjax.physics`` (Lynch's ellipsoid, the exact limit surface, every effect but the slide after the
pusher stops) gives it a dependence. ``pushjax.sim.scene`` keeps MuJoCo's friction close to Coulomb's for slow pushes,
but its contacts are soft (a sliding support under the soft elliptic cone is pushed up in proportion to its sliding
speed). This simulates a few turning pushes on the ``ideal`` testbed's grid support at each speed and prints, per
speed:

* the plate's rotation until the pusher stops (the slide after it is ``inertia``'s, a real difference), and its ratio
  to the rotation at the slowest speed (1 for a rate-independent testbed);
* the friction law at the supports: the median of each sliding support's friction over its normal force times the
  table's coefficient (1: Coulomb), over the supports sliding faster than :data:`SLIDING`;
* where the load sits: the median move of the centre of the supports' normal forces from where it rests, along the
  plate's motion, over the load transfer ``mu * thickness / 2`` (the pushing force, at half the plate's height, tips
  the load forwards);
* how the load spreads: the median of its mean squared distance from its centre over the same at rest (above 1: the
  load moved outwards, which makes the plate harder to turn).

    python benchmarks/testbed_rate_dependence.py [--objects rect1:pu,tri2:delrin,ellip3:delrin] [--velocities 15,20,40]
        [--support_d0 0.1] [--tip_stiffness 100] [--impratio 100]

The last three replace the testbed's constants (``pushjax.sim.scene``'s ``SUPPORT_SOLIMP[0]``, ``TIP_STIFFNESS`` with
its critical damping, ``IMPRATIO``; the defaults are the testbed's) in this process, to ask which of them the rate
dependence comes from.
"""

from __future__ import annotations

import argparse

import numpy as np

from pushjax.geometry import OBJECT_NAMES, get_object
from pushjax.mit.protocol import PushParams
from pushjax.sim import scene
from pushjax.sim.push import Simulator
from pushjax.sim.surfaces import SURFACES

PUSHES = ((0.2, 0.0), (0.8, 0.3), (0.3, -0.3))
"""(point along the side, angle rad) of the pushes on side 0: off-centre, so that the plate turns."""
SLIDING = 5e-4
"""Sliding speed (m/s) from which a support counts as sliding: below it MuJoCo's soft friction is still building up."""


def measure(obj: str, surface: str, velocity: float) -> tuple[list[float], float, float, float]:
    """(the rotation of each of :data:`PUSHES` until the pusher stops, degrees; the supports' median friction over
    Coulomb's; the load's median forward shift over ``mu * thickness / 2``; the load's median spread over its spread
    at rest) at ``velocity`` mm/s."""
    simulator = Simulator(obj, surface)
    mu = SURFACES[surface].object_friction
    transfer = mu * get_object(obj).thickness / 2
    points = simulator.support_points
    friction, forward, spread, rest = [], [], [], [np.zeros(2), 1.0]

    def record(sim: Simulator) -> None:
        forces, speeds = sim.support_forces(), sim.support_sliding_speeds()
        sliding = (forces[:, 0] > 0) & (speeds > SLIDING)
        friction.extend(forces[sliding, 1] / (mu * forces[sliding, 0]))
        if forces[:, 0].sum() == 0:
            return
        load = forces[:, 0] / forces[:, 0].sum()
        centre = load @ points
        square = load @ np.sum((points - centre) ** 2, axis=1)
        motion = sim.object_velocity()[:2]
        if np.linalg.norm(motion) < 1e-5:
            rest[:] = centre, square  # how the load sits before the pusher reaches the plate
        elif np.linalg.norm(motion) > 0.3e-3 * velocity:
            forward.append((centre - rest[0]) @ motion / np.linalg.norm(motion) / transfer)
            spread.append(square / rest[1])

    turned = []
    for point, angle in PUSHES:
        push = PushParams(surface=surface, shape=obj, acceleration=0.0, velocity=velocity, side=0, point=point,
                          angle=angle)
        recording = simulator.run(push, on_step=record)
        tip, pose = recording.tip_pose, recording.true_object_pose
        stop = np.flatnonzero(np.linalg.norm(np.diff(tip[:, 1:3], axis=0), axis=1) > 1e-7)[-1] + 1
        turned.append(float(np.degrees(pose[stop, 3] - pose[0, 3])))
    return turned, float(np.median(friction)), float(np.median(forward)), float(np.median(spread))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="rect1:pu,tri2:delrin,ellip3:delrin",
                        help="comma-separated object:surface pairs")
    parser.add_argument("--velocities", default="15,20,40", help="comma-separated push speeds, mm/s")
    parser.add_argument("--support_d0", type=float, default=scene.SUPPORT_SOLIMP[0],
                        help="the support contacts' impedance at zero penetration (MuJoCo solimp d0)")
    parser.add_argument("--tip_stiffness", type=float, default=scene.TIP_STIFFNESS, help="the pusher tip's spring, N/m")
    parser.add_argument("--impratio", type=float, default=scene.IMPRATIO, help="MuJoCo's frictional impedance ratio")
    args = parser.parse_args()
    scene.SUPPORT_SOLIMP = (args.support_d0, *scene.SUPPORT_SOLIMP[1:])
    scene.TIP_STIFFNESS, scene.IMPRATIO = args.tip_stiffness, args.impratio
    scene.TIP_DAMPING = 2 * (scene.TIP_STIFFNESS * scene.TIP_MASS) ** 0.5
    pairs = [pair.split(":") for pair in args.objects.split(",")]
    if any(len(pair) != 2 or pair[0] not in OBJECT_NAMES or pair[1] not in SURFACES for pair in pairs):
        parser.error(f"--objects: expected object:surface pairs (objects {', '.join(OBJECT_NAMES)}; surfaces "
                     f"{', '.join(SURFACES)}), got {args.objects!r}")
    try:
        velocities = sorted(float(value) for value in args.velocities.split(","))
    except ValueError:
        velocities = []
    if not velocities or min(velocities) <= 0:
        parser.error(f"--velocities: expected comma-separated positive speeds in mm/s, got {args.velocities!r}")
    print("| object | surface | push speed mm/s | rotation of the pushes, deg | over the rotation at the slowest speed "
          "| supports' friction / Coulomb's | load's forward shift / (mu thickness / 2) | load's spread / at rest |")
    print("|---|---|---:|---|---|---:|---:|---:|")
    for obj, surface in pairs:
        slowest = None
        for velocity in velocities:
            turned, friction, forward, spread = measure(obj, surface, velocity)
            slowest = slowest or turned
            print(f"| {obj} | {surface} | {velocity:g} | {', '.join(f'{r:.2f}' for r in turned)} | "
                  f"{', '.join(f'{r / s:.3f}' for r, s in zip(turned, slowest))} | {friction:.3f} | {forward:.2f} | "
                  f"{spread:.3f} |",
                  flush=True)


if __name__ == "__main__":
    main()
