"""The orchestrator's reports: which dataset a run reads, what its progress bars name, and its record of each sitting."""

import dataclasses
import datetime
import json
import logging
import shutil

import numpy as np

from pushjax import data
from pushjax.data.builder import RAW_DIR_NAME
from pushjax.paper import runner
from pushjax.paper import spec as spec_lib
from pushjax.train import describe_specs, subset_specs


def test_load_splits_says_which_dataset_it_reused(smoke_data, caplog):
    data_dir = smoke_data("data_efficiency")
    spec = spec_lib.make_spec(spec_lib.SETUPS["data_efficiency"], "smoke", data_dir=data_dir, build=False)
    with caplog.at_level(logging.INFO, logger="absl"):
        splits = runner.load_splits(spec, spec.dataset, progress=False)
    assert "train" in splits
    [message] = [record.getMessage() for record in caplog.records if record.getMessage().startswith("dataset push_effects")]
    assert message.startswith("dataset push_effects/data_efficiency_smoke version 3.0.0: reused from ")
    assert str(data_dir) in message


def test_load_splits_says_where_it_built_a_dataset(smoke_data, tmp_path, caplog):
    # The smallest smoke dataset (visualize's 24 test examples), its simulated push in the suite's raw cache, so that
    # the build only renders and writes the examples.
    shutil.copytree(smoke_data("repeated") / RAW_DIR_NAME, tmp_path / RAW_DIR_NAME)
    spec = spec_lib.make_spec(spec_lib.SETUPS["visualize"], "smoke", data_dir=tmp_path)
    with caplog.at_level(logging.INFO, logger="absl"):
        runner.load_splits(spec, spec.test_dataset, progress=False)
    [message] = [record.getMessage() for record in caplog.records if record.getMessage().startswith("dataset push_effects")]
    assert message.startswith("dataset push_effects/repeated_smoke version 3.0.0: built in ")
    assert str(tmp_path) in message


def test_grown_test_splits_hold_the_test_examples_and_unseen_pushes(smoke_data, tmp_path, caplog):
    # The smoke test split (11 sequences) grown to 22 from the suite's raw cache: only the 11 added pushes simulate.
    shutil.copytree(smoke_data("data_efficiency") / RAW_DIR_NAME, tmp_path / RAW_DIR_NAME)
    spec = spec_lib.make_spec(spec_lib.SETUPS["data_efficiency"], "smoke", data_dir=tmp_path, min_test_sequences=22,
                              workers=1)
    with caplog.at_level(logging.INFO, logger="absl"):
        [(name, grown)] = runner.load_splits(spec, spec.test_dataset, progress=False).items()
    assert any(record.getMessage().startswith(
        "dataset push_effects/data_efficiency_smoke/min_test_sequences=22 version 3.0.0: built in ")
        for record in caplog.records)
    own = runner.load_splits(dataclasses.replace(spec, data_dir=str(smoke_data("data_efficiency")), build=False),
                             spec.dataset, progress=False)["test"]
    own_plan, grown_plan = (data.plan_splits(config, "/unused") for config in (spec.dataset, spec.test_dataset))
    own_ids = {own_plan.jobs[i].path: i for i in own_plan.splits["test"]}
    grown_to_own = {i: own_ids.get(grown_plan.jobs[i].path) for i in grown_plan.splits["test"]}
    assert name == "test" and len(grown_to_own) == 22 and sum(i is not None for i in grown_to_own.values()) == 11
    examples = [grown[i] for i in range(len(grown))]
    assert len(examples) == 22 * spec.test_dataset.examples_per_sequence
    kept = [example for example in examples if grown_to_own[int(example["sequence_id"])] is not None]
    originals = [own[i] for i in range(len(own))]
    assert len(kept) == len(originals)
    for example, original in zip(kept, originals):  # both in the order of their sequences' paths
        assert grown_to_own[int(example["sequence_id"])] == int(original["sequence_id"])
        for field in original:
            if field != "sequence_id":
                np.testing.assert_array_equal(example[field], original[field], err_msg=field)


def test_progress_labels_name_the_variants_sizes_and_seeds():
    specs = subset_specs(100, (20, 50), (0, 3), ("error", "error_norm"))
    assert describe_specs("error", specs) == "error,error_norm: sizes 20,50 x seeds 0,3 (8 models)"
    assert describe_specs("hybrid", subset_specs(100, (20,), (1,), (None,))) == "hybrid: sizes 20 x seeds 1 (1 models)"


def test_every_sweep_of_a_run_is_numbered_in_its_label():
    spec = spec_lib.make_spec(spec_lib.SETUPS["error_variants"], "smoke")
    planned = runner.plan_sweeps(spec, ("train",))
    assert [(sweep.l_scale, sweep.variants, sweep.label) for sweep in planned] == [
        (1.0, ("hybrid",), "sweep 1/6: "),
        (1.0, ("error", "error_grad", "error_norm"), "sweep 2/6: "),
        (1.5, ("hybrid",), "sweep 3/6, l x1.5: "),
        (1.5, ("error",), "sweep 4/6, l x1.5: "),
        (3.0, ("hybrid",), "sweep 5/6, l x3: "),
        (3.0, ("error",), "sweep 6/6, l x3: "),
    ]


def test_a_stopped_sitting_keeps_its_wall_time_and_the_next_one_adds_to_it(tmp_path):
    first = datetime.datetime(2026, 1, 1, 10, 0, tzinfo=datetime.timezone.utc)
    runner._record_sitting(tmp_path, {"commit": "abc"}, first, 0.0, finished=False)
    runner._record_sitting(tmp_path, {"commit": "abc"}, first, 600.0, finished=False)  # after a sweep; then killed
    second = first + datetime.timedelta(hours=1)
    provenance = runner._record_sitting(tmp_path, {"commit": "abd"}, second, 300.0, finished=True)
    assert [(entry["commit"], entry["started"], entry["wall_s"], entry["finished"])
            for entry in provenance["invocations"]] == [("abc", "2026-01-01T10:00:00+00:00", 600.0, False),
                                                       ("abd", "2026-01-01T11:00:00+00:00", 300.0, True)]
    assert provenance["commit"] == "abd"
    assert provenance["wall_s"] == 900.0
    lines = (tmp_path / "invocations.jsonl").read_text().splitlines()
    assert [json.loads(line) for line in lines] == provenance["invocations"]
