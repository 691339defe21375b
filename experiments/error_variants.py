r"""Table 4 and Fig. 9 (error, error_grad, error_norm by training-set size) and Table 5 (physics, hybrid and
error with the limit-surface ratio l set to 1.5 and 3 times its true value).

  python -m experiments.error_variants [--sizes=2500,190000] [--scale=smoke|cpu|paper] --workdir=DIR

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("error_variants", argv)


if __name__ == "__main__":
    experiments.run(main)
