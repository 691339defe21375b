"""The loop on pushes that are not the MIT protocol's: curved pusher paths at varying speed, one episode per folder as
``pushjax.studies.adapt`` records the controller's (``episode_push_path``), every episode a push sequence of its own."""

import dataclasses
import math

import numpy as np
import pytest

from pushjax.loop import LoopConfig, close_loop
from pushjax.loop.correction import CorrectionConfig
from pushjax.loop.fit import FitConfig
from pushjax.loop.windows import build_examples
from pushjax.mit.files import iter_pushes, write_push
from pushjax.sim import push
from pushjax.sim.effects import Effects
from pushjax.studies.adapt import episode_push_path

EPISODES = 12
"""As many as the loop needs to select on (pushjax.loop.splits.MIN_SEQUENCES)."""
SPEED = 0.03
"""Speed limit of the paths, m/s (the file names' v = 30)."""


def _targets(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A pusher start [2] and targets [n, 2] (m, one per 4 ms): still, then an arc towards the object and past its
    centre at a speed varying between half and all of SPEED, then still again; not a straight line at one velocity."""
    start = np.array([-0.08, rng.uniform(-0.02, 0.02)])
    heading, turn = rng.uniform(-0.2, 0.2), rng.uniform(-0.3, 0.3)  # rad, rad/s
    times = np.arange(1, round(2.5 * push.SAMPLE_RATE) + 1) * push.SAMPLE_PERIOD
    speed = SPEED * (0.75 + 0.25 * np.sin(2 * math.pi * times / 1.3))
    angle = heading + turn * times
    steps = (speed * push.SAMPLE_PERIOD)[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    path = start + np.cumsum(steps, axis=0)
    still = round(0.2 * push.SAMPLE_RATE)
    return start, np.concatenate([np.repeat(start[None], still, 0), path, np.repeat(path[-1:], 2 * still, 0)])


@pytest.fixture(scope="module")
def episodes(tmp_path_factory):
    """EPISODES recorded paths on a table tilted by 4 degrees (ideal testbed otherwise), in the study's layout."""
    root = tmp_path_factory.mktemp("controller_pushes")
    simulator = push.simulator("rect1", "abs", Effects(table_tilt_deg=4.0, table_tilt_azimuth_deg=90.0))
    rng = np.random.default_rng(0)
    for number in range(EPISODES):
        start, targets = _targets(rng)
        episode = push.Episode(simulator, (0.0, 0.0, 0.0), start, SPEED)
        recording = episode.advance(targets)
        write_push(episode_push_path(root, "abs", "rect1", number, SPEED), None, recording.tip_pose,
                   recording.object_pose, recording.ft_wrench)
    return root


def test_every_episode_is_a_sequence_of_its_own(episodes):
    files = sorted(episodes.rglob("*.h5"))
    assert len(files) == EPISODES and len({path.name for path in files}) == 1  # the same file-name fields
    examples, summary = build_examples(iter_pushes(episodes), horizon=0.5)
    assert summary.n_pushes == EPISODES and summary.n_skipped == 0
    assert examples.n_sequences == EPISODES and examples.n_pushes == EPISODES
    assert all("episode=" in name for name in examples.sequence_names)
    # The file-name variables hold the study's constants; the windows' own vary.
    assert set(np.unique(examples.variables["push velocity"])) == {30.0}
    assert len(np.unique(examples.variables["push direction in the world"])) > EPISODES
    assert np.ptp(examples.inputs.push_speed) > 0.25 * SPEED  # the speed varies along the paths
    touching = examples.variables["contact versus no contact"] == "contact"
    assert 0 < touching.mean() < 1
    # The object moved where the pusher touched it, and the tilt pulled it downhill (+y) on the way.
    moved = np.linalg.norm(examples.target[:, :2], axis=1)
    assert moved[touching].mean() > 5 * moved[~touching].mean()


def test_the_loop_runs_on_them(episodes, tmp_path):
    settings = LoopConfig(effects=("table_tilt", "cof_offset"), stride=0.5, n_bootstrap=50,
                            fit=FitConfig(steps=60, warm_steps=20),
                            correction=dataclasses.replace(CorrectionConfig(), steps=100, eval_every=50))
    result = close_loop(episodes, tmp_path, settings, seed=0, progress=False)
    assert sum(result.report.n_pushes[role] for role in ("select", "test")) <= EPISODES
    assert result.report.n_pushes["test"] >= 4
    assert (tmp_path / "model.json").is_file() and (tmp_path / "report.md").is_file()
    # The tilt is found from these paths: the drift points downhill (+y; tan(4 deg) / 0.13 = 0.54 over abs's
    # friction) and the test error falls (seed 0: table_tilt and cof_offset, drift (-0.14, 0.47), 41 % -> 7 % of zero).
    assert "table_tilt" in result.report.selected and set(result.model.effects) <= {"table_tilt", "cof_offset"}
    drift = result.model.params["table_tilt"]["drift_force"]
    assert drift[1] > 0.3 and abs(drift[0]) < drift[1]
    assert result.report.after.trans_percent < 0.5 * result.report.baseline.trans_percent
