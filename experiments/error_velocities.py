r"""Fig. 9: the error-term variants (error, error_grad, error_norm) beside hybrid and neural, trained at 20 mm/s,
tested at 10 to 300 mm/s.

  python -m experiments.error_velocities [--scale=smoke|cpu|paper] --workdir=DIR

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("error_velocities", argv)


if __name__ == "__main__":
    experiments.run(main)
