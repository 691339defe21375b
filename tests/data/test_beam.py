"""Building with Apache Beam (TFDS's Beam support, on Beam's real DirectRunner) gives the process pool's dataset."""

import filecmp
import json
import subprocess
import sys
from pathlib import Path

import pytest
import tensorflow_datasets as tfds
from array_record.python.array_record_module import ArrayRecordReader

pytest.importorskip("apache_beam", reason="Beam builds need apache-beam: pip install -e '.[beam]'")

from pushjax.data.builder import PushEffects, build  # noqa: E402

REPOSITORY = Path(__file__).resolve().parents[2]


def _assert_same_files(first: Path, second: Path, pattern: str) -> None:
    """The files matching ``pattern`` under ``first`` and ``second`` have the same names and bytes."""
    names = sorted(path.relative_to(first).as_posix() for path in first.rglob(pattern) if path.is_file())
    assert names and names == sorted(path.relative_to(second).as_posix() for path in second.rglob(pattern)
                                     if path.is_file())
    match, mismatch, errors = filecmp.cmpfiles(first, second, names, shallow=False)
    assert match == names, (mismatch, errors)


def _records(builder: PushEffects) -> dict[str, list[bytes]]:
    """Split name -> the split's records in storage order (shard after shard)."""
    records = {}
    for name in builder.info.splits:
        records[name] = []
        for shard in sorted(Path(builder.data_dir).glob(f"*-{name}.array_record-*")):
            reader = ArrayRecordReader(str(shard))
            records[name] += reader.read_all()
            reader.close()
    return records


def test_beam_build_has_the_process_pool_records(smoke_data, tmp_path):
    # `objects` at smoke scale: 25 sequences in 6 splits, the 4 training splits sharing sequences. The Beam build
    # reads the sequences the process pool simulated (the suite's smoke dataset, built by `build` with one
    # worker), and cuts splits into 2 shards by key (the pool writes 1).
    tfds.disable_progress_bar()
    pool_dir = smoke_data("objects")
    pool = build("objects", "smoke", data_dir=pool_dir, workers=1, progress=False)
    beam = PushEffects(config="objects_smoke", data_dir=tmp_path / "beam",
                       raw_dir=pool_dir / "push_effects_raw" / "realistic" / "seed0")
    beam.download_and_prepare(download_config=tfds.download.DownloadConfig(beam_runner="DirectRunner", num_shards=2))
    assert max(len(split.shard_lengths) for split in beam.info.splits.values()) == 2
    assert {name: split.num_examples for name, split in pool.info.splits.items()} == {
        name: split.num_examples for name, split in beam.info.splits.items()}
    assert _records(pool) == _records(beam)


def test_cli_builds_with_beam_worker_processes(tmp_path):
    # Sequences simulated, rendered and serialized in Beam's worker processes: the process pool's files.
    pool = build("repeated", "smoke", data_dir=tmp_path / "pool", workers=1, progress=False)
    result = subprocess.run(
        [sys.executable, "-m", "experiments.build_dataset", "--experiment=repeated", "--scale=smoke",
         f"--data_dir={tmp_path / 'beam'}", "--beam_runner=DirectRunner",
         "--beam_options=--direct_num_workers=2 --direct_running_mode=multi_processing"],
        capture_output=True, text=True, cwd=REPOSITORY)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "repeated_smoke: test 24 examples" in result.stdout
    beam = PushEffects(config="repeated_smoke", data_dir=tmp_path / "beam")
    assert {name: (split.shard_lengths, split.num_bytes) for name, split in pool.info.splits.items()} == {
        name: (split.shard_lengths, split.num_bytes) for name, split in beam.info.splits.items()}
    _assert_same_files(Path(pool.data_dir), Path(beam.data_dir), "*.array_record-*")
    _assert_same_files(tmp_path / "pool" / "push_effects_raw", tmp_path / "beam" / "push_effects_raw", "*.h5")


# Parses each case's flags with the binary's own flags, as `experiments.run` does; prints the one-line errors (the
# last line it wrote on stderr before exiting with status 2).
_PARSE = """
import contextlib, io, json, sys
from absl import flags
import experiments
import experiments.build_dataset
errors = []
for arguments in json.loads(sys.argv[1]):
    flags.FLAGS.unparse_flags()
    stderr = io.StringIO()
    try:
        with contextlib.redirect_stderr(stderr):
            experiments.parse_flags_or_exit(["build_dataset", *arguments])
        errors.append(None)
    except SystemExit as error:
        assert error.code == experiments.USAGE_ERROR_STATUS, error.code
        errors.append(stderr.getvalue().splitlines()[-1])  # after absl's log lines, if any
print(json.dumps(errors))
"""


def test_bad_beam_flags_are_one_line_errors(tmp_path):
    data_dir = f"--data_dir={tmp_path}"
    cases = [  # (flags, the flag the error must name, or None: accepted)
        (["--beam_runner=Bogus"], "--beam_runner"),
        (["--beam_runner="], "--beam_runner"),
        (["--beam_options=--direct_num_workers=2"], "--beam_options"),
        (["--beam_runner=DirectRunner", "--beam_options=--direct_num_workers=two"], "--beam_options"),
        (["--beam_runner=DirectRunner", "--beam_options=--direct_num_worker=2"], "--beam_options"),
        (["--beam_runner=DirectRunner", "--beam_options=--direct_num_workers='2"], "--beam_options"),
        (["--beam_runner=DirectRunner", "--workers=2"], "--workers"),
        (["--beam_runner=DirectRunner", "--beam_options=--direct_num_workers=2"], None),
        (["--beam_runner=DataflowRunner", "--beam_options=--project=p --region=r --temp_location=gs://b/t"], None),
    ]
    result = subprocess.run([sys.executable, "-c", _PARSE, json.dumps([[data_dir, *flags] for flags, _ in cases])],
                            capture_output=True, text=True, cwd=REPOSITORY)
    assert result.returncode == 0, result.stderr[-3000:]
    errors = json.loads(result.stdout.splitlines()[-1])
    for (arguments, flag), error in zip(cases, errors):
        if flag is None:
            assert error is None, (arguments, error)
        else:
            assert error is not None and "\n" not in error and error.startswith("error: ") and flag in error, \
                (arguments, error)
