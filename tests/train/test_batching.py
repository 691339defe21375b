import numpy as np
import pytest

from pushjax import train
from pushjax.data import schema
from tests.tiny_configs import TINY_SMOKE


def test_batch_order_walks_through_permuted_epochs():
    spec = train.ModelSpec("m", np.arange(100, 110), seed=3)
    batches = np.concatenate([train.batch_indices(spec, step, 4) for step in range(5)])
    assert sorted(batches[:10]) == list(range(100, 110))  # epoch 0
    assert sorted(batches[10:20]) == list(range(100, 110))  # epoch 1
    assert not np.array_equal(batches[:10], batches[10:20])
    np.testing.assert_array_equal(train.batch_indices(spec, 3, 4), batches[12:16])


def test_batch_order_depends_only_on_seed_and_subset():
    subset = np.arange(20, 40)
    batch = train.batch_indices(train.ModelSpec("a", subset, seed=7), 5, 8)
    np.testing.assert_array_equal(train.batch_indices(train.ModelSpec("b", subset, seed=7, variant="error"), 5, 8),
                                  batch)
    assert not np.array_equal(train.batch_indices(train.ModelSpec("a", subset, seed=8), 5, 8), batch)


def test_subset_specs():
    specs = train.subset_specs(50, sizes=[10, 20], seeds=[0, 1])
    assert [len(spec.train_indices) for spec in specs] == [10, 10, 20, 20]
    assert not np.array_equal(specs[0].train_indices, specs[1].train_indices)
    assert all(len(np.unique(spec.train_indices)) == len(spec.train_indices) for spec in specs)
    with pytest.raises(ValueError, match="sizes"):
        train.subset_specs(50, sizes=[51], seeds=[0])


def test_subset_specs_share_the_subset_across_variants():
    specs = train.subset_specs(50, sizes=[10], seeds=[2], variants=["error", "error_grad"])
    assert [spec.name for spec in specs] == ["size=10/seed=2/error", "size=10/seed=2/error_grad"]
    assert [spec.variant for spec in specs] == ["error", "error_grad"]
    np.testing.assert_array_equal(specs[0].train_indices, specs[1].train_indices)
    with pytest.raises(ValueError, match="seeds"):
        train.subset_specs(50, sizes=[10], seeds=[-1])


def test_model_spec_rejects_bad_subsets_and_variants():
    with pytest.raises(ValueError, match="train_indices"):
        train.ModelSpec("empty", np.array([], np.int64), seed=0)
    with pytest.raises(ValueError, match="train_indices"):
        train.ModelSpec("float", np.array([0.0, 1.0]), seed=0)
    with pytest.raises(ValueError, match="variant"):
        train.ModelSpec("bad", np.arange(3), seed=0, variant="hybrid")


def test_gather_picks_the_fields_at_the_indices():
    examples = {"motion": np.arange(30.0).reshape(10, 3), "l": np.arange(10.0)}
    batch = train.gather(examples, np.array([[4, 1], [0, 9]]), ["motion"])
    assert set(batch) == {"motion"} and batch["motion"].shape == (2, 2, 3)
    np.testing.assert_array_equal(batch["motion"][0, 0], [12.0, 13.0, 14.0])
    with pytest.raises(ValueError, match="missing fields"):
        train.gather(examples, np.array([0]), ["motion", "mu"])


def test_model_fields_are_the_image_and_the_model_inputs():
    config = TINY_SMOKE.model
    assert train.model_fields(config) == (config.image_field, *train.MODEL_INPUT_FIELDS)


class _Source:
    """A random-access source of `count` examples whose scalars are Python numbers, as TFDS returns."""

    def __init__(self, count):
        self.count = count

    def __len__(self):
        return self.count

    def __getitem__(self, index):
        return {"l": float(index), "motion": np.full(3, index, np.float64)}


def test_examples_from_source_reads_every_example_with_the_schema_dtypes():
    count = 2500  # more than one read chunk
    examples = train.examples_from_source(_Source(count), ["l", "motion"])
    assert set(examples) == {"l", "motion"}
    assert examples["motion"].shape == (count, 3)
    assert examples["l"].dtype == schema.FIELDS["l"].dtype
    assert examples["motion"].dtype == schema.FIELDS["motion"].dtype
    np.testing.assert_array_equal(examples["l"], np.arange(count))
    with pytest.raises(ValueError, match="at least one example"):
        train.examples_from_source(_Source(0), ["l"])


def test_examples_from_source_reads_the_given_indices_in_their_order():
    indices = [2400, 3, 1100, 5]
    examples = train.examples_from_source(_Source(2500), ["l", "motion"], indices)
    np.testing.assert_array_equal(examples["l"], indices)
    np.testing.assert_array_equal(examples["motion"][:, 0], indices)
    with pytest.raises(ValueError, match=r"indices: expected indices in \[0, 2500\)"):
        train.examples_from_source(_Source(2500), ["l"], [2500])


def test_examples_from_source_reads_a_smoke_split(smoke):
    examples = smoke["test"]
    assert {name: examples[name].dtype for name in train.MODEL_INPUT_FIELDS} == {
        name: schema.FIELDS[name].dtype for name in train.MODEL_INPUT_FIELDS
    }
    assert len({len(values) for values in examples.values()}) == 1
