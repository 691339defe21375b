"""A wrong invocation of a binary is one line on stderr, ``error: <flag or file>: <what was expected>``, and exit
status 2 (`experiments.run`): never absl's flag help, never a traceback.

`test_wrong_invocations` runs the real binaries (``python -m experiments.<name>``, a fresh interpreter each, so that
nothing printed while importing hides) on fourteen wrong invocations, `PARALLEL` at a time: each costs the seconds
of importing JAX, TFDS and MuJoCo, and fails before any dataset is built or model trained. Those that fail on a flag
print exactly one line; those that fail on a file the binary read may print absl's log lines (``I…``, ``W…``) and
progress bars first, and then at most three lines, the last the error. tests/test_binaries_bad_flags.py holds every
flag of every binary to the same line, more cheaply (one process, forked per case), among them the other six of the
twenty wrong invocations of issue 52 (``--sizes=-200``, ``--config.learning_rate=abc``, no ``--workdir``,
``--scale=huge``, an unknown flag, ``track --filters=kalman``).
"""

import concurrent.futures
import os
import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from absl import flags

import experiments
from pushjax.mit import files

REPOSITORY = Path(__file__).resolve().parents[1]
PARALLEL = 4
TIMEOUT_S = 120
LOG_LINE = re.compile(r"^[IWEF]\d{4} \d\d:\d\d:\d\d\.\d+ ")
"""An absl log line (``I1128 14:52:43.523777 140361020308352 file.py:849] ...``)."""
HELP_TEXT = re.compile(r"^\s+--\[?\w|^flags:|^\s+\(default: |USAGE|Try --help")
"""A line of absl's flag help."""

RUN = ("--scale=smoke", "--workdir={tmp}/work", "--data_dir={empty}", "--nobuild")
# (binary, flags, what the error line must name, whether a file the binary read is at fault). Places: {tmp} a fresh
# folder per case, {empty} an empty folder, {damaged_pushes} MIT push files that are all damaged, {old_dataset} a
# data folder whose data_efficiency_smoke dataset was written by another version, {damaged_checkpoint} a
# checkpoint folder with garbage in place of orbax's files, {damaged_raw} a raw folder whose one planned push file
# (repeated_smoke) is not HDF5.
INVOCATIONS = [
    ("build_dataset", [], "--data_dir: expected a value", False),
    ("data_efficiency", [*RUN, "--variants=hybrd"], "--variants: unknown ['hybrd']", False),
    ("train", [*RUN, "--config.learning_rate=-1"], "--config.learning_rate: expected > 0", False),
    ("data_efficiency", [*RUN, "--config.model.head_features=64,,32"],
     "--config.model.head_features: expected comma-separated integers > 0", False),
    ("rollouts", [*RUN, "--test_splits=test_999"], "--test_splits: expected some of test_10", False),
    ("push_to_goal", ["--workdir={tmp}/goals", "--states=perception", "--perception={tmp}/missing"],
     "--perception: path: {tmp}/missing is not a folder", False),
    ("push_to_goal", ["--workdir={tmp}/goals", "--models=lynch,loop", "--loop_model={tmp}/missing.json"],
     "--loop_model: {tmp}/missing.json: expected a pushing model file", False),
    ("close_loop", ["--workdir={tmp}/loop"], "--data_dir: expected a value", False),
    ("record_pushes", ["--out_dir={tmp}/pushes", "extra"], "unexpected arguments: extra", False),
    ("demo", ["--mu=-1"], "--mu: expected a finite non-negative friction coefficient", False),
    ("findings", ["--workdirs={tmp}/missing"], "--workdirs: {tmp}/missing/results.json does not exist", False),
    # A file the binary reads.
    ("close_loop", ["--workdir={tmp}/loop", "--data_dir={damaged_pushes}"],
     "--data_dir: pushes: none gave a prediction window", True),
    ("data_efficiency", [*RUN, "--data_dir={old_dataset}"],
     "--data_dir: {old_dataset}/push_effects/data_efficiency_smoke/3.0.0 is not a readable push_effects 3.0.0 "
     "dataset", True),
    ("track", ["--workdir={tmp}/track", "--perception={damaged_checkpoint}"],
     "--perception: path: the checkpoint {damaged_checkpoint}/checkpoints/7 cannot be read", True),
]


def _write_damaged_pushes(root: Path) -> None:
    """Four push files, each damaged another way: truncated, not HDF5, NaN in a pose, a pose of 3 columns."""
    time = np.linspace(0.0, 2.0, 501)
    pose = np.stack([time, 0.001 * time, 0 * time, 0 * time], axis=-1)
    paths = [files.push_file_path(root, files.PushParams("abs", "rect1", 0, 20, 0, 0.5, angle))
             for angle in (0.1, 0.2, 0.3, 0.4)]
    files.write_push(paths[0], None, pose, pose, pose)
    paths[0].write_bytes(paths[0].read_bytes()[:300])
    paths[1].write_text("not HDF5")
    with h5py.File(paths[2], "w") as file:
        file["tip_pose"], file["object_pose"], file["ft_wrench"] = pose, np.where(time[:, None] > 1, np.nan, pose), pose
    with h5py.File(paths[3], "w") as file:
        file["tip_pose"], file["object_pose"], file["ft_wrench"] = pose, pose[:, :3], pose


def _places(folder: Path) -> dict[str, Path]:
    places = {"tmp": folder / "fresh", "empty": folder / "empty", "damaged_pushes": folder / "damaged_pushes",
              "old_dataset": folder / "old_dataset", "damaged_checkpoint": folder / "damaged_checkpoint"}
    places["tmp"].mkdir(parents=True)
    places["empty"].mkdir()
    _write_damaged_pushes(places["damaged_pushes"])
    version = places["old_dataset"] / "push_effects" / "data_efficiency_smoke" / "3.0.0"
    version.mkdir(parents=True)
    (version / "dataset_info.json").write_text('{"name": "push_effects", "version": "2.0.0"}')
    step = places["damaged_checkpoint"] / "checkpoints" / "7"
    for item in ("state", "metadata"):
        (step / item).mkdir(parents=True)
    (step / "state" / "_METADATA").write_text("garbage")
    (step / "metadata" / "metadata").write_text("garbage")
    return places


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory) -> list[tuple[list[str], dict[str, Path], subprocess.CompletedProcess]]:
    """Each of `INVOCATIONS` run: (its arguments, its places, how it ended)."""
    base = tmp_path_factory.mktemp("usage_errors")
    runs = []
    for index, (binary, arguments, _, _) in enumerate(INVOCATIONS):
        places = _places(base / f"case{index}")
        runs.append(([sys.executable, "-m", f"experiments.{binary}", *(a.format(**places) for a in arguments)],
                     places))

    def run(command):
        return subprocess.run(command, cwd=REPOSITORY, capture_output=True, text=True, timeout=TIMEOUT_S,
                              env={**os.environ, "MUJOCO_GL": "egl"})

    with concurrent.futures.ThreadPoolExecutor(PARALLEL) as pool:
        results = list(pool.map(run, [command for command, _ in runs]))
    return [(command, places, result) for (command, places), result in zip(runs, results)]


@pytest.mark.parametrize("index", range(len(INVOCATIONS)),
                         ids=[f"{binary}-{'-'.join(a.split('=')[0].strip('-') for a in arguments[-1:]) or 'none'}"
                              for binary, arguments, _, _ in INVOCATIONS])
def test_wrong_invocations(outcomes, index):
    command, places, result = outcomes[index]
    _, _, names, file_at_fault = INVOCATIONS[index]
    shown = f"{' '.join(command[2:])}: exit {result.returncode}, stderr:\n{result.stderr[-3000:]}"
    assert result.returncode == experiments.USAGE_ERROR_STATUS, shown
    assert "Traceback" not in result.stderr, shown
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert not any(HELP_TEXT.search(line) for line in lines), shown
    if file_at_fault:  # log lines and progress bars may come first
        lines = [line for line in lines if not LOG_LINE.match(line) and "|" not in line and line.strip() != "[A"]
        assert 1 <= len(lines) <= 3, shown
    else:
        assert len(lines) == 1, shown
    assert lines[-1].startswith("error: ") and names.format(**places) in lines[-1], shown


@pytest.mark.parametrize("arguments, expected", [
    (["--data_dir=x", "--scale=huge"], "--scale=huge: value should be one of <smoke|cpu|cpu_full|paper_full|paper>"),
    (["--data_dir=x", "--bogus=2"], "--bogus: unknown flag (--helpshort lists the flags)"),
    (["--data_dir=x", "--scal=cpu"], "--scal: unknown flag; did you mean --scale? (--helpshort lists the flags)"),
    (["--data_dir=x", "--scale"], "--scale: expected a value"),
    (["--data_dir=x", "--nobuild=yes"], "--nobuild: takes no value (a boolean flag)"),
    ([], "--data_dir: expected a value (the flag is required)"),
    (["--data_dir=x", "--workers=0", "--seed=-1"], "--workers=0: expected a positive integer"),  # the first only
    (["--data_dir=x", "--loop_model=x"], "--loop_model: expected exactly when --models has 'loop'"),
])
def test_flag_errors_are_one_line_naming_the_flag(arguments, expected):
    """absl's messages for the flag errors it finds, as `experiments.flag_error_message` words them."""
    values = flags.FlagValues()
    flags.DEFINE_enum("scale", "cpu", ["smoke", "cpu", "cpu_full", "paper_full", "paper"], "", flag_values=values)
    flags.DEFINE_list("sizes", [], "", flag_values=values)
    flags.DEFINE_bool("build", True, "", flag_values=values)
    flags.DEFINE_string("data_dir", None, "", required=True, flag_values=values)
    flags.DEFINE_integer("workers", 1, "", flag_values=values)
    flags.DEFINE_integer("seed", 0, "", flag_values=values)
    flags.DEFINE_list("models", ["lynch"], "", flag_values=values)
    flags.DEFINE_string("loop_model", None, "", flag_values=values)
    flags.register_validator("workers", lambda value: value >= 1, "expected a positive integer", flag_values=values)
    flags.register_validator("seed", lambda value: value >= 0, "expected an integer >= 0", flag_values=values)
    flags.register_multi_flags_validator(
        ["models", "loop_model"], lambda v: ("loop" in v["models"]) == bool(v["loop_model"]),
        "--loop_model: expected exactly when --models has 'loop'", flag_values=values)
    with pytest.raises((flags.Error, ValueError)) as error:
        values(["binary", *arguments])
    assert experiments.flag_error_message(error.value) == expected


def test_usage_errors_exit_2_with_one_line(capsys):
    with pytest.raises(SystemExit) as exit:
        experiments.exit_usage_error("--workdir: expected\n  a folder")
    assert exit.value.code == 2 == experiments.USAGE_ERROR_STATUS
    assert capsys.readouterr().err == "error: --workdir: expected a folder\n"
