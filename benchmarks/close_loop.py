"""Wall time of the whole loop (``pushjax.loop.close_loop``) on 500 simulated pushes.

Records the pushes once (testbed, no declared effects; not timed) — by default 5 objects x 2 surfaces x 50
pushes at velocities from 10 to 200 mm/s, so that the fast ones slide on after the pusher stops, with a
centre-of-mass offset — then times the loop end to end in this process: reading the files, windows and
contact annotation, diagnosis, fitting every effect and the forward selection (including JAX
compilation), the fallback if needed, figures and report. The acceptance bound is 30 s on 2 idle cores; the CPU time
(all threads) and the time XLA spent compiling are printed too, since on a shared machine the wall time measures the
neighbours.

    python benchmarks/close_loop.py [--data_dir DIR] [--workdir OUT] [--pushes_per_pair 50] [--workers 2]
                                    [--compilation_cache DIR]

With ``--compilation_cache`` the loop uses that persistent compilation cache, as ``experiments.close_loop`` uses its
default one: run it twice with the same empty folder for a cold and a warm first call.

With ``--data_dir`` the pushes are recorded there (or reused when present). With ``--profile N`` the loop runs under
``cProfile`` and the N pushjax functions with the largest cumulative time are printed after the timing (the profiler
adds a few per cent).
"""

import argparse
import cProfile
import json
import pstats
import resource
import sys
import tempfile
import time
from pathlib import Path

import jax

from pushjax import compilation_cache
from pushjax.loop import close_loop
from pushjax.sim.dataset import RecordingConfig, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.testbed import IDEAL

OBJECTS = ["rect1", "tri1", "ellip2", "hex", "butter"]
SURFACES = ["abs", "plywood"]
VELOCITIES = [10.0, 20.0, 50.0, 100.0, 200.0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data_dir", type=Path, default=None, help="where to record (or reuse) the pushes")
    parser.add_argument("--workdir", type=Path, default=None, help="report directory (default: temporary)")
    parser.add_argument("--pushes_per_pair", type=int, default=50, help="pushes per object and surface")
    parser.add_argument("--effects", default="com_offset=0.01,-0.005", help="testbed effects (record_pushes syntax)")
    parser.add_argument("--workers", type=int, default=2, help="recording processes")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--profile", type=int, default=0,
                        help="print this many pushjax functions by cumulative time (cProfile; 0: no profile)")
    parser.add_argument("--compilation_cache", default="off",
                        help="persistent compilation cache folder (default off: every program compiled here)")
    args = parser.parse_args()
    if args.profile < 0:
        parser.error(f"--profile: expected a count of functions >= 0, got {args.profile}")
    compilation_cache.enable(args.compilation_cache)
    compiling = _compile_seconds()

    with tempfile.TemporaryDirectory() as scratch:
        data_dir = args.data_dir or Path(scratch) / "pushes"
        workdir = args.workdir or Path(scratch) / "loop"
        start = time.perf_counter()
        settings = RecordingConfig(seed=args.seed, velocities=VELOCITIES, effects=Effects.parse(args.effects),
                                   declare_effects=False, testbed=IDEAL)
        recorded = record_pushes(data_dir, OBJECTS, SURFACES, args.pushes_per_pair, settings, workers=args.workers,
                                 progress=True)
        print(f"recorded {len(recorded.written)} pushes ({len(recorded.skipped)} reused) in "
              f"{time.perf_counter() - start:.1f} s")
        profiler = cProfile.Profile() if args.profile else None
        start, cpu = time.perf_counter(), _cpu_seconds()
        if profiler:
            profiler.enable()
        report = close_loop(data_dir, workdir, seed=args.seed).report.as_dict()
        if profiler:
            profiler.disable()
        elapsed, cpu = time.perf_counter() - start, _cpu_seconds() - cpu
    pushes = len(recorded.written) + len(recorded.skipped)
    print(json.dumps({key: report[key] for key in ("n_pushes", "baseline", "selected", "after", "noise_floor", "explained")},
                     indent=1))
    print(f"close_loop on {pushes} pushes: {elapsed:.1f} s wall, {cpu:.1f} s CPU (user + system, all threads), "
          f"{compiling():.1f} s compiling")
    if profiler:
        print(f"\nthe {args.profile} pushjax functions with the largest cumulative time (cProfile, s):")
        stats = pstats.Stats(profiler, stream=sys.stdout).sort_stats("cumulative")
        stats.print_stats("pushjax", args.profile)


def _compile_seconds():
    """A function returning the seconds XLA has spent compiling since this call (programs the persistent cache held
    are loaded, not compiled, and do not count)."""
    total = [0.0]

    def listener(event: str, seconds: float, **_) -> None:
        if event == "/jax/core/compile/backend_compile_duration":
            total[0] += seconds

    jax.monitoring.register_event_duration_secs_listener(listener)
    return lambda: total[0]


def _cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


if __name__ == "__main__":
    main()
