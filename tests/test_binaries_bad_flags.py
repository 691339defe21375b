"""Every flag of every binary under ``experiments/`` rejects a bad value with one line naming the flag.

Each case runs ``python -m experiments.<binary> <flags>`` in a process of its own, which must exit with status 2
and print ``error: <flag>: <what was expected>`` as the last line of stderr, with no traceback, no flag help and at
most three lines besides absl's log lines, before any dataset is built or model trained (a run that goes on is
killed after `CASE_TIMEOUT_S`). Starting Python and importing JAX, TFDS and MuJoCo takes
seconds, so one server process imports the binaries' libraries once and forks a child per case, which runs the
binary as ``python -m`` does (``runpy`` as ``__main__``, with ``sys.argv`` set) and reports how it ended as the
interpreter does, then skips the interpreter's seconds-long teardown of those libraries.
"""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]
CASE_TIMEOUT_S = 60
PARALLEL = 3
USAGE_ERROR_STATUS = 2  # experiments.USAGE_ERROR_STATUS
LOG_LINE = re.compile(r"^[IWEF]\d{4} \d\d:\d\d:\d\d\.\d+ ")
"""An absl log line (``I1128 14:52:43.523777 140361020308352 file.py:849] ...``)."""
HELP_TEXT = re.compile(r"^\s+--\[?\w|^flags:|^\s+\(default: |Try --help")
"""A line of absl's flag help."""

LIBRARIES = ("experiments, pushjax.data, pushjax.loop, pushjax.paper.findings, pushjax.paper.figures, "
             "pushjax.paper.rollouts, pushjax.paper.runner, pushjax.paper.spec, pushjax.paper.tables, "
             "pushjax.paper.visualize, pushjax.physics.demo, pushjax.sim.dataset, pushjax.studies.push_to_goal, "
             "pushjax.studies.adapt, pushjax.studies.loop_power")
"""What the binaries import, bar the binaries themselves (each defines flags): a server imports it once and forks."""

# The server: imports the libraries (not the binaries, which define the flags), then forks one child per case.
SERVER = r"""
import contextlib, json, os, runpy, signal, sys, time
import """ + LIBRARIES + r"""


def run_as_main(binary):
    # The exit status of `python -m experiments.<binary>`, with what the interpreter prints on the way out.
    try:
        runpy.run_module(f"experiments.{binary}", run_name="__main__", alter_sys=True)
    except SystemExit as exit:
        if exit.code is None or isinstance(exit.code, int):
            return exit.code or 0
        print(exit.code, file=sys.stderr)
        return 1
    except BaseException:
        sys.excepthook(*sys.exc_info())
        return 1
    return 0


cases, out, parallel, timeout = json.load(open(sys.argv[1])), sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
running, codes = {}, {}  # child -> (case, deadline); case -> exit status


def reap_one():
    # Waits for a child to end; one past its deadline is killed with its process group (e.g. build workers).
    while True:
        pid, status = os.waitpid(-1, os.WNOHANG)
        if pid:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(pid, signal.SIGKILL)
            codes[running.pop(pid)[0]] = os.waitstatus_to_exitcode(status)
            return
        for pid, (_, deadline) in running.items():
            if time.monotonic() > deadline:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(pid, signal.SIGKILL)
        time.sleep(0.02)


for index, (binary, arguments) in enumerate(cases):
    while len(running) >= parallel:
        reap_one()
    sys.stdout.flush(), sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        os.setpgid(0, 0)
        for fd, stream in ((1, "stdout"), (2, "stderr")):
            os.dup2(os.open(f"{out}/{index}.{stream}", os.O_WRONLY | os.O_CREAT | os.O_TRUNC), fd)
        sys.argv = ["-m", *arguments]
        status = run_as_main(binary)
        sys.stdout.flush(), sys.stderr.flush()
        os._exit(status)
    with contextlib.suppress(PermissionError, ProcessLookupError):  # the child may have done it already
        os.setpgid(pid, pid)
    running[pid] = (index, time.monotonic() + timeout)
while running:
    reap_one()
json.dump([codes[index] for index in range(len(cases))], sys.stdout)
"""

EXPERIMENTS = ("data_efficiency", "new_pushes", "velocities", "objects", "error_variants", "viewpoint", "visualize",
               "rollouts")
# Each case has its own {tmp}: a fresh folder; {file}: a regular file; {empty}: an empty folder (no dataset, no
# pushes, no results); and all share {read_only}: a folder this process cannot write in.
RUN = ("--scale=smoke", "--workdir={tmp}/work", "--data_dir={empty}", "--nobuild")
CASES = [
    # (binary, flags, the flag the last line of stderr must name)
    # The flags every experiment binary shares (pushjax/paper/cli.py), on data_efficiency.
    ("data_efficiency", [*RUN, "--scale=huge"], "--scale"),
    ("data_efficiency", ["--scale=smoke", "--data_dir={empty}", "--nobuild"], "--workdir"),
    ("data_efficiency", [*RUN, "--workdir="], "--workdir"),
    ("data_efficiency", [*RUN, "--workdir={file}/work"], "--workdir"),
    ("data_efficiency", [*RUN, "--workdir={read_only}/work"], "--workdir"),
    ("data_efficiency", [*RUN, "--min_test_sequences=-3"], "--min_test_sequences"),
    ("visualize", [*RUN, "--min_test_sequences=150"], "--min_test_sequences"),
    ("data_efficiency", [*RUN, "--sizes=ten"], "--sizes"),
    ("data_efficiency", [*RUN, "--sizes=0"], "--sizes"),
    ("data_efficiency", [*RUN, "--sizes=-5"], "--sizes"),
    ("data_efficiency", [*RUN, "--sizes=nan"], "--sizes"),
    ("data_efficiency", [*RUN, "--seeds=-1"], "--seeds"),
    ("data_efficiency", [*RUN, "--seeds=x"], "--seeds"),
    ("data_efficiency", [*RUN, "--seeds="], "--seeds"),
    ("data_efficiency", [*RUN, "--num_steps=0"], "--num_steps"),
    ("data_efficiency", [*RUN, "--num_steps=-3"], "--num_steps"),
    ("data_efficiency", [*RUN, "--num_steps=nan"], "--num_steps"),
    ("data_efficiency", [*RUN, "--data_dir={tmp}/missing"], "--data_dir"),
    ("data_efficiency", [*RUN, "--data_dir={file}"], "--data_dir"),
    ("data_efficiency", [*RUN], "--build"),  # --nobuild and no dataset
    ("data_efficiency", [*RUN, "--build=maybe"], "--build"),
    ("data_efficiency", ["--scale=smoke", "--workdir={tmp}/work", "--data_dir={read_only}"], "--data_dir"),
    ("data_efficiency", [*RUN, "--workers=0"], "--workers"),
    ("data_efficiency", [*RUN, "--workers=-2"], "--workers"),
    ("data_efficiency", [*RUN, "--mode=fast"], "--mode"),
    ("data_efficiency", [*RUN, "--variants=transformer"], "--variants"),
    ("data_efficiency", [*RUN, "--variants=,"], "--variants"),
    ("data_efficiency", [*RUN, "--testbed=perfect"], "--testbed"),
    ("data_efficiency", [*RUN, "--num_processes=0"], "--num_processes"),
    ("data_efficiency", [*RUN, "--process_id=-1"], "--process_id"),
    ("data_efficiency", [*RUN, "--num_processes=2", "--process_id=2", "--coordinator_address=127.0.0.1:1"],
     "--process_id"),
    ("data_efficiency", [*RUN, "--num_processes=2"], "--coordinator_address"),
    ("data_efficiency", [*RUN, "--num_processes=2", "--coordinator_address=localhost"], "--coordinator_address"),
    ("data_efficiency", [*RUN, "--coordinator_address=127.0.0.1:1234"], "--coordinator_address"),
    ("data_efficiency", [*RUN, "extra"], "unexpected arguments"),
    ("data_efficiency", [*RUN, "--config.schedule=bogus"], "--config.schedule"),
    ("data_efficiency", [*RUN, "--config.bogus=1"], "config.bogus"),
    ("data_efficiency", [*RUN, "--sizes=-200"], "--sizes"),
    ("data_efficiency", [*RUN, "--variants=hybrd"], "--variants"),
    ("data_efficiency", [*RUN, "--bogus=1"], "--bogus"),
    ("data_efficiency", [*RUN, "--nobuild=x"], "--nobuild"),
    ("data_efficiency", [*RUN, "--scale"], "--scale"),
    *[("data_efficiency", [*RUN, f"--config.{field}={value}"], f"--config.{field}")
      for field, value in (("learning_rate", "abc"), ("learning_rate", "-1"), ("learning_rate", "nan"),
                           ("weight_decay", "-1"), ("batch_size", "1.5"), ("model.head_features", "64,,32"),
                           ("model.head_features", "64,"), ("model.head_features", ""),
                           ("model.head_features", "0,8"), ("model.glimpse_kernel", "0"),
                           ("model.batch_norm_momentum", "2"))],
    # Each other experiment binary: the shared flags are wired, and its datasets are looked for.
    *[(binary, [*RUN], "--build") for binary in EXPERIMENTS[1:]],
    *[(binary, [*RUN, "--workdir={file}/work"], "--workdir") for binary in EXPERIMENTS[1:]],
    *[(binary, [*RUN, "--sizes=0"], "--sizes") for binary in EXPERIMENTS[1:]],
    # rollouts: its own flag and the variants it can roll out.
    ("rollouts", [*RUN, "--test_splits=test_7"], "--test_splits"),
    ("rollouts", [*RUN, "--test_splits=test_999"], "--test_splits"),
    ("rollouts", [*RUN, "--test_splits=test_20,test_20"], "--test_splits"),
    ("rollouts", [*RUN, "--variants=simple"], "--variants"),
    # train: the shared flags and its own.
    ("train", [*RUN, "--experiment=bogus"], "--experiment"),
    ("train", [*RUN, "--variant=transformer"], "--variant"),
    ("train", [*RUN, "--variant=hybrid", "--mix_error_variants"], "--mix_error_variants"),
    ("train", [*RUN, "--train_split=bogus"], "--train_split"),
    ("train", [*RUN, "--test_split="], "--test_split"),
    ("train", [*RUN, "--experiment=velocities", "--train_split=train"], "--train_split"),
    ("train", [*RUN], "--build"),
    ("train", [*RUN, "--workdir={file}/work"], "--workdir"),
    ("train", [*RUN, "--seeds=1.5"], "--seeds"),
    ("train", [*RUN, "extra"], "unexpected arguments"),
    ("train", [*RUN, "--config.batch_size=x"], "--config.batch_size"),
    ("train", [*RUN, "--config.model.head_features=a,b"], "--config.model.head_features"),
    # build_dataset
    ("build_dataset", ["--data_dir={tmp}/data", "--experiment=bogus"], "--experiment"),
    ("build_dataset", ["--data_dir={tmp}/data", "--scale=huge"], "--scale"),
    ("build_dataset", [], "--data_dir"),
    ("build_dataset", ["--data_dir={file}/data"], "--data_dir"),
    ("build_dataset", ["--data_dir={read_only}/data"], "--data_dir"),
    ("build_dataset", ["--data_dir={tmp}/data", "--seed=-1"], "--seed"),
    ("build_dataset", ["--data_dir={tmp}/data", "--workers=0"], "--workers"),
    ("build_dataset", ["--data_dir={tmp}/data", "--raw_dir={tmp}/missing"], "--raw_dir"),
    ("build_dataset", ["--data_dir={tmp}/data", "--testbed=perfect"], "--testbed"),
    ("build_dataset", ["--data_dir={tmp}/data", "--experiment=repeated", "--min_test_sequences=5"],
     "--min_test_sequences"),
    ("build_dataset", ["--data_dir={tmp}/data", "--raw_dir={file}"], "--raw_dir"),
    ("build_dataset", ["--data_dir={tmp}/data", "extra"], "unexpected arguments"),
    # record_pushes
    ("record_pushes", [], "--out_dir"),
    ("record_pushes", ["--out_dir={file}/pushes"], "--out_dir"),
    ("record_pushes", ["--out_dir={read_only}/pushes"], "--out_dir"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--objects=box"], "--objects"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--objects="], "--objects"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--surfaces=ice"], "--surfaces"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--velocities=nan"], "--velocities"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--velocities=20,inf"], "--velocities"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--velocities=0"], "--velocities"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--velocities=fast"], "--velocities"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--velocities="], "--velocities"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--accelerations=-1"], "--accelerations"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--accelerations=nan"], "--accelerations"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--pushes=0"], "--pushes"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--seed=-1"], "--seed"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--effects=gravity=2"], "--effects"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--effects=com_offset=nan,0"], "--effects"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--declare_effects=maybe"], "--declare_effects"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--repeats=0"], "--repeats"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--workers=0"], "--workers"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--support=disc"], "--support"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--start_poses=random"], "--start_poses"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--testbed=perfect"], "--testbed"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--testbed_overrides=drop_rate=2"], "--testbed_overrides"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--testbed_overrides=wind=1"], "--testbed_overrides"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "--testbed_overrides=drop_rate"], "--testbed_overrides"),
    ("record_pushes", ["--out_dir={tmp}/pushes", "extra"], "unexpected arguments"),
    # close_loop
    ("close_loop", ["--workdir={tmp}/loop"], "--data_dir"),
    ("close_loop", ["--workdir={tmp}/loop", "--data_dir={tmp}/missing"], "--data_dir"),
    ("close_loop", ["--workdir={tmp}/loop", "--data_dir={empty}"], "--data_dir"),
    ("close_loop", ["--data_dir={empty}"], "--workdir"),
    ("close_loop", ["--data_dir={empty}", "--workdir={file}/loop"], "--workdir"),
    ("close_loop", ["--data_dir={empty}", "--workdir={read_only}/loop"], "--workdir"),
    *[("close_loop", ["--data_dir={empty}", "--workdir={tmp}/loop", f"--{flag}={value}"], f"--{flag}")
      for flag, values in (("horizon", ("0", "-1", "nan", "inf")), ("seed", ("-1",)),
                           ("heldout_fraction", ("0", "1.5", "nan")), ("min_gain", ("-0.1", "1", "nan")),
                           ("min_strength", ("-0.1", "2", "nan")), ("steps", ("0",)))
      for value in values],
    ("close_loop", ["--data_dir={empty}", "--workdir={tmp}/loop", "--effects=limit_surface,grain"], "--effects"),
    ("close_loop", ["--data_dir={empty}", "--workdir={tmp}/loop", "--effects="], "--effects"),
    ("close_loop", ["--data_dir={empty}", "--workdir={tmp}/loop", "extra"], "unexpected arguments"),
    # findings
    ("findings", [], "--workdirs"),
    ("findings", ["--workdirs="], "--workdirs"),
    ("findings", ["--workdirs={tmp}/missing"], "--workdirs"),
    ("findings", ["--workdirs={empty}"], "--workdirs"),
    ("findings", ["--workdirs={file}"], "--workdirs"),
    ("findings", ["--workdirs={empty}", "--output={empty}"], "--output"),
    ("findings", ["--workdirs={empty}", "--output={file}/table.md"], "--output"),
    ("findings", ["--workdirs={empty}", "--output={read_only}/table.md"], "--output"),
    ("findings", ["--workdirs={empty}", "extra"], "unexpected arguments"),
    # track
    ("track", [], "--workdir"),
    ("track", ["--workdir={file}/track"], "--workdir"),
    ("track", ["--workdir={read_only}/track"], "--workdir"),
    *[("track", ["--workdir={tmp}/track", f"--{flag}={value}"], f"--{flag}")
      for flag, values in (("scale", ("paper", "huge")), ("filters", ("kalman", "ekf,ekf", "")),
                           ("seed", ("-1",)), ("rate_hz", ("0", "7", "nan", "500")),
                           ("learn_steps", ("0", "-3", "1.5")),
                           ("testbed", ("perfect",)), ("testbed_overrides", ("drop_rate=2", "wind=1")))
      for value in values],
    ("track", ["--workdir={tmp}/track", "--learn_steps=5", "--filters=ekf,ukf"], "--learn_steps"),
    ("track", ["--workdir={tmp}/track", "extra"], "unexpected arguments"),
    ("track", ["--workdir={tmp}/track", "--seeds=0"], "--seeds"),
    ("track", ["--workdir={tmp}/track", "--seeds=1,1"], "--seeds"),
    ("track", ["--workdir={tmp}/track", "--seeds=1,x"], "--seeds"),
    ("track", ["--workdir={tmp}/track", "--seed=1", "--seeds=2,3"], "--seed"),
    ("track", ["--workdir={tmp}/track", "--perception={tmp}/missing"], "--perception"),
    ("track", ["--workdir={tmp}/track", "--perception={empty}"], "--perception"),
    # pool_goals
    ("pool_goals", ["--workdir={tmp}/pooled"], "--runs"),
    ("pool_goals", ["--runs={tmp}/missing,{tmp}/missing2", "--workdir={tmp}/pooled"], "--runs"),
    ("pool_goals", ["--runs={empty},{empty}", "--workdir={tmp}/pooled"], "--runs"),
    ("pool_goals", ["--runs={empty}"], "--workdir"),
    # push_to_goal
    ("push_to_goal", [], "--workdir"),
    ("push_to_goal", ["--workdir={file}/goals"], "--workdir"),
    ("push_to_goal", ["--workdir={read_only}/goals"], "--workdir"),
    *[("push_to_goal", ["--workdir={tmp}/goals", f"--{flag}={value}"], f"--{flag}")
      for flag, values in (("scale", ("huge",)), ("objects", ("box", "rect1,rect1", "")),
                           ("goals", ("0", "x")), ("models", ("newton", "lynch+wind", "")),
                           ("effect_params", ("friction_ratio=1", "wind.speed=1")),
                           ("planners", ("newton", "gradient,gradient", "")), ("seed", ("-1",)),
                           ("surface", ("ice",)), ("testbed", ("perfect",)),
                           ("testbed_overrides", ("drop_rate=2", "wind=1")), ("effects", ("gravity=2",)),
                           ("max_time", ("0", "nan")))
      for value in values],
    ("push_to_goal", ["--workdir={tmp}/goals", "extra"], "unexpected arguments"),
    ("push_to_goal", ["--workdir={tmp}/goals", "--models=lynch,loop"], "--loop_model"),
    ("push_to_goal", ["--workdir={tmp}/goals", "--loop_model={file}"], "--loop_model"),
    ("push_to_goal", ["--workdir={tmp}/goals", "--models=loop", "--loop_model={tmp}/missing.json"], "--loop_model"),
    ("push_to_goal", ["--workdir={tmp}/goals", "--models=loop", "--loop_model={file}"], "--loop_model"),
    ("push_to_goal", ["--workdir={tmp}/goals", "--states=perception", "--perception={tmp}/missing"], "--perception"),
    ("push_to_goal", ["--workdir={tmp}/goals", "--states=perception"], "--perception"),
    # adapt
    ("adapt", [], "--workdir"),
    ("adapt", ["--workdir={file}/adapt"], "--workdir"),
    *[("adapt", ["--workdir={tmp}/adapt", f"--{flag}={value}"], f"--{flag}")
      for flag, values in (("scale", ("huge",)), ("effect", ("wind", "")), ("worlds", ("0", "x")),
                           ("blocks", ("0",)), ("per_block", ("-1",)), ("first_block", ("0",)),
                           ("max_time", ("0", "nan")), ("seed", ("-1",)))
      for value in values],
    ("adapt", ["--workdir={tmp}/adapt", "extra"], "unexpected arguments"),
    # loop_power
    ("loop_power", ["--archive={file}/archive", "--cached_only"], "--archive"),
    *[("loop_power", ["--archive={tmp}/archive", f"--{flag}={value}", "--cached_only"], f"--{flag}")
      for flag, values in (("setup", ("moon",)), ("cases", ("wind", "", "clean,wind")), ("seeds", ("0", "x")),
                           ("clean_seeds", ("-1",)))
      for value in values],
    ("loop_power", ["--archive={tmp}/archive", "extra"], "unexpected arguments"),
    # demo
    *[("demo", [f"--{flag}={value}"], f"--{flag}")
      for flag, values in (("mu", ("-1", "nan", "inf")), ("angle_deg", ("90", "-120", "nan")),
                           ("point", ("1.5", "-0.1", "nan")))
      for value in values],
    ("demo", ["extra"], "unexpected arguments"),
]


def _read_only_folder(tmp_path: Path) -> Path:
    """A folder this process cannot write in: mode 555, or for root (who writes there anyway) ``/sys``."""
    if os.geteuid() == 0:
        return Path("/sys")
    folder = tmp_path / "read_only"
    folder.mkdir()
    folder.chmod(0o555)
    return folder


def _case_places(folder: Path, read_only: Path) -> dict[str, Path]:
    places = {"tmp": folder / "fresh", "file": folder / "a_file", "empty": folder / "empty", "read_only": read_only}
    places["tmp"].mkdir(parents=True)
    places["file"].write_text("not a folder")
    places["empty"].mkdir()
    return places


def test_every_bad_flag_is_a_one_line_usage_error(tmp_path):
    read_only = _read_only_folder(tmp_path)
    cases = []
    for index, (binary, arguments, _) in enumerate(CASES):
        places = _case_places(tmp_path / f"case{index}", read_only)
        cases.append((binary, [argument.format(**places) for argument in arguments]))
    (tmp_path / "cases.json").write_text(json.dumps(cases))
    out = tmp_path / "out"
    out.mkdir()
    server = subprocess.run(
        [sys.executable, "-c", SERVER, str(tmp_path / "cases.json"), str(out), str(PARALLEL), str(CASE_TIMEOUT_S)],
        cwd=REPOSITORY, env={**os.environ, "MUJOCO_GL": "egl"}, capture_output=True, text=True,
        timeout=CASE_TIMEOUT_S * len(CASES) / PARALLEL)
    assert server.returncode == 0, server.stderr[-3000:]
    exit_codes = json.loads(server.stdout.splitlines()[-1])

    failures = []
    for index, ((binary, arguments), (_, _, flag), exit_code) in enumerate(zip(cases, CASES, exit_codes)):
        stderr = (out / f"{index}.stderr").read_text()
        lines = [line for line in stderr.splitlines() if line.strip() and not LOG_LINE.match(line)]
        last = lines[-1] if lines else ""
        problems = [problem for problem, found in (
            (f"exit {exit_code}", exit_code != USAGE_ERROR_STATUS), ("traceback", "Traceback" in stderr),
            ("flag help", any(HELP_TEXT.search(line) for line in lines)), (f"{len(lines)} lines", len(lines) > 3),
            ("no 'error: ' line naming the flag", not (last.startswith("error: ") and flag in last))) if found]
        if problems:
            failures.append(f"python -m experiments.{binary} {' '.join(arguments)}: {', '.join(problems)}; "
                            f"last line {last!r}")
    assert not failures, f"{len(failures)} of {len(CASES)} cases:\n" + "\n".join(failures)
