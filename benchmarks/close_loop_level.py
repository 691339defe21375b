"""The level of the loop's selection: how often does it select an effect where none can help? (By hand; not a
timed test.)

Clean data sets of the independent set-up of ``benchmarks/close_loop_power.py`` (recorded there) with their
targets replaced by the plain Lynch model's prediction plus its own residual, the residual's sign flipped per push
sequence at random: every sequence keeps its residual's size and within-push structure, but no effect can predict
it on sequences it was not fitted on. The loop's split and forward selection then run as in the loop, at 200
and at 100 pushes, each both with a single fit/select split and cross-fitted (the loop's choice below
``pushjax.loop.splits.CROSS_FIT_BELOW`` select sequences).

Criterion, fixed before measuring: the selection controls the family-wise error at 0.05, so on this null it should
select anything in at most 5 % of the draws; a count of draws with a selection whose probability at a true rate of
5 % is at most 0.05 (with 12 draws: 3 or more) says the selection is too liberal on that path.

    python benchmarks/close_loop_level.py [--data_dir /tmp/close_loop_power/data] [--draws 12]
"""

import argparse
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from pushjax.loop import fit as fit_lib
from pushjax.loop import select, splits
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes
from pushjax.physics.effects import EFFECT_NAMES

PATHS = {"200 pushes, single split": (200, 0), "100 pushes, cross-fitted": (100, 10**6),
         "100 pushes, single split": (100, 0), "200 pushes, cross-fitted": (200, 10**6)}
"""name -> (push sequences, CROSS_FIT_BELOW for the path)."""
LEVEL = 0.05


def too_many(draws: int) -> int:
    """The smallest count of selecting draws that a selection rate of LEVEL reaches with probability <= LEVEL."""
    def tail(k):
        return sum(math.comb(draws, j) * LEVEL ** j * (1 - LEVEL) ** (draws - j) for j in range(k, draws + 1))
    return next(k for k in range(draws + 2) if k > draws or tail(k) <= LEVEL)


def null_examples(examples, pushes: int, seed: int):
    """`pushes` sequences of `examples` with targets plain prediction + residual with a random sign per sequence."""
    rng = np.random.default_rng(seed)
    sequences = np.unique(examples.sequence)
    if pushes < len(sequences):
        examples = examples.select(np.isin(examples.sequence, rng.choice(sequences, pushes, replace=False)))
    plain = fit_lib.predict([None], examples)[0]
    ids, index = np.unique(examples.sequence, return_inverse=True)
    signs = rng.choice([-1.0, 1.0], len(ids))[index]
    return dataclasses.replace(examples, target=plain + signs[:, None] * (examples.target - plain))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data_dir", type=Path, default=Path("/tmp/close_loop_power/data"))
    parser.add_argument("--draws", type=int, default=12)
    parser.add_argument("--recorded_seeds", type=int, default=12, help="clean data sets recorded under data_dir")
    args = parser.parse_args()
    start = time.perf_counter()
    clean = [build_examples(iter_pushes(args.data_dir / "clean" / f"seed{seed}"))[0]
             for seed in range(args.recorded_seeds)]
    print("| path | draws | anything selected | selections |\n|---|---:|---:|---|")
    for name, (pushes, cross_fit_below) in PATHS.items():
        splits.CROSS_FIT_BELOW = cross_fit_below
        selections = []
        for draw in range(args.draws):
            examples = null_examples(clean[draw % len(clean)], pushes, draw)
            selections.append(select.select_effects(splits.split(examples, len(EFFECT_NAMES), seed=draw),
                                                    seed=draw).selected)
        count = sum(bool(s) for s in selections)
        verdict = "too liberal" if count >= too_many(args.draws) else "within the level"
        print(f"| {name} | {args.draws} | {count / args.draws:.0%} ({verdict}) | "
              f"{'; '.join('+'.join(s) or '-' for s in selections)} |", flush=True)
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
