"""Shared simulated data for the loop's tests: one small testbed data set per injected effect, recorded
once per test run without declared effects, and the loop's report on each, computed once. The data sets are shared
by every pytest-xdist worker (the suite runs a test file per worker, and several files use the same data)."""

import dataclasses

import pytest

from tests.conftest import _shared_folder, once_across_workers

from pushjax.loop import close_loop
from pushjax.sim.dataset import record_pushes
from pushjax.sim.effects import Effects


@dataclasses.dataclass(frozen=True)
class Case:
    """A testbed data set: its effects and the library effects that should explain them first (empty: none)."""

    effects: Effects
    expected: frozenset[str]
    pushes: int = 120


REAL_DIFFERENCES = frozenset({"limit_surface", "inertia"})
"""What any simulator has that Lynch's model lacks: the exact limit surface of its support instead of the ellipsoid, and
motion after the pusher stops. Selecting them on clean data is no false discovery."""
KNOWN_FALSE_DISCOVERIES = frozenset({"pusher_friction", "friction_field", "frame_offset"})
"""Effects the loop still selects where the testbed has none (issue 29 is open on this): once the exact surface has
removed the ellipsoid's error, the noise-free residual of these 120-push sets is small and structured enough that
``pusher_friction`` (a scale of about 1.14), ``friction_field`` (a curvature of the field that follows the fixed start
pose along the push) and, with anisotropic friction, ``frame_offset`` pass every test (Holm, the floor above the noise
floor); with one object, surface and velocity the mechanism check has nothing to compare. The tests hold the loop to
these and no others."""

CASES = {
    "clean": Case(Effects(), REAL_DIFFERENCES),
    # The testbed's moved centre of mass redistributes the support's normal forces (pushjax.sim.effects): a
    # shifted centre of friction, which cof_offset models alone and pressure_gradient together with its l.
    "com_offset": Case(Effects(com_offset=(0.015, -0.01)), frozenset({"cof_offset", "pressure_gradient"})),
    "pressure": Case(Effects(pressure_rim=-4.0), frozenset({"limit_surface"})),
    "anisotropy": Case(Effects(friction_anisotropy=(1.0, 2.5)), frozenset({"anisotropic_friction"})),
    "table_tilt": Case(Effects(table_tilt_deg=6.0, table_tilt_azimuth_deg=60.0), frozenset({"table_tilt"})),
    "pusher_friction": Case(Effects(pusher_friction=0.8), frozenset({"pusher_friction"})),
    "tracking_bias": Case(Effects(tracking_bias=(0.01, -0.006, 0.0)), frozenset({"frame_offset"})),
    # Outside the library: the motion-capture yaw is biased by 7 degrees, so every contact is annotated on
    # a turned outline. No effect turns the annotated geometry.
    "tracking_yaw_bias": Case(Effects(tracking_bias=(0.0, 0.0, 0.12)), frozenset()),
    # Two at once: the forward selection must find both. Alone, either effect explains the pushes only in part
    # (pusher friction the slipping ones, the offset the others), so the first round needs more sequences: on
    # 120 pushes (30 select sequences) pusher_friction's gain (30 %) has p = 0.023 > 0.05 / 10; on 240, 3e-4.
    "com_offset_and_pusher_friction": Case(Effects(com_offset=(0.015, -0.01), pusher_friction=0.8),
                                           frozenset({"cof_offset", "pressure_gradient", "pusher_friction"}),
                                           pushes=240),
}
PUSHES = 120
"""Pushes per data set unless the case says otherwise: rect1 on polyurethane at 20 mm/s (quasi-static), drawn
from the MIT grid."""


@pytest.fixture(scope="session")
def record(tmp_path_factory):
    """record(name) -> root of the data set ``CASES[name]`` (recorded on first use)."""
    shared = _shared_folder(tmp_path_factory)

    def get(name):
        root = shared / f"loop_pushes_{name}"
        return once_across_workers(root, lambda: record_pushes(
            root, ["rect1"], ["pu"], CASES[name].pushes, seed=1, velocities=(20.0,), effects=CASES[name].effects,
            declare_effects=False, workers=1, progress=False))

    return get


@pytest.fixture(scope="session")
def loop_report(record, tmp_path_factory):
    """loop_report(name) -> (report.json content, workdir) of the loop on ``CASES[name]`` (run on first use)."""
    reports = {}

    def get(name):
        if name not in reports:
            workdir = tmp_path_factory.mktemp(f"loop_{name}")
            reports[name] = (close_loop(record(name), workdir, progress=False), workdir)
        return reports[name]

    return get
