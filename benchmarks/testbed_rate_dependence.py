"""Is the testbed rate-independent? The same push at several speeds (by hand; not a timed test).

Quasi-static pushing with Coulomb friction is rate-independent: the path of a push does not depend on its speed, and
no model in ``pushjax.physics`` (Lynch's ellipsoid, the exact limit surface, every effect but the slide after the
pusher stops) gives it a dependence. ``pushjax.sim.scene`` keeps MuJoCo's friction close to Coulomb's for slow pushes,
but its contacts are soft (a sliding support under the soft elliptic cone is pushed up in proportion to its sliding
speed). This simulates a few turning pushes on the ``ideal`` testbed's grid support at each speed and prints the
plate's rotation until the pusher stops (the slide after it is ``inertia``'s, a real difference), and its ratio to the
rotation at the slowest speed (1 for a rate-independent testbed).

    python benchmarks/testbed_rate_dependence.py [--objects rect1:pu,tri2:delrin,ellip3:delrin] [--velocities 15,20,40]
        [--support_d0 0.1] [--tip_stiffness 100] [--impratio 100]

The last three replace the testbed's constants (``pushjax.sim.scene``'s ``SUPPORT_SOLIMP[0]``, ``TIP_STIFFNESS`` with
its critical damping, ``IMPRATIO``; the defaults are the testbed's) in this process, to ask which of them the rate
dependence comes from.
"""

from __future__ import annotations

import argparse

import numpy as np

from pushjax.mit.protocol import PushParams
from pushjax.sim import scene
from pushjax.sim.push import simulate_push

PUSHES = ((0.2, 0.0), (0.8, 0.3), (0.3, -0.3))
"""(point along the side, angle rad) of the pushes on side 0: off-centre, so that the plate turns."""


def rotations(obj: str, surface: str, velocity: float) -> list[float]:
    """The plate's rotation over each of :data:`PUSHES` until the pusher stops (the slide after it, which grows with
    the speed, left out), degrees."""
    result = []
    for point, angle in PUSHES:
        push = PushParams(surface=surface, shape=obj, acceleration=0.0, velocity=velocity, side=0, point=point,
                          angle=angle)
        recording = simulate_push(push)
        tip, pose = recording.tip_pose, recording.true_object_pose
        stop = np.flatnonzero(np.linalg.norm(np.diff(tip[:, 1:3], axis=0), axis=1) > 1e-7)[-1] + 1
        result.append(float(np.degrees(pose[stop, 3] - pose[0, 3])))
    return result


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
    if any(len(pair) != 2 for pair in pairs):
        parser.error(f"--objects: expected object:surface pairs, got {args.objects!r}")
    velocities = sorted(float(value) for value in args.velocities.split(","))
    print("| object | surface | push speed mm/s | rotation of the pushes, deg | over the rotation at the slowest speed |")
    print("|---|---|---:|---|---|")
    for obj, surface in pairs:
        slowest = None
        for velocity in velocities:
            turned = rotations(obj, surface, velocity)
            slowest = slowest or turned
            print(f"| {obj} | {surface} | {velocity:g} | {', '.join(f'{r:.2f}' for r in turned)} | "
                  f"{', '.join(f'{r / s:.3f}' for r, s in zip(turned, slowest))} |", flush=True)


if __name__ == "__main__":
    main()
