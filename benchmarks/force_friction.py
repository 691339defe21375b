"""The pusher–object friction that the force sensor reads (pushjax.loop.force) on recorded pushes.

    python benchmarks/force_friction.py DIR [DIR ...]

For each folder of pushes (raw MIT layout, e.g. from ``python -m experiments.record_pushes``): the coefficient with
its standard error over push sequences, and how many pushes slid long enough to read it.
"""

import argparse
from pathlib import Path

from pushjax.loop import force
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("data_dirs", type=Path, nargs="+")
    for data_dir in parser.parse_args().data_dirs:
        examples, _ = build_examples(iter_pushes(data_dir))
        measured = force.estimate(examples.push_friction, examples.push, examples.sequence)
        value = "none" if measured.value is None else f"{measured.value:.4f} ± {measured.std or 0:.4f}"
        print(f"{data_dir}: {value} ({measured.n_sequences} sequences, {measured.n_pushes} pushes slid, "
              f"{measured.n_pushes_without} did not)")


if __name__ == "__main__":
    main()
