r"""Figs. 7-8 style plots of the repeated push: predicted object translations, contact points and normals
of each variant (trained on ``data_efficiency``) for one push under many scene transforms.

  python -m experiments.visualize [--variants=neural,hybrid,simple,error] [--sizes=2500] \
      [--scale=smoke|cpu|paper] --workdir=DIR

Writes fig8_repeated_pushes.png, results.json and results.md to the work directory.
"""

from absl import flags

import experiments
from pushjax.paper import cli

flags.adopt_module_key_flags(cli)


def main(argv):
    cli.main("visualize", argv)


if __name__ == "__main__":
    experiments.run(main)
