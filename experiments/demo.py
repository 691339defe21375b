r"""Push each of the 11 MIT objects with the analytical Lynch model and print a table.

  python -m experiments.demo [--mu=0.25] [--angle_deg=20]
"""

from absl import app, flags

from pushjax.demo import analytical_push_table

_MU = flags.DEFINE_float("mu", 0.25, "Pusher-object friction coefficient.")
_ANGLE = flags.DEFINE_float("angle_deg", 20.0, "Push angle to the side's inward normal, degrees.")
_POINT = flags.DEFINE_float("point", 0.3, "Contact point along side 0, fraction in [0, 1].")


def main(argv):
    del argv
    print(analytical_push_table(mu=_MU.value, angle_deg=_ANGLE.value, point=_POINT.value))


if __name__ == "__main__":
    app.run(main)
