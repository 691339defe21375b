r"""Sec. V: the hybrid model on the free (oblique) camera with point clouds.

  python -m experiments.viewpoint [--scale=smoke|cpu|paper] --workdir=DIR

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("viewpoint", argv)


if __name__ == "__main__":
    experiments.run(main)
