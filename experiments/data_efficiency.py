r"""Table 1, Fig. 5 and Table 2: every variant and the zero / physics baselines by training-set size.

  python -m experiments.data_efficiency --sizes=2500,190000 [--seeds=0,1,2] [--scale=smoke|cpu|paper] --workdir=DIR

Sizes larger than the training split are clipped with a warning.

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("data_efficiency", argv)


if __name__ == "__main__":
    experiments.run(main)
