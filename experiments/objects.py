r"""Fig. 7: neural, hybrid and error trained on butter (+ hex, + ellip1 or tri1), tested on ellipses and triangles.

  python -m experiments.objects [--scale=smoke|cpu|paper] --workdir=DIR

Writes results.json, results.md and PNG figures to the work directory (all flags: --help).
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("objects", argv)


if __name__ == "__main__":
    experiments.run(main)
