r"""Push each of the 11 MIT objects with the analytical Lynch model and print a table.

  python -m experiments.demo [--mu=0.25] [--angle_deg=20] [--point=0.3]
"""

from absl import app, flags

import experiments
from pushjax.physics.demo import analytical_push_table

_MU = flags.DEFINE_float("mu", 0.25, "Pusher-object friction coefficient, finite and >= 0.")
_ANGLE = flags.DEFINE_float("angle_deg", 20.0, "Push angle to the side's inward normal, degrees in (-90, 90).")
_POINT = flags.DEFINE_float("point", 0.3, "Contact point along side 0, fraction in [0, 1].")


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    try:
        table = analytical_push_table(mu=_MU.value, angle_deg=_ANGLE.value, point=_POINT.value)
    except ValueError as error:  # a bad mu, angle_deg or point, named as the flag is
        raise app.UsageError(f"--{error}") from None
    print(table)
    print("wrote no files: the table above is the whole output")


if __name__ == "__main__":
    experiments.run(main)
