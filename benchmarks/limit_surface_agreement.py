"""How closely clean testbed pushes follow Lynch's ellipsoid and the exact limit surface, sticking and slipping.

Records pushes of the ``ideal`` testbed (uniform pressure on the grid supports, one friction, perfect tracking; not
timed), cuts them into the closed loop's windows (``pushjax.loop.windows``) and predicts each with the testbed's own
pusher friction by

* Lynch's model with the uniform plate's ``l``, and with the best global scale of ``l`` (a grid over 0.6–1.3, chosen
  on these same windows: a knob's best case);
* the exact limit surface (``pushjax.physics.limit_surface``) of the footprint's support cells
  (``pushjax.geometry.support_cells``, what the loop's ``limit_surface`` effect uses) and of the testbed's own 24 grid
  supports (``pushjax.sim.scene.support_points``), both with uniform pressure.

Errors are translation + rotation in % of the zero baseline over all touching windows and over those the exact surface
says stick or slip. The goal for the exact surface: the sticking error at most a third of Lynch's.

    python benchmarks/limit_surface_agreement.py [--objects ellip2,tri1] [--surface abs] [--velocities 10,30]
        [--pushes 30] [--seed 0] [--data_dir DIR]
"""

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from pushjax.geometry import get_object
from pushjax.loop import metrics
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.physics import limit_surface, lynch
from pushjax.planar import rotate
from pushjax.sim import scene
from pushjax.sim.dataset import RecordingConfig, record_pushes
from pushjax.sim.testbed import IDEAL


def _score(prediction, examples, mask):
    errors = metrics.window_errors(prediction[mask], examples.target[mask], examples.sequence[mask])
    return metrics.combined(metrics.summarize(errors))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="ellip2,tri1")
    parser.add_argument("--surface", default="abs")
    parser.add_argument("--velocities", default="10,30", help="mm/s")
    parser.add_argument("--pushes", type=int, default=30, help="pushes per object")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--data_dir", type=Path, default=None, help="where to record (or reuse) the pushes")
    args = parser.parse_args()
    objects = args.objects.split(",")
    with tempfile.TemporaryDirectory() as scratch:
        data_dir = args.data_dir or Path(scratch) / "pushes"
        settings = RecordingConfig(seed=args.seed, velocities=tuple(float(v) for v in args.velocities.split(",")),
                                   declare_effects=False, testbed=IDEAL)
        record_pushes(data_dir, objects, [args.surface], args.pushes, settings, workers=1, progress=True)
        examples, _ = build_examples(iter_pushes(data_dir), pusher_friction=scene.pusher_friction())
    inputs = examples.inputs
    contact, normal, action = (np.asarray(getattr(inputs, name)) for name in ("contact", "normal", "action"))
    l, mu, s, yaw = (np.asarray(getattr(inputs, name)) for name in ("l", "mu", "s", "object_yaw"))
    start = time.perf_counter()
    cells = limit_surface.solve(contact, normal, action, mu, rotate(np.asarray(inputs.support_points), yaw[:, None]),
                                inputs.support_weights, inputs.patch_radius, s)
    cells_seconds = time.perf_counter() - start
    # The testbed's own supports, relative to the plate's centre of mass, each a capsule end of SUPPORT_RADIUS.
    names = examples.variables["object"]
    testbed_points = np.zeros((len(names), 24, 2))
    testbed_weights = np.zeros((len(names), 24))
    for name in objects:
        points, weights = scene.support_points(name)
        rows = names == name
        testbed_points[rows] = rotate(points - get_object(name).centroid, yaw[rows, None])
        testbed_weights[rows] = weights
    testbed = limit_surface.predict(contact, normal, action, mu, testbed_points, testbed_weights,
                                    np.full(len(names), scene.SUPPORT_RADIUS), s, stick_iterations=14,
                                    slip_iterations=14)
    plain = np.asarray(lynch.predict(contact, normal, action, l, mu, s))
    scales = np.round(np.arange(0.6, 1.31, 0.05), 2)
    touching = s > 0
    scaled = {scale: np.asarray(lynch.predict(contact, normal, action, scale * l, mu, s)) for scale in scales}
    best = min(scales, key=lambda scale: _score(scaled[scale], examples, touching))
    sticking = touching & np.asarray(cells.sticking)
    slipping = touching & ~np.asarray(cells.sticking)
    print(f"{len(examples)} windows of {examples.n_pushes} pushes ({', '.join(objects)} on {args.surface}, "
          f"{args.velocities} mm/s, ideal testbed, pusher friction {scene.pusher_friction()}); touching "
          f"{touching.sum()}, sticking {sticking.sum()}, slipping {slipping.sum()}; exact solve of the cells "
          f"{cells_seconds:.1f} s (compilation included)\n")
    print("| model | touching windows | sticking | slipping |")
    print("|---|---:|---:|---:|")
    for label, prediction in (("Lynch, `l`", plain), (f"Lynch, best global scale {best:g} `l`", scaled[best]),
                              ("exact surface, footprint cells (the loop's `limit_surface`)", np.asarray(cells.twist)),
                              ("exact surface, the testbed's 24 supports", np.asarray(testbed))):
        print(f"| {label} | {_score(prediction, examples, touching):.1f} | {_score(prediction, examples, sticking):.1f} "
              f"| {_score(prediction, examples, slipping):.1f} |")


if __name__ == "__main__":
    main()
