r"""Track pushes of the testbed with the EKF, UKF and particle filter, and infer the pusher friction.

  python -m experiments.track --workdir=work/track [--scale=smoke|cpu] [--filters=ekf,ukf,particle,ekf_learned]
      [--seed=0 | --seeds=1,2,3] [--rate_hz=10] [--learn_steps=200] [--testbed=realistic|ideal] [--testbed_overrides='drop_rate=0.1']
      [--perception=<a trained model's work directory or checkpoint> [--perception_hz=2.5] [--perception_scale=cpu]]

Simulates the scale's pushes in memory (``pushjax.studies.tracking``: the truth only the simulation knows), filters
the tracked poses, and writes ``results.json``, ``results.md`` (pose RMSE against the raw measurements and a
constant-velocity filter, NEES in its 95 % band, the pusher friction against its drawn value, the hand-set and the
learned noise) and ``mu_over_time.png`` to ``--workdir``. ``ekf_learned`` learns its noise on as many other pushes,
simulated with seed ``--seed`` + 1, before the pushes of ``--seed`` are filtered.

``--perception`` adds a second observation stream: the object's centre of mass that the trained model's perception
locates in the depth image of the true scene, rendered at ``--perception_hz`` as the model's dataset
(``data_efficiency`` at ``--perception_scale``) renders its examples (``pushjax.sensing.perception``); its noise is
estimated on the pushes of seed ``--seed`` + 1, never on the evaluated ones. Rows ``ekf_perception`` (motion capture
and perception), ``ekf_perception_only`` (perception after the first motion-capture sample) and ``perception`` (the
readings themselves). The model's folder is only read.

``--seeds=1,2,3`` runs each seed into ``--workdir/seed<k>/`` (a seed whose ``results.json`` is there is read, not run
again) and writes to ``--workdir`` the filters' position errors per seed and their paired comparisons over the pushes
of every seed but the one the process noise was tuned on (``pushjax.studies.tracking.compare_over_seeds``).
"""

import dataclasses
import json
from pathlib import Path

from absl import app, flags

import experiments
from pushjax.data import configs as data_configs
from pushjax import outputs
from pushjax.sensing import perception
from pushjax.studies import tracking

_WORKDIR = flags.DEFINE_string("workdir", None, "Folder for results.json, results.md and the figure.", required=True)
_SCALE = flags.DEFINE_enum("scale", "cpu", list(tracking.SCALES), "Objects, pushes and particles (smoke: a test).")
_FILTERS = flags.DEFINE_list("filters", list(tracking.FILTERS), f"Filters, from {','.join(tracking.FILTERS)}.")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the pushes, the testbed's draws and the particle filter.",
                             lower_bound=0)
_SEEDS = flags.DEFINE_list("seeds", None, "Several seeds, each run into --workdir/seed<k>/, and their comparison over "
                           f"the seeds but the tuning seed {tracking.TUNING_SEED}.")
_RATE = flags.DEFINE_float("rate_hz", None, "Filter rate, Hz: 250 divided by a whole number (default: the scale's).")
_LEARN_STEPS = flags.DEFINE_integer("learn_steps", None,
                                    "Adam steps of ekf_learned's noise (default: the scale's).")
_TESTBED = experiments.define_testbed_flag()
_TESTBED_OVERRIDES = flags.DEFINE_string(
    "testbed_overrides", "", "Magnitudes of the testbed profile to change, e.g. 'drop_rate=0.1'.")
_PERCEPTION = flags.DEFINE_string(
    "perception", None, "A trained model's work directory or checkpoint (pushjax.train.predictor.load_model; its last "
    "model): its perception's object position becomes a second observation stream of the EKF.")
_PERCEPTION_HZ = flags.DEFINE_float("perception_hz", 2.5, "Rate of the perception readings, Hz: the filter rate "
                                    "divided by a whole number.")
_PERCEPTION_SCALE = flags.DEFINE_enum("perception_scale", "cpu", list(data_configs.SCALES),
                                      "Scale of the data_efficiency dataset the --perception model was trained on (its "
                                      "camera and image size render the scenes).")
experiments.require_writable_folder("workdir")


@flags.validator("seeds", "expected distinct seeds >= 0, at least one of them not the tuning seed "
                          f"{tracking.TUNING_SEED}")
def _check_seeds(values):
    if values is None:
        return True
    if not all(value.isdigit() for value in values) or len(set(map(int, values))) != len(values):
        return False
    return any(int(value) != tracking.TUNING_SEED for value in values)


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    if _SEEDS.value is not None and flags.FLAGS["seed"].present:
        raise app.UsageError("--seed: give --seed or --seeds, not both")
    testbed = experiments.testbed_from_flags(_TESTBED.value, _TESTBED_OVERRIDES.value)
    if _LEARN_STEPS.value is not None and "ekf_learned" not in _FILTERS.value:
        raise app.UsageError("--learn_steps: only used by ekf_learned, which --filters leaves out")
    for name in ("perception_hz", "perception_scale"):
        if flags.FLAGS[name].present and _PERCEPTION.value is None:
            raise app.UsageError(f"--{name}: only used with --perception, which is not given")
    try:
        config = tracking.TrackingConfig.from_scale(
            _SCALE.value, filters=_FILTERS.value, rate_hz=_RATE.value, learn_steps=_LEARN_STEPS.value,
            seed=_SEED.value, testbed=testbed, perception_hz=_PERCEPTION_HZ.value)
        if _PERCEPTION.value is not None:
            config = dataclasses.replace(config, perception=_sensor())
    except ValueError as error:
        raise experiments.config_error(error) from None
    if _SEEDS.value is None:
        paths = tracking.write(tracking.run(config, _WORKDIR.value), _WORKDIR.value)
        print(paths[1].read_text())
        print(f"wrote {', '.join(str(path) for path in paths)}")
        return
    records = []
    for seed in map(int, _SEEDS.value):
        folder = Path(_WORKDIR.value) / f"seed{seed}"
        if (folder / "results.json").is_file():
            record = json.loads((folder / "results.json").read_text())
            if (record.get("scale"), record.get("filters", [])[:len(_FILTERS.value)]) != (_SCALE.value, _FILTERS.value):
                raise app.UsageError(f"--workdir: {folder} holds a run of other settings (scale, filters): use a fresh "
                                     f"--workdir")
            print(f"seed {seed}: read {folder / 'results.json'}")
        else:
            record = tracking.run(dataclasses.replace(config, seed=seed), folder)
            tracking.write(record, folder)
        records.append(record)
    comparison = tracking.compare_over_seeds(records)
    table = tracking.seeds_table(comparison)
    paths = outputs.write_report(_WORKDIR.value, {"scale": _SCALE.value, "seeds": [int(s) for s in _SEEDS.value],
                                                  **comparison}, table)
    print(table)
    print(f"wrote {', '.join(str(path) for path in paths)}")


def _sensor() -> perception.PerceptionSensor:
    """The ``--perception`` model's perception (a usage error naming the flag when it cannot be loaded)."""
    try:
        return perception.load_data_efficiency(_PERCEPTION.value, _PERCEPTION_SCALE.value)
    except ValueError as error:
        raise app.UsageError(f"--perception: {' '.join(str(error).split())}") from None


if __name__ == "__main__":
    experiments.run(main)
