r"""Record simulated MIT Push Dataset files (MuJoCo, MIT protocol and raw layout).

  python -m experiments.record_pushes --out_dir=/tmp/pushes --objects=rect1,tri2 --surfaces=abs \
      --velocities=20,50 --pushes=100 --seed=0 [--accelerations=0] [--repeats=1] [--workers=2] \
      [--effects='com_offset=0.01,0.0;table_tilt_deg=1.0'] [--declare_effects=false] [--support=grid] \
      [--testbed=realistic|ideal] [--testbed_overrides='drop_rate=0;friction_field_sigma=0.2'] \
      [--start_poses=fixed|scattered]

Pushes are drawn from the MIT grid (side, contact point, angle; velocity and acceleration from the flags) and
written to ``<out_dir>/<surface>/<object>/motion_surface=..._shape=..._a=..._v=..._i=..._s=..._t=...h5``.
The same flags give byte-identical files. ``<out_dir>/pushjax_manifest.json`` records the flags that fix the files'
bytes (all but --objects, --surfaces, --pushes and --workers); a later run into the same folder with other such
flags, or into a folder of .h5 files without a manifest, is refused. An interrupted run can be resumed: existing
files that read as valid pushes are kept, invalid (e.g. truncated) ones are recorded again. Runs with the same
flags may record into one folder at once.

``--effects`` takes ``name=value`` items separated by ``;`` with vector components separated by ``,``:
com_offset=dx,dy (m); pressure_rim=k; friction_anisotropy=kx,ky; table_tilt_deg=deg;
table_tilt_azimuth_deg=deg; pusher_friction=mu; tracking_noise=sigma_xy,sigma_yaw (m, rad);
tracking_bias=dx,dy,dyaw (m, m, rad). See ``pushjax.sim.effects`` for what each one does.

``--testbed`` picks the testbed profile of ``pushjax.sim.testbed``: ``realistic`` (the default: uneven support
pressure, friction varying over the table, with the object, with the sliding speed and from push to push, and a
motion-capture system with noise, time-stamp jitter and dropped samples, calibrated against the paper) or ``ideal``
(every push exactly as Lynch's quasi-static model assumes, the clean reference). ``--testbed_overrides`` changes
single magnitudes of the profile, ``name=value`` items separated by ``;`` (0 switches a mechanism off), e.g.
``--testbed=realistic --testbed_overrides='drop_rate=0;pusher_friction_sigma=0.1'``; the fields are those of
``pushjax.sim.testbed.Testbed``.

``--start_poses=scattered`` starts each push from its own drawn pose (position within 0.1 m of the table origin,
any yaw; ``pushjax.sim.dataset.START_POSES``) instead of the MIT protocol's one pose, so that effects fixed to the
table can be told from effects fixed to the object.
"""

import math

from absl import app, flags

import experiments
from pushjax.geometry import OBJECT_NAMES
from pushjax.sim import scene
from pushjax.sim.dataset import START_POSES, OutDirConflictError, RecordingConfig, record_pushes
from pushjax.sim.effects import Effects
from pushjax.sim.surfaces import SURFACE_NAMES
from pushjax.sim.testbed import from_flags

_OUT_DIR = flags.DEFINE_string("out_dir", None, "Dataset root directory.", required=True)
_OBJECTS = flags.DEFINE_list("objects", ["rect1"], f"Objects, from {','.join(OBJECT_NAMES)}.")
_SURFACES = flags.DEFINE_list("surfaces", ["abs"], f"Surfaces, from {','.join(SURFACE_NAMES)}.")
_VELOCITIES = flags.DEFINE_list("velocities", ["20"], "Pusher velocities to draw from, mm/s (> 0).")
_ACCELERATIONS = flags.DEFINE_list("accelerations", ["0"], "Pusher accelerations to draw from, mm/s² (0: constant).")
_PUSHES = flags.DEFINE_integer("pushes", 10, "Distinct pushes per object and surface.", lower_bound=1)
_SEED = flags.DEFINE_integer("seed", 0, "Seed of the push draws and of the tracking noise.", lower_bound=0)
_EFFECTS = flags.DEFINE_string("effects", "", "Effects, e.g. 'com_offset=0.01,0.0;table_tilt_deg=1.0'.")
_DECLARE = flags.DEFINE_bool("declare_effects", True, "Write effects and seed as HDF5 attributes.")
_REPEATS = flags.DEFINE_integer("repeats", 1, "Files per drawn push (_rep=NNNN when > 1).", lower_bound=1)
_WORKERS = flags.DEFINE_integer("workers", None, "Worker processes (default: all cores).", lower_bound=1)
_SUPPORT = flags.DEFINE_enum("support", "grid", list(scene.SUPPORT_MODES), "Support points of the object.")
_START_POSES = flags.DEFINE_enum(
    "start_poses", "fixed", list(START_POSES),
    "Where pushes start: fixed (the MIT protocol: every push from the table origin, yaw 0) or scattered (each from "
    "a drawn position within 0.1 m and yaw).")
_TESTBED = experiments.define_testbed_flag()
_TESTBED_OVERRIDES = flags.DEFINE_string(
    "testbed_overrides", "",
    "Magnitudes of the testbed profile to change, e.g. 'drop_rate=0;friction_field_sigma=0.2'.")


def _numbers(flag: str, values: list[str], low: float, strict: bool) -> list[float]:
    try:
        numbers = [float(value) for value in values]
    except ValueError:
        raise flags.ValidationError(f"--{flag}: expected comma-separated numbers, got {','.join(values)!r}") from None
    if not numbers or any(not math.isfinite(n) or ((n <= low) if strict else (n < low)) for n in numbers):
        raise flags.ValidationError(
            f"--{flag}: expected finite numbers {'>' if strict else '>='} {low:g}, got {','.join(values)!r}")
    return numbers


def _names(flag: str, values: list[str], known: tuple[str, ...]) -> bool:
    unknown = [value for value in values if value not in known]
    if not values or unknown:
        raise flags.ValidationError(
            f"--{flag}: unknown {unknown or 'empty list'}; expected names from {','.join(known)}")
    return True


def _effects(spec: str) -> bool:
    try:
        Effects.parse(spec)
    except ValueError as error:
        raise flags.ValidationError(f"--effects={spec!r}: {error}") from None
    return True


def _testbed_overrides(spec: str) -> bool:
    try:
        from_flags("ideal", spec)
    except ValueError as error:
        raise flags.ValidationError(f"--testbed_overrides={spec!r}: {error}") from None
    return True


experiments.require_writable_folder("out_dir")
flags.register_validator("objects", lambda v: _names("objects", v, OBJECT_NAMES))
flags.register_validator("surfaces", lambda v: _names("surfaces", v, SURFACE_NAMES))
flags.register_validator("velocities", lambda v: _numbers("velocities", v, 0.0, strict=True) is not None)
flags.register_validator("accelerations", lambda v: _numbers("accelerations", v, 0.0, strict=False) is not None)
flags.register_validator("effects", _effects)
flags.register_validator("testbed_overrides", _testbed_overrides)


def main(argv):
    if len(argv) > 1:
        raise app.UsageError(f"unexpected arguments: {' '.join(argv[1:])}")
    try:
        settings = RecordingConfig(
            seed=_SEED.value, velocities=_numbers("velocities", _VELOCITIES.value, 0.0, strict=True),
            accelerations=_numbers("accelerations", _ACCELERATIONS.value, 0.0, strict=False),
            repeats=_REPEATS.value, effects=Effects.parse(_EFFECTS.value), declare_effects=_DECLARE.value,
            support=_SUPPORT.value, testbed=from_flags(_TESTBED.value, _TESTBED_OVERRIDES.value),
            start_poses=_START_POSES.value)
        summary = record_pushes(_OUT_DIR.value, _OBJECTS.value, _SURFACES.value, _PUSHES.value, settings,
                                workers=_WORKERS.value)
    except OutDirConflictError as error:
        raise app.UsageError(f"--{error}") from None
    print(f"wrote {len(summary.written)} files ({len(summary.rerecorded)} replacing invalid files), "
          f"reused {len(summary.skipped)} valid existing files under {_OUT_DIR.value}")


if __name__ == "__main__":
    experiments.run(main)
