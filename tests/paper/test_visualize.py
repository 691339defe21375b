import numpy as np

from pushjax.paper import visualize
from pushjax.train import batching


def test_the_figure_shows_each_variants_model_with_the_most_training_examples():
    specs = batching.subset_specs(100, sizes=[10, 60], seeds=[0, 1], variants=["error", "error_norm"])
    for variant in ("error", "error_norm"):
        spec = specs[visualize.largest_model(specs, variant)]
        assert (spec.variant, len(spec.train_indices), spec.seed) == (variant, 60, 0)


def test_a_plain_sweep_picks_its_largest_model_for_any_variant_name():
    specs = [batching.ModelSpec(name=f"size={n}", train_indices=np.arange(n), seed=0) for n in (30, 90, 90)]
    assert visualize.largest_model(specs, "hybrid") == 1
