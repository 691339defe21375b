"""Recording throughput of experiments/record_pushes (pushjax.sim.dataset.record_pushes).

Records rect1 pushes on abs at 20 mm/s drawn from the MIT grid into a temporary directory with the given
number of worker processes and prints pushes per second, worker start-up included. The acceptance bound is
20 pushes/s with 2 workers on 2 cores.

    python benchmarks/record.py [--pushes 200] [--workers 2] [--velocity 20]
"""

import argparse
import tempfile
import time

from pushjax.sim import dataset
from pushjax.sim.testbed import IDEAL


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pushes", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--velocity", type=float, default=20.0, help="pusher velocity, mm/s")
    parser.add_argument("--object", default="rect1")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as root:
        # Plan once so that the timed run only simulates and writes.
        settings = dataset.RecordingConfig(velocities=(args.velocity,), testbed=IDEAL)
        dataset.plan_pushes(root, [args.object], ["abs"], args.pushes, settings)
        start = time.perf_counter()
        summary = dataset.record_pushes(root, [args.object], ["abs"], args.pushes, settings, workers=args.workers,
                                        progress=False)
        elapsed = time.perf_counter() - start
    count = len(summary.written)
    print(f"{count} pushes of {args.object} at {args.velocity:g} mm/s with {args.workers} workers: {elapsed:.2f} s, "
          f"{count / elapsed:.1f} pushes/s")


if __name__ == "__main__":
    main()
