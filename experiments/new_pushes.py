r"""Table 3: the variants on pushes at angles and contact points never seen in training.

  python -m experiments.new_pushes [--sizes=2500,190000] [--scale=smoke|cpu|paper] --workdir=DIR

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("new_pushes", argv)


if __name__ == "__main__":
    experiments.run(main)
