"""Shared simulated data for the loop's tests: one small testbed data set per injected effect, recorded
once per session without declared effects, and the loop's report on each, computed once."""

import dataclasses

import pytest

from pushjax.loop import close_loop
from pushjax.sim.dataset import record_pushes
from pushjax.sim.effects import Effects


@dataclasses.dataclass(frozen=True)
class Case:
    """A testbed data set: its effects and the library effects that should explain them first (empty: none)."""

    effects: Effects
    expected: frozenset[str]


CASES = {
    "clean": Case(Effects(), frozenset()),
    # The testbed's moved centre of mass redistributes the support's normal forces (pushjax.sim.effects): a
    # shifted centre of friction, which cof_offset models alone and pressure_gradient together with its l.
    "com_offset": Case(Effects(com_offset=(0.015, -0.01)), frozenset({"cof_offset", "pressure_gradient"})),
    "pressure": Case(Effects(pressure_rim=-4.0), frozenset({"friction_ratio"})),
    "anisotropy": Case(Effects(friction_anisotropy=(1.0, 2.5)), frozenset({"anisotropic_friction"})),
    "table_tilt": Case(Effects(table_tilt_deg=6.0, table_tilt_azimuth_deg=60.0), frozenset({"table_tilt"})),
    "pusher_friction": Case(Effects(pusher_friction=0.8), frozenset({"pusher_friction"})),
    "tracking_bias": Case(Effects(tracking_bias=(0.01, -0.006, 0.0)), frozenset({"frame_offset"})),
    # Outside the library: the motion-capture yaw is biased by 7 degrees, so every contact is annotated on
    # a turned outline. No effect turns the annotated geometry.
    "tracking_yaw_bias": Case(Effects(tracking_bias=(0.0, 0.0, 0.12)), frozenset()),
    # Two at once: the forward selection must find both.
    "com_offset_and_pusher_friction": Case(Effects(com_offset=(0.015, -0.01), pusher_friction=0.8),
                                           frozenset({"cof_offset", "pressure_gradient", "pusher_friction"})),
}
PUSHES = 120
"""Pushes per data set: rect1 on polyurethane at 20 mm/s (quasi-static), drawn from the MIT grid."""


@pytest.fixture(scope="session")
def record(tmp_path_factory):
    """record(name) -> root of the data set ``CASES[name]`` (recorded on first use)."""
    roots = {}

    def get(name):
        if name not in roots:
            root = tmp_path_factory.mktemp(f"pushes_{name}")
            record_pushes(root, ["rect1"], ["pu"], PUSHES, seed=1, velocities=(20.0,), effects=CASES[name].effects,
                          declare_effects=False, workers=1, progress=False)
            roots[name] = root
        return roots[name]

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
