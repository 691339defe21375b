r"""Track pushes of the testbed with the EKF, UKF and particle filter, and infer the pusher friction.

  python -m experiments.track --workdir=work/track [--scale=smoke|cpu] [--filters=ekf,ukf,particle,ekf_learned]
      [--seed=0] [--rate_hz=10] [--learn_steps=200] [--testbed=realistic|ideal] [--testbed_overrides='drop_rate=0.1']

Simulates the scale's pushes in memory (``pushjax.filter.tracking``: the truth only the simulation knows), filters
the tracked poses, and writes ``results.json``, ``results.md`` (pose RMSE against the raw measurements and a
constant-velocity filter, NEES in its 95 % band, the pusher friction against its drawn value, the hand-set and the
learned noise) and ``mu_over_time.png`` to ``--workdir``. ``ekf_learned`` learns its noise on as many other pushes,
simulated with seed ``--seed`` + 1, before the pushes of ``--seed`` are filtered.
"""

import math

from absl import app, flags

import experiments
from pushjax.filter import tracking

_WORKDIR = flags.DEFINE_string("workdir", None, "Folder for results.json, results.md and the figure.", required=True)
_SCALE = flags.DEFINE_enum("scale", "cpu", list(tracking.SCALES), "Objects, pushes and particles (smoke: a test).")
_FILTERS = flags.DEFINE_list("filters", list(tracking.FILTERS), f"Filters, from {','.join(tracking.FILTERS)}.")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the pushes, the testbed's draws and the particle filter.",
                             lower_bound=0)
_RATE = flags.DEFINE_float("rate_hz", None, "Filter rate, Hz: 250 divided by a whole number (default: the scale's).")
_LEARN_STEPS = flags.DEFINE_integer("learn_steps", None,
                                    "Adam steps of ekf_learned's noise (default: the scale's).")
_TESTBED = experiments.define_testbed_flag()
_TESTBED_OVERRIDES = flags.DEFINE_string(
    "testbed_overrides", "", "Magnitudes of the testbed profile to change, e.g. 'drop_rate=0.1'.")
experiments.require_writable_folder("workdir")


@flags.validator("filters", "expected a non-empty list of known filters, no repeats")
def _check_filters(values):
    return bool(values) and len(set(values)) == len(values) and all(v in tracking.FILTERS for v in values)


@flags.validator("rate_hz", f"expected {tracking.RECORDING_RATE_HZ} Hz divided by a whole number")
def _check_rate(value):
    if value is None:
        return True
    if not (math.isfinite(value) and 0 < value <= tracking.RECORDING_RATE_HZ):
        return False
    step = tracking.RECORDING_RATE_HZ / value
    return abs(step - round(step)) < 1e-9


@flags.validator("learn_steps", "expected a whole number of steps >= 1")
def _check_learn_steps(value):
    return value is None or value >= 1


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    testbed = experiments.testbed_from_flags(_TESTBED.value, _TESTBED_OVERRIDES.value)
    scale = tracking.SCALES[_SCALE.value]
    rate = _RATE.value or scale["rate_hz"]
    learns = "ekf_learned" in _FILTERS.value
    if _LEARN_STEPS.value is not None and not learns:
        raise app.UsageError("--learn_steps: only used by ekf_learned, which --filters leaves out")
    pushes = tracking.simulate_pushes(scale["objects"], scale["pushes"], _SEED.value, testbed, rate)
    training_seed = _SEED.value + tracking.TRAINING_SEED_OFFSET
    training_pushes = (tracking.simulate_pushes(scale["objects"], scale["pushes"], training_seed, testbed, rate)
                       if learns else [])
    measurement_std = (max(testbed.tracking_noise_xy, 1e-5), max(testbed.tracking_noise_xy, 1e-5),
                       max(testbed.tracking_noise_yaw, 1e-4))
    results = tracking.run(pushes, _FILTERS.value, rate, scale["particles"], _SEED.value, measurement_std,
                           training_pushes, _LEARN_STEPS.value or scale["learn_steps"])
    results.update(scale=_SCALE.value, seed=_SEED.value, testbed=testbed.to_dict())
    if learns:
        results.update(training_seed=training_seed)
    paths = tracking.write(results, _WORKDIR.value)
    print(paths[1].read_text())
    print(f"wrote {', '.join(str(path) for path in paths)}")


if __name__ == "__main__":
    experiments.run(main)
