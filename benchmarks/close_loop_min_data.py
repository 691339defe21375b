"""How often does the loop select an effect on clean data, by the number of push sequences? The measurement
behind ``pushjax.loop.splits.MIN_SEQUENCES`` (by hand; not a timed test).

Clean data sets of the independent set-up of ``benchmarks/close_loop_power.py`` of commit 1135d3f (ellip2 and tri1 on abs,
10 and 30 mm/s, no effect; recorded there), subsampled to N push sequences (DRAWS seeded draws per N, from
the five recorded data sets in turn), analysed by the loop's split and forward selection with its measured
minimum switched off (the sign-flip test's own floor of 2^-S stays: below 12 sequences no effect can pass).

Criterion, fixed before measuring: MIN_SEQUENCES is the smallest N of the grid from which on no measured N
selects anything in more than 5 % of the draws (with 10 draws: in none).

    python benchmarks/close_loop_min_data.py [--data_dir /tmp/close_loop_power/data] [--draws 10]
"""

import argparse
import time
from pathlib import Path

import numpy as np

from pushjax.loop import select, splits
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.physics.effects import EFFECT_NAMES

GRID = (12, 16, 24, 32, 48)
RATE = 0.05


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data_dir", type=Path, default=Path("/tmp/close_loop_power/data"))
    parser.add_argument("--draws", type=int, default=10)
    parser.add_argument("--recorded_seeds", type=int, default=5)
    args = parser.parse_args()
    start = time.perf_counter()
    clean = [build_examples(iter_pushes(args.data_dir / "clean" / f"seed{seed}"))[0]
             for seed in range(args.recorded_seeds)]
    splits.MIN_SEQUENCES = 1  # measured here, so switched off
    rates = {}
    print("| push sequences | draws | anything selected | selections |\n|---:|---:|---:|---|")
    for n in GRID:
        selections = []
        for draw in range(args.draws):
            examples = clean[draw % len(clean)]
            sequences = np.random.default_rng(draw).choice(np.unique(examples.sequence), n, replace=False)
            subset = examples.select(np.isin(examples.sequence, sequences))
            selections.append(select.select_effects(splits.split(subset, len(EFFECT_NAMES), seed=draw),
                                                    seed=draw).selected)
        rates[n] = np.mean([bool(s) for s in selections])
        print(f"| {n} | {args.draws} | {rates[n]:.0%} | {'; '.join('+'.join(s) or '-' for s in selections)} |",
              flush=True)
    minimum = next(n for n in GRID if all(rates[m] <= RATE for m in GRID if m >= n))
    print(f"\nsmallest N from which no N selects anything in more than {RATE:.0%} of draws: {minimum} "
          f"({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
