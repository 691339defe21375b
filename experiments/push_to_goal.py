r"""Push objects to goal poses with model-predictive control, closed on the MuJoCo testbed.

  python -m experiments.push_to_goal --workdir=work/push_to_goal [--scale=smoke|cpu|full] [--objects=rect1,...]
      [--goals=N] [--models=lynch,lynch+friction_ratio,loop] [--effect_params='friction_ratio.log_scale=0.3']
      [--loop_model=W/model.json]
      [--planners=gradient,sampling] [--seed=0] [--surface=abs] [--testbed=realistic|ideal]
      [--testbed_overrides='drop_rate=0'] [--effects='table_tilt_deg=2'] [--max_time=60]
      [--states=mocap,mocap+perception,perception --perception=<a trained model's work directory or checkpoint>
       [--perception_scale=cpu] [--perception_every=1] [--perception_gate=13.8]] [--looks=1]

Draws the goals (``pushjax.control.goals``), runs every model and planner on each (``pushjax.studies.push_to_goal``,
resumable from ``--workdir``/episodes.jsonl) and writes ``results.json``, ``results.md`` and ``trajectories.png``.

``--states`` chooses where the controller's state comes from (``pushjax.studies.episode.STATE_SOURCES``): motion
capture, motion capture and perception, perception only. Perception is the ``--perception`` model's (a hybrid trained
on the ``data_efficiency`` dataset at ``--perception_scale``): the centre of mass it locates in the depth image of the
true scene, rendered as its dataset renders examples, every ``--perception_every`` control periods
(``pushjax.sensing.perception``), a reading skipped when ``--perception_gate`` is given and its squared innovation
exceeds it (``pushjax.studies.episode.PositionSource.gate``); its noise is estimated on one push per object simulated with seed ``--seed`` + 1
(``pushjax.studies.tracking.simulate_pushes``), not on the evaluated episodes.

``--looks`` says how many times the models' comparison has been looked at, this run included (e.g. 2 when more goals
are added to a finished run in the same work folder): the verdict then needs Pocock's larger bound
(``pushjax.stats.decide``).
"""

import dataclasses
import math

from absl import app, flags

import experiments
from pushjax import stats
from pushjax.control import mpc
from pushjax.data import configs as data_configs
from pushjax.sensing import perception
from pushjax.sim.effects import Effects
from pushjax.sim.surfaces import SURFACE_NAMES
from pushjax.studies import episode, push_to_goal, tracking

_WORKDIR = flags.DEFINE_string("workdir", None, "Folder for episodes.jsonl, results.json, results.md, the figure.",
                               required=True)
_SCALE = flags.DEFINE_enum("scale", "cpu", list(push_to_goal.SCALES), "Objects, goals and planners (smoke: a test).")
_OBJECTS = flags.DEFINE_list("objects", None, "Objects (default: the scale's).")
_GOALS = flags.DEFINE_integer("goals", None, "Goals per object (default: the scale's).", lower_bound=1)
_MODELS = flags.DEFINE_list("models", ["lynch"], "Models: lynch or lynch+<effect>+... (pushjax.physics.effects).")
_EFFECT_PARAMS = flags.DEFINE_string("effect_params", "", "The models' effect parameters, effect.parameter=value;...")
_LOOP_MODEL = flags.DEFINE_string("loop_model", None,
                                  "Pushing model file of the model 'loop' (experiments.close_loop's model.json).")
_PLANNERS = flags.DEFINE_list("planners", None, f"Planners from {','.join(mpc.PLANNERS)} (default: the scale's).")
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the goals, the testbed's draws and the planners.", lower_bound=0)
_SURFACE = flags.DEFINE_enum("surface", "abs", list(SURFACE_NAMES), "Surface the objects are pushed on.")
_TESTBED = experiments.define_testbed_flag()
_TESTBED_OVERRIDES = flags.DEFINE_string("testbed_overrides", "", "Testbed magnitudes to change, e.g. 'drop_rate=0'.")
_EFFECTS = flags.DEFINE_string("effects", "", "Effects of the simulated world, e.g. 'table_tilt_deg=2'.")
_MAX_TIME = flags.DEFINE_float("max_time", None, "Simulated seconds per goal (default: the scale's).", lower_bound=1)
_STATES = flags.DEFINE_list("states", ["mocap"], "The controller's state sources from "
                            f"{','.join(episode.STATE_SOURCES)} (perception: needs --perception).")
_PERCEPTION = flags.DEFINE_string("perception", None, "A trained model's work directory or checkpoint "
                                  "(pushjax.train.predictor.load_model; its last model) whose perception reads the "
                                  "object's position from the rendered depth image.")
_PERCEPTION_SCALE = flags.DEFINE_enum("perception_scale", "cpu", list(data_configs.SCALES),
                                      "Scale of the data_efficiency dataset the --perception model was trained on (its "
                                      "camera and image size render the scenes).")
_PERCEPTION_EVERY = flags.DEFINE_integer("perception_every", 1, "Control periods between perception readings.",
                                         lower_bound=1)
_PERCEPTION_GATE = flags.DEFINE_float("perception_gate", None, "Skip a perception reading whose squared innovation "
                                       "(chi-square, 2 degrees of freedom) exceeds this, e.g. 13.8 (99.9 %).",
                                       lower_bound=1e-9)
_LOOKS = flags.DEFINE_integer("looks", 1, "How many times the models' comparison has been looked at, this run "
                              "included (pushjax.stats.SEQUENTIAL_STANDARD_ERRORS: 1-5).", lower_bound=1,
                              upper_bound=max(stats.SEQUENTIAL_STANDARD_ERRORS))
experiments.require_writable_folder("workdir")
NOISE_PUSHES = 1
"""Pushes per object, simulated with seed --seed + 1, on which the perception's noise is estimated."""


@flags.validator("perception_gate", "expected a finite chi-square bound > 0")
def _check_gate(value):
    return value is None or math.isfinite(value)


def _parsed_by(parse):
    """A flag checker that raises parse's one-line error as the flag's."""

    def check(value):
        try:
            parse(value)
        except ValueError as error:
            raise flags.ValidationError(str(error)) from None
        return True

    return check


flags.register_multi_flags_validator(
    ["models", "loop_model"], lambda values: (push_to_goal.LOOP_MODEL in values["models"]) == bool(values["loop_model"]),
    f"--loop_model: expected exactly when --models has '{push_to_goal.LOOP_MODEL}'")
flags.register_multi_flags_validator(
    ["states", "perception"], lambda values: any("perception" in state for state in values["states"])
    == bool(values["perception"]), "--perception: expected exactly when --states has a state with perception")
flags.register_validator("effects", _parsed_by(Effects.parse))
FLAG_NAMES = {"goals_per_object": "goals", "setup.max_time": "max_time"}
"""The flags of the config's fields that are named otherwise (``experiments.config_error``)."""


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    testbed = experiments.testbed_from_flags(_TESTBED.value, _TESTBED_OVERRIDES.value)
    for name in ("perception_scale", "perception_every", "perception_gate"):
        if flags.FLAGS[name].present and _PERCEPTION.value is None:
            raise app.UsageError(f"--{name}: only used with --perception, which is not given")
    try:
        config = push_to_goal.PushToGoalConfig.from_scale(
            _SCALE.value, objects=_OBJECTS.value, goals_per_object=_GOALS.value, models=_MODELS.value,
            planners=_PLANNERS.value, seed=_SEED.value, effect_params=_EFFECT_PARAMS.value,
            loop_model=_LOOP_MODEL.value, looks=_LOOKS.value, max_time=_MAX_TIME.value, surface=_SURFACE.value,
            testbed=testbed, effects=Effects.parse(_EFFECTS.value))
    except ValueError as error:
        raise experiments.config_error(error, FLAG_NAMES) from None
    position = _position(config) if _PERCEPTION.value is not None else {}
    try:
        config = dataclasses.replace(config, states=tuple(_STATES.value), **position)
    except ValueError as error:
        raise experiments.config_error(error, FLAG_NAMES) from None
    try:
        results = push_to_goal.run(config, _WORKDIR.value)
    except push_to_goal.ModelFileError as error:
        raise app.UsageError(f"--loop_model: {error}") from None
    paths = push_to_goal.write(results, _WORKDIR.value)
    print(paths[1].read_text())
    print(f"wrote {', '.join(str(path) for path in paths)}")


def _position(config: push_to_goal.PushToGoalConfig) -> dict:
    """The ``--perception`` model's readings as `config`'s position source and what identifies it: its noise estimated
    on `NOISE_PUSHES` pushes per object simulated with the config's seed + 1, not on the evaluated episodes."""
    try:
        sensor = perception.load_data_efficiency(_PERCEPTION.value, _PERCEPTION_SCALE.value)
    except ValueError as error:
        raise app.UsageError(f"--perception: {' '.join(str(error).split())}") from None
    noise_seed = config.seed + tracking.TRAINING_SEED_OFFSET
    noise_pushes = tracking.simulate_pushes(config.objects, NOISE_PUSHES, noise_seed, config.setup.testbed,
                                            1.0 / config.controller.period)
    noise = perception.estimate_noise(sensor, noise_pushes, _PERCEPTION_EVERY.value)
    position = episode.PositionSource(sensor.locate, tuple(max(v, 1e-5) for v in noise["std"]),
                                      _PERCEPTION_EVERY.value, sensor.description, _PERCEPTION_GATE.value)
    return {"position": position,
            "position_settings": {"model": _PERCEPTION.value, "dataset": f"data_efficiency/{_PERCEPTION_SCALE.value}",
                                  "noise_seed": noise_seed, "noise_bias_m": noise["bias"],
                                  "noise_rmse_m": noise["rmse"], "noise_readings": noise["readings"],
                                  "noise_pushes": noise["pushes"]}}


if __name__ == "__main__":
    experiments.run(main)
