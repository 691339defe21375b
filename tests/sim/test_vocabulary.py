"""One physics, three vocabularies: the testbed's effects and profile fields translate to the pushing model's effects
through one table, ``pushjax.sim.effects.MODEL_EFFECT``, whose names all exist on both sides."""

import dataclasses
import re
from pathlib import Path

from pushjax.physics.effects import EFFECTS
from pushjax.sim.effects import MODEL_EFFECT, Effects
from pushjax.sim import testbed

ARCHITECTURE = Path(__file__).resolve().parents[2] / "ARCHITECTURE.md"


def test_every_testbed_name_is_translated():
    testbed_names = {field.name for cls in (Effects, testbed.Testbed) for field in dataclasses.fields(cls)}
    assert set(MODEL_EFFECT) == testbed_names


def test_every_translation_is_a_model_effect_or_none():
    unknown = {name: effect for name, effect in MODEL_EFFECT.items() if effect is not None and effect not in EFFECTS}
    assert not unknown, unknown


def test_architecture_shows_the_table():
    """ARCHITECTURE.md's "One physics, three places" lists every translation as a row ``| `name` | ... | `effect` |``
    (``—`` for None)."""
    section = ARCHITECTURE.read_text().split("## One physics, three places", 1)[1].split("\n## ", 1)[0]
    rows = dict(re.findall(r"^\| `(\w+)` \|[^|\n]*\| (?:`(\w+)`|—) \|", section, re.MULTILINE))
    assert rows == {name: effect or "" for name, effect in MODEL_EFFECT.items()}
