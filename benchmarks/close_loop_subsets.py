"""The loop's decision on part of a stored power-benchmark data set: the pushes of one speed, or a random half of the
push sequences (by hand; not a timed test).

Asks whether a selection on a data set that mixes push speeds (``python -m experiments.loop_power --setup=held_out``: 15
and 40 mm/s; its pushes in ``work/loop_power/held_out/<case>/seed<k>/pushes``) comes from mixing them: compare the decision on each speed alone with that on random halves of the same
size that keep both speeds (the control for the lost power).

    python benchmarks/close_loop_subsets.py --data work/loop_power/held_out/clean/seed0/pushes --seed 0 \
        (--speed 15 | --half 1)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from pushjax.loop.pipeline import LoopConfig, decide
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True, help="a recorded data set (raw MIT layout)")
    parser.add_argument("--seed", type=int, default=0, help="the loop's seed (the power benchmark uses the data set's)")
    part = parser.add_mutually_exclusive_group(required=True)
    part.add_argument("--speed", type=float, help="keep the pushes at this speed, mm/s")
    part.add_argument("--half", type=int, help="keep a random half of the push sequences, drawn with this seed")
    args = parser.parse_args()
    if not args.data.is_dir():
        parser.error(f"--data: {str(args.data)!r} is not a directory")
    try:
        examples = build_examples(iter_pushes(args.data))[0]
    except ValueError as error:
        parser.error(f"--data: {error}")
    speeds = np.asarray(examples.variables["push velocity"], float)
    if args.speed is not None:
        keep = speeds == args.speed
        if not keep.any():
            parser.error(f"--speed: no pushes at {args.speed:g} mm/s; the data has {sorted(set(speeds.tolist()))}")
    else:
        sequences = np.unique(examples.sequence)
        chosen = np.random.default_rng(args.half).permutation(sequences)[:len(sequences) // 2]
        keep = np.isin(examples.sequence, chosen)
    examples = examples.select(np.flatnonzero(keep))
    start = time.perf_counter()
    decision = decide(examples, LoopConfig(), args.seed)
    kept = {f"{speed:g} mm/s": int(count) for speed, count in zip(*np.unique(speeds[keep], return_counts=True))}
    print(f"{args.data}: windows {kept}, selected {decision.selection.selected} "
          f"({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
