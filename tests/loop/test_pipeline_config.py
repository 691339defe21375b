"""LoopConfig rejects values outside their ranges, naming the field."""

import dataclasses

import pytest

from pushjax.loop import LoopConfig
from pushjax.loop.fit import FitConfig


@pytest.mark.parametrize("field, value", [
    ("horizon", 0.0), ("horizon", float("inf")), ("stride", -0.1), ("select_fraction", 1.0),
    ("test_fraction", 0.0), ("test_fraction", 0.8), ("pusher_friction", -0.1), ("effects", ()),
    ("effects", ("no_such_effect",)), ("min_gain", 1.0), ("min_strength", 1.5), ("alpha", 0.0), ("n_bootstrap", 0),
    ("fit", dataclasses.replace(FitConfig(), steps=0)),
])
def test_a_value_out_of_range_names_its_field(field, value):
    with pytest.raises(ValueError, match=f"^{field}: expected "):
        LoopConfig(**{field: value})


def test_the_defaults_are_valid():
    assert LoopConfig().horizon > 0
