"""``python -m experiments.adapt --scale=smoke`` end to end (the rows of the arms by block, the figure, the
controller's own pushes in the MIT layout, the loop run on them after the first block and the second block planned
with its model), a second run over the same work folder (nothing simulated again, the same bytes; an interrupted
episode simulated again), a bad flag as one line, and the study's parts without simulation: the config's validation
and the comparison rule."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pushjax import stats
from pushjax.loop import splits
from pushjax.mit.files import load_push, parse_push_file_name
from pushjax.sim.surfaces import PUSHER_OBJECT_FRICTION
from pushjax.studies import adapt, adapt_report, worlds

REPOSITORY = Path(__file__).resolve().parents[2]


def _binary(*arguments):
    # A process of its own: the binary's flags clash with other binaries' (absl).
    return subprocess.run([sys.executable, "-m", "experiments.adapt", *arguments], cwd=REPOSITORY,
                          env={**os.environ, "MUJOCO_GL": "egl"}, capture_output=True, text=True, timeout=900,
                          check=False)


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    """``--scale=smoke`` run once by the binary: (work folder, its stdout)."""
    workdir = tmp_path_factory.mktemp("adapt")
    result = _binary("--scale=smoke", f"--workdir={workdir}")
    assert result.returncode == 0, result.stderr[-3000:]
    return workdir, result.stdout


def _outcome(row):
    return row["position_error_mm"], row["yaw_error_deg"], row["path_length_m"], row["stop"], row["time_s"]


def test_smoke_run_switches_to_the_loops_model_and_writes_the_arms_by_block(smoke):
    workdir, stdout = smoke
    assert f"wrote {workdir / 'results.json'}" in stdout
    config = adapt.SCALES["smoke"]
    text = (workdir / "results.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    results = json.loads(text)
    assert results["comparison_rule"] == adapt.COMPARISON_RULE
    rows = {(row["effect"], row["arm"], row["block"]): row for row in results["rows"]}
    assert set(rows) == {(effect, arm, block) for effect in config.effects for arm in adapt.ARMS
                         for block in range(config.blocks)}
    for (_, _, block), row in rows.items():
        assert row["episodes"] == config.block_start(block + 1) - config.block_start(block)
        assert 0 <= row["success_rate"] <= 1 and row["path_length_m"] > 0
        assert 0 < row["time_to_goal_s"] <= config.max_time + 1 and row["time_to_goal_se_s"] is None  # one world
    episodes = results["episodes"]
    assert len(episodes) == len(config.effects) * config.episodes * len(adapt.ARMS) == 4 * 18
    for row in episodes:
        assert row["time_to_goal_s"] == (row["time_s"] if row["success"] else config.max_time)
    by_arm = {arm: {block: [row for row in episodes if row["arm"] == arm and row["block"] == block]
                    for block in range(config.blocks)} for arm in adapt.ARMS}
    for block in range(config.blocks):
        assert [row["goal"] for row in by_arm["adaptive"][block]] == [row["goal"] for row in by_arm["oracle"][block]]
    nominal = {"effects": [], "pusher_friction": PUSHER_OBJECT_FRICTION}
    true_mu = results["worlds"][0]["magnitude"]["pusher_friction"]
    assert all(row["model"] == {"effects": [], "pusher_friction": true_mu}
               for block in by_arm["oracle"].values() for row in block)
    assert all(row["model"] == nominal for block in by_arm["plain"].values() for row in block)
    # The filtered arm plans with plain Lynch whose friction follows the EKF within each episode: on this low-friction
    # world many of its 6 s pushes are its own, not the plain arm's (where the pusher never slid, the filter has
    # nothing to move its friction by).
    filtered, plain = (sum(by_arm[arm].values(), []) for arm in ("filtered", "plain"))
    assert all(row["model"] == nominal for row in filtered)
    assert [row["goal"] for row in filtered] == [row["goal"] for row in plain]
    assert sum(_outcome(one) != _outcome(other) for one, other in zip(filtered, plain, strict=True)) >= len(plain) // 4
    assert results["filter_rule"] == adapt.FILTER_RULE
    within = results["filter_comparison"]["pusher_friction"]
    assert within["goals"] == config.episodes and within["verdict"] == "not decided"
    assert within["filtered_minus_plain_s"]["standard_error"] is None

    # Block 1 (16 episodes): the loop has not run, so the adaptive arm plans with plain Lynch: the plain arm's episodes.
    assert all(row["model"] == nominal for row in by_arm["adaptive"][0])
    assert list(map(_outcome, by_arm["adaptive"][0])) == list(map(_outcome, by_arm["plain"][0]))
    # Then the loop runs on the controller's 16 pushes (at least the 12 push sequences it needs): it selects no effect
    # (its one candidate, the pusher friction, is measured instead) and its model carries the pusher friction that
    # the force sensor read while the pusher slid, near the world's true one (not the nominal 0.25).
    assert config.block_start(1) >= splits.minimum_sequences(len(config.loop.effects), config.loop.alpha)
    assert [(row["block"], row["pushes"], row["ran"]) for row in results["loop"]] == [(0, 16, True), (1, 18, True)]
    switch = results["loop"][0]
    assert switch["selected"] == [] and switch["model"]["effects"] == []
    measured = switch["model"]["pusher_friction"]
    assert abs(measured - true_mu) < 0.2 * true_mu and measured < 0.6 * PUSHER_OBJECT_FRICTION
    assert switch["reason"] == f"the loop's model: nothing selected (Lynch), pusher friction {measured:.3f}"
    report = json.loads((workdir / "pusher_friction" / "world=0" / "loop" / "block=0" / "report.json").read_text())
    assert report["pusher_friction"]["from_force_sensor"]
    assert report["pusher_friction"]["used"] == pytest.approx(measured, rel=1e-6)
    # Block 2 plans with the loop's model, so the adaptive arm's episodes are its own, not the plain arm's.
    assert all(row["model"] == {"effects": [], "pusher_friction": measured} for row in by_arm["adaptive"][1])
    for adaptive_row, plain_row in zip(by_arm["adaptive"][1], by_arm["plain"][1], strict=True):
        assert adaptive_row["goal"] == plain_row["goal"] and _outcome(adaptive_row) != _outcome(plain_row)
    assert max(abs(adaptive_row["path_length_m"] - plain_row["path_length_m"])  # by more than rounding: 23 mm
               for adaptive_row, plain_row in zip(by_arm["adaptive"][1], by_arm["plain"][1])) > 0.005

    # One world seed: no standard error over world seeds (null, not NaN), so not decided, and why.
    comparison = results["comparison"]["pusher_friction"]
    assert comparison["criterion_s"]["standard_error"] is None and comparison["verdict"] == "not decided"
    assert comparison["reason"] == "one world seed: no standard error over world seeds"
    markdown = (workdir / "results.md").read_text()
    assert "| adaptive | 2 | 2 |" in markdown and "(one world seed: no standard error" in markdown
    # The loop's model beside the world's truth (the world's drawn friction): the measured friction after block 1.
    truth = next(line for line in markdown.splitlines() if line.startswith("| 0 | Lynch, μ "))
    assert truth.split(" | ")[2] == f"Lynch, μ {measured:.3f}" and "(pusher_friction " in truth.split(" | ")[1]
    assert (workdir / "time_to_goal.png").stat().st_size > 5000
    # The controller's own pushes, one folder (and push sequence) per episode, readable as MIT files.
    files = sorted((workdir / "pusher_friction" / "world=0" / "pushes").rglob("*.h5"))
    assert [path.parent.name for path in files] == [f"episode={k:04d}" for k in range(config.episodes)]
    push = load_push(files[0])
    assert push.params == parse_push_file_name(files[0]) and push.params.velocity == 40.0
    assert np.ptp(push.tip[:, 0]) > 0.02 and len(push.time) > 250 * 4


def _outputs(workdir):
    return {path.relative_to(workdir): path.read_bytes() for path in sorted(workdir.rglob("*"))
            if path.is_file() and not path.name.startswith(".")}


def test_the_report_shows_no_share_of_a_gap_that_is_not_there():
    assert adapt_report._gap_text({"plain_minus_oracle_s": -0.8, "plain_minus_adaptive_s": -0.9,
                                   "gap_closed_share": 1.125}).endswith("no gap to close (the oracle is not faster than plain)")
    assert adapt_report._gap_text({"plain_minus_oracle_s": 2.2, "plain_minus_adaptive_s": 1.5,
                                   "gap_closed_share": 1.5 / 2.2}).endswith("gap closed 68%")


def test_a_second_run_reads_back_what_the_first_finished(smoke, monkeypatch, capsys):
    workdir, _ = smoke
    config = adapt.SCALES["smoke"]
    first = _outputs(workdir)
    run_episode = adapt.episode.run_episode
    mtimes = {path: path.stat().st_mtime_ns for path in workdir.rglob("*") if path.is_file()}

    def refuse(*args, **kwargs):
        raise AssertionError("simulated or ran the loop again")

    # Over the finished work folder: nothing simulated and no loop run, the same bytes, no file written again.
    monkeypatch.setattr(adapt.episode, "run_episode", refuse)
    monkeypatch.setattr(adapt, "close_loop", refuse)
    adapt.write(adapt.run(config, workdir), workdir)
    assert "adapt: 0 episodes simulated, 72 read back; the loop ran 0 times, 2 read back" in capsys.readouterr().out
    assert _outputs(workdir) == first
    assert all(path.stat().st_mtime_ns == mtime for path, mtime in mtimes.items()
               if path.name not in ("results.json", "results.md", "time_to_goal.png"))

    # Interrupted in the last episode: the adaptive arm's push file written but not its record, the oracle arm's
    # record half written. Those two episodes are simulated again; the loop's runs still stand (the pushes are the
    # same); the same bytes.
    last = workdir / "pusher_friction" / "world=0" / "episodes" / f"episode={config.episodes - 1:04d}"
    (last / "adaptive.json").unlink()
    (last / "oracle.json").write_text((last / "oracle.json").read_text()[:100])
    calls = []

    def counted(controller, model, config, task, **kwargs):
        calls.append(task.index)
        return run_episode(controller, model, config, task, **kwargs)

    monkeypatch.setattr(adapt.episode, "run_episode", counted)
    adapt.write(adapt.run(config, workdir), workdir)
    assert len(calls) == 2
    assert "adapt: 2 episodes simulated, 70 read back; the loop ran 0 times, 2 read back" in capsys.readouterr().out
    assert _outputs(workdir) == first


def test_a_bad_flag_is_one_line(tmp_path):
    result = _binary(f"--workdir={tmp_path}", "--effect=wind")
    assert result.returncode == 2
    assert result.stderr.strip().splitlines()[-1].startswith("error: --effect=wind: expected one of tilt,")
    assert "Traceback" not in result.stderr


def test_report_only_writes_the_tables_again_and_leaves_the_record(smoke, tmp_path):
    workdir = tmp_path / "published"
    workdir.mkdir()
    recorded = (smoke[0] / "results.json").read_bytes()
    (workdir / "results.json").write_bytes(recorded)
    result = _binary("--report_only", f"--workdir={workdir}")
    assert result.returncode == 0, result.stderr[-3000:]
    assert (workdir / "results.json").read_bytes() == recorded  # the run's provenance kept
    assert (workdir / "results.md").read_text() == (smoke[0] / "results.md").read_text()
    assert (workdir / "time_to_goal.png").stat().st_size > 5000
    assert sorted(path.name for path in workdir.iterdir()) == ["results.json", "results.md", "time_to_goal.png"]
    missing = _binary("--report_only", f"--workdir={tmp_path / 'empty'}")
    assert missing.returncode == 2 and "Traceback" not in missing.stderr
    assert missing.stderr.strip().splitlines()[-1].startswith("error: --report_only: no results.json in --workdir")


def test_the_config_is_validated_and_its_scales_are_defined_once():
    assert set(adapt.SCALES) == {"smoke", "cpu"}
    cpu = adapt.SCALES["cpu"]
    assert cpu.effects == worlds.EFFECTS and cpu.worlds == 3 and cpu.world_seeds == (0, 1, 2)
    # The loop can run (one push sequence per episode) before the last block.
    assert math.ceil(splits.MIN_SEQUENCES / cpu.per_block) < cpu.blocks
    assert adapt.make_config("smoke", worlds=2, seed=5).world_seeds == (5, 6)
    # The first block may differ from the others: episodes 0-15, 16-17, 18-19 at the smoke scale with 3 blocks.
    three = adapt.make_config("smoke", blocks=3)
    assert [three.block_start(block) for block in range(4)] == [0, 16, 18, 20] and three.episodes == 20
    assert cpu.block_start(2) == 12 and cpu.episodes == 24 and cpu.as_dict()["first_block"] == 6
    for overrides, field in ((dict(effects=("wind",)), "effects"), (dict(objects=()), "objects"),
                             (dict(worlds=0), "worlds"), (dict(per_block=1.5), "per_block"),
                             (dict(first_block=0), "first_block"),
                             (dict(max_time=math.nan), "max_time"), (dict(seed=-1), "seed"),
                             (dict(surface="ice"), "surface")):
        with pytest.raises(ValueError, match=f"^{field}: expected"):
            adapt.make_config("smoke", **overrides)
    with pytest.raises(ValueError, match="^scale"):
        adapt.make_config("huge")


def _rows(times_by_world):
    """Episode rows of the last block (1) from {world: [(plain, adaptive, oracle) time per goal]}."""
    return [{"world": world, "arm": arm, "object": "rect1", "index": index, "block": 1, "time_to_goal_s": time}
            for world, goals in times_by_world.items() for index, times in enumerate(goals)
            for arm, time in zip(("plain", "adaptive", "oracle"), times)]


def test_the_comparison_rule():
    # The adaptive arm closes most of a 10 s gap in every world: decided.
    closes = adapt.compare(_rows({w: [(30, 22 + w, 20), (28, 20, 18 + w)] for w in range(3)}), 1)
    assert closes["verdict"] == "closes the gap" and closes["goals"] == 6 and closes["worlds"] == 3
    assert 0.5 < closes["gap_closed_share"] < 1
    short = adapt.compare(_rows({w: [(30, 30 - w * 0.1, 20)] for w in range(3)}), 1)
    assert short["verdict"] == "falls short"
    one = adapt.compare(_rows({0: [(30, 20, 20)]}), 1)
    assert one["verdict"] == "not decided" and one["criterion_s"]["standard_error"] is None
    assert one["reason"] == "one world seed: no standard error over world seeds"
    # No gap between plain and oracle: no share of it (null, not NaN).
    assert adapt.compare(_rows({w: [(20, 20, 20)] for w in range(2)}), 1)["gap_closed_share"] is None
    # The verdict is the project's decision rule (stats.decide on the paired difference, 2 standard errors).
    within = adapt.compare(_rows({0: [(30, 24, 20)], 1: [(30, 26.5, 20)]}), 1)  # d = 1 and -1.5: mean -0.25
    assert within["verdict"] == "not decided" and "within 2 standard errors" in within["reason"]
    for result in (closes, short, within):
        mean, error = result["criterion_s"]["mean"], result["criterion_s"]["standard_error"]
        assert result["verdict"] == adapt.VERDICTS[stats.decide(-mean, error)]


def test_the_filter_rule():
    def rows(times_by_world):  # {world: [(plain, filtered) time per goal]}, goals spread over two blocks
        return [{"world": world, "arm": arm, "object": "rect1", "index": index, "block": index % 2,
                 "time_to_goal_s": time}
                for world, goals in times_by_world.items() for index, times in enumerate(goals)
                for arm, time in zip(("plain", "filtered"), times)]

    helps = adapt.compare_filtered(rows({w: [(30, 25 + w * 0.5), (20, 17)] for w in range(3)}))
    assert helps["verdict"] == "helps" and helps["goals"] == 6 and helps["worlds"] == 3
    hurts = adapt.compare_filtered(rows({w: [(20, 24 + w)] for w in range(3)}))
    assert hurts["verdict"] == "hurts"
    mixed = adapt.compare_filtered(rows({0: [(20, 22)], 1: [(20, 19)]}))
    assert mixed["verdict"] == "not decided" and mixed["filtered_minus_plain_s"]["mean"] == 0.5
    one = adapt.compare_filtered(rows({0: [(30, 20)]}))
    assert one["verdict"] == "not decided" and one["reason"] == "one world seed: no standard error over world seeds"
    assert adapt.compare_filtered(rows({}))["goals"] == 0
    for result in (helps, hurts, mixed):
        difference = result["filtered_minus_plain_s"]
        assert result["verdict"] == adapt.FILTER_VERDICTS[stats.decide(difference["mean"], difference["standard_error"])]

