"""Split plans are a registry: one planner per dataset experiment."""

from pushjax.data import configs


def test_every_experiment_has_a_split_plan():
    assert set(configs.SPLIT_PLANS) == set(configs.EXPERIMENTS)
    plan = configs.plan_splits(configs.get_config("repeated", "smoke"), "/nonexistent/raw")
    assert list(plan.splits) == ["test"] and len(plan.jobs) == 1
