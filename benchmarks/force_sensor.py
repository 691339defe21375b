"""What the force sensor reads as the pusher-object friction in recorded pushes (by hand; not a timed test).

For each data set: the loop's pooled reading (``pushjax.loop.force.estimate`` over every push sequence) and, per object
and push velocity, the spread of the per-push readings (``pushjax.loop.force.sliding_friction``): a per-push reading
far below the rest is a push whose sticking samples were counted as sliding.

    python benchmarks/force_sensor.py --data DIR [DIR ...]
"""

from __future__ import annotations

import argparse
import collections
import sys
from pathlib import Path

import numpy as np

from pushjax.loop import force
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, nargs="+", required=True, help="push folders (raw MIT layout)")
    arguments = parser.parse_args()
    for folder in arguments.data:
        if not folder.is_dir():
            sys.exit(f"--data: {folder} is not a directory")
    for folder in arguments.data:
        examples, _ = build_examples(iter_pushes(folder))
        pooled = force.estimate(examples.push_friction, examples.push, examples.sequence)
        std = f" ± {pooled.std:.3f}" if pooled.std is not None else ""
        value = f"{pooled.value:.3f}{std}" if pooled.value is not None else "none"
        print(f"{folder}: {value} ({pooled.n_pushes} pushes with a reading, {pooled.n_pushes_without} without)")
        _, first = np.unique(examples.push, return_index=True)
        groups = collections.defaultdict(list)
        for index in first:
            if np.isfinite(examples.push_friction[index]):
                key = (str(examples.variables["object"][index]), float(examples.variables["push velocity"][index]))
                groups[key].append(examples.push_friction[index])
        for (shape, velocity), values in sorted(groups.items()):
            p10, median, p90 = np.percentile(values, [10, 50, 90])
            print(f"  {shape} at {velocity:g} mm/s: {len(values)} pushes, per push p10 {p10:.3f}, median {median:.3f}, "
                  f"p90 {p90:.3f}")


if __name__ == "__main__":
    main()
