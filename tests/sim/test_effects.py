"""Tests for pushjax.sim.effects: validation, JSON round trip and the command-line syntax."""

import dataclasses
import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pushjax.sim.effects import Effects

finite = st.floats(-1.0, 1.0, allow_nan=False)
positive = st.floats(0.1, 5.0)


@settings(max_examples=50, deadline=None)
@given(com=st.tuples(finite, finite), rim=finite, anisotropy=st.tuples(positive, positive),
       tilt=st.floats(0.0, 45.0), azimuth=st.floats(-180.0, 180.0),
       pusher=st.one_of(st.none(), st.floats(0.0, 2.0)), noise=st.tuples(positive, positive),
       bias=st.tuples(finite, finite, finite))
def test_json_round_trip(com, rim, anisotropy, tilt, azimuth, pusher, noise, bias):
    effects = Effects(com_offset=com, pressure_rim=rim, friction_anisotropy=anisotropy, table_tilt_deg=tilt,
                      table_tilt_azimuth_deg=azimuth, pusher_friction=pusher, tracking_noise=noise,
                      tracking_bias=bias)
    text = effects.to_json()
    assert Effects.from_json(text) == effects
    assert json.loads(text) == effects.to_dict()


def test_defaults_are_no_effects():
    effects = Effects()
    assert effects.physical == effects
    assert Effects.parse("") == effects
    assert Effects.from_json("{}") == effects
    assert hash(effects) == hash(Effects.from_json(effects.to_json()))


def test_parse_command_line_syntax():
    effects = Effects.parse("com_offset=0.01,0.0; table_tilt_deg=1.0;pusher_friction=0.5;tracking_bias=0,0,0.1")
    assert effects == Effects(com_offset=(0.01, 0.0), table_tilt_deg=1.0, pusher_friction=0.5,
                              tracking_bias=(0.0, 0.0, 0.1))
    assert Effects.parse("pusher_friction=none").pusher_friction is None


def test_physical_drops_only_the_tracking_effects():
    effects = Effects(table_tilt_deg=2.0, tracking_noise=(1e-3, 0.01), tracking_bias=(0.01, 0.0, 0.0))
    assert effects.physical == Effects(table_tilt_deg=2.0)


@pytest.mark.parametrize("spec, message", [
    ("gravity=2", "unknown effect"),
    ("com_offset=1", "com_offset: expected 2 numbers"),
    ("table_tilt_deg=1,2", "table_tilt_deg: expected one number"),
    ("table_tilt_deg=abc", "table_tilt_deg: expected a number"),
    ("table_tilt_deg=95", "table_tilt_deg"),
    ("friction_anisotropy=1,0", "friction_anisotropy"),
    ("pusher_friction=-0.1", "pusher_friction"),
    ("tracking_noise=-1,0", "tracking_noise"),
    ("pressure_rim=nan", "pressure_rim"),
    ("com_offset", "expected 'name=value'"),
    ("pressure_rim=1;pressure_rim=2", "given twice"),
])
def test_bad_effects_name_the_problem(spec, message):
    with pytest.raises(ValueError, match=message):
        Effects.parse(spec)


def test_from_json_rejects_bad_input():
    with pytest.raises(ValueError, match="JSON"):
        Effects.from_json("not json")
    with pytest.raises(ValueError, match="unknown"):
        Effects.from_json('{"wind": 1}')
    with pytest.raises(dataclasses.FrozenInstanceError):
        Effects().pressure_rim = 1.0
