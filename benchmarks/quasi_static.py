"""How quasi-static the simulated 20 mm/s pushes are: the Lynch model's error on 0.5 s windows, per object.

For every MIT object, pushes drawn from the MIT grid at 20 mm/s are simulated (distributed support, abs) and
random 0.5 s windows in which the pusher touches the object are predicted with pushjax.physics.lynch from the
annotated contact (pushjax.geometry.contact.annotate), the uniform-pressure limit-surface ratio and the
simulated pusher-object friction. Prints a markdown table of the median error of the centre-of-mass
displacement relative to the median displacement (the acceptance bound in tests/sim is 25 %).

    python benchmarks/quasi_static.py [--pushes 30] [--windows 10] [--surface abs] [--seed 0]
"""

import argparse
import time

import numpy as np

from pushjax.geometry import OBJECT_NAMES
from pushjax.sim import scene
from pushjax.sim.quasi_static import quasi_static_agreement


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pushes", type=int, default=30, help="simulated pushes per object")
    parser.add_argument("--windows", type=int, default=10, help="windows drawn per push")
    parser.add_argument("--surface", default="abs")
    parser.add_argument("--support", default="grid", choices=scene.SUPPORT_MODES)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    print(f"surface {args.surface}, support {args.support}, {args.pushes} pushes x {args.windows} windows, 20 mm/s\n")
    print("| object | windows | median motion (mm) | median error (mm) | error / motion | 90th pct error / motion |")
    print("|---|---|---|---|---|---|")
    start = time.perf_counter()
    for name in OBJECT_NAMES:
        agreement = quasi_static_agreement(name, args.surface, args.pushes, args.windows, seed=args.seed,
                                           support=args.support)
        errors = np.linalg.norm(agreement.predicted - agreement.simulated, axis=1)
        print(f"| {name} | {len(errors)} | {agreement.median_motion * 1e3:.2f} | {agreement.median_error * 1e3:.3f} "
              f"| {agreement.relative_error:.1%} | {np.percentile(errors, 90) / agreement.median_motion:.1%} |")
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
