"""Split plans are a registry: one planner per dataset experiment; test splits grown by further draws."""

import collections
import math

import pytest

from pushjax.data import configs


def test_every_experiment_has_a_split_plan():
    assert set(configs.SPLIT_PLANS) == set(configs.EXPERIMENTS)
    plan = configs.plan_splits(configs.get_config("repeated", "smoke"), "/nonexistent/raw")
    assert list(plan.splits) == ["test"] and len(plan.jobs) == 1


@pytest.mark.parametrize("experiment, minimum", [
    ("data_efficiency", 150), ("new_pushes", 150), ("velocities", 150), ("objects", 100), ("viewpoint", 150)])
def test_grown_test_splits_keep_their_sequences_and_add_only_unseen_pushes(experiment, minimum):
    own = configs.plan_splits(configs.get_config(experiment, "cpu"), "/unused")
    config = configs.get_config(experiment, "cpu", min_test_sequences=minimum)
    grown = configs.plan_splits(config, "/unused")
    assert config.name == f"{experiment}_cpu_test{minimum}"
    own_paths = {name: {own.jobs[i].path for i in ids} for name, ids in own.splits.items()}
    assert set(grown.splits) == {name for name in own.splits if name.startswith("test")}
    seen = set().union(*own_paths.values())
    for name, ids in grown.splits.items():
        jobs = [grown.jobs[i] for i in ids]
        paths = {job.path for job in jobs}
        assert own_paths[name] <= paths and len(paths) >= minimum
        added = [job for job in jobs if job.path not in own_paths[name]]
        assert added and not {job.path for job in added} & seen
        groups = collections.Counter((job.params.shape, job.params.surface, job.params.velocity) for job in jobs)
        assert min(groups.values()) == math.ceil(minimum / len(groups)), name
        if experiment == "new_pushes":
            assert all(configs.is_new_push(job.params, config) for job in jobs)
    again = configs.plan_splits(config, "/unused")
    assert again.splits == grown.splits and [job.path for job in again.jobs] == [job.path for job in grown.jobs]


def test_grown_test_splits_name_the_pool_that_runs_out():
    with pytest.raises(ValueError, match=r"^min_test_sequences: butter on abs at 20 mm/s has \d+ pushes left for test"):
        configs.plan_splits(configs.get_config("data_efficiency", "smoke", min_test_sequences=100_000), "/unused")
    with pytest.raises(ValueError, match="^min_test_sequences: the repeated experiment tests one push"):
        configs.get_config("repeated", "smoke", min_test_sequences=10)
