r"""Fig. 6: neural, neural_dyn, simple, hybrid and error trained at 20, 10 + 20 and 20 + 50 mm/s, tested at 10 to
300 mm/s.

  python -m experiments.velocities [--scale=smoke|cpu|paper] --workdir=DIR

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("velocities", argv)


if __name__ == "__main__":
    experiments.run(main)
