"""SimConfig: the /atlas/sim_config schema, written and parsed in one place."""

from __future__ import annotations

import json

import pytest

from tutorial_atlas_control.sim.sim_config import SimConfig, SimConfigError, parse_sim_config

CONFIG = SimConfig(model_file='atlas_v1.xml', model_sha1='0123456789abcdef' * 2 + '01234567',
                   timestep_s=0.001, time_to_unpin_s=1.0, last_reset_time_s=2.5)


def test_the_json_is_the_one_the_simulator_has_always_published() -> None:
    """Bags stay bit-exact: the keys, their order and the number formatting of json.dumps."""
    assert CONFIG.to_json() == (
        '{"model_file": "atlas_v1.xml", "model_sha1": "' + CONFIG.model_sha1 + '", '
        '"timestep": 0.001, "time_to_unpin": 1.0, "last_reset_time": 2.5}')


def test_json_round_trip() -> None:
    assert SimConfig.from_json(CONFIG.to_json()) == CONFIG


def test_model_file_and_checksum_may_be_missing() -> None:
    config = SimConfig.from_json('{"timestep": 0.001, "time_to_unpin": 0, "last_reset_time": 0}')
    assert config == SimConfig(None, None, 0.001, 0.0, 0.0)
    assert config.recorded


@pytest.mark.parametrize(('text', 'message'), [
    ('{"timestep": 0.001}', r"lacks a valid 'time_to_unpin' \(expected JSON with timestep, "
                            r'time_to_unpin, last_reset_time\)\.'),
    ('{"timestep": "fast", "time_to_unpin": 1, "last_reset_time": 0}',
     r"lacks a valid could not convert string to float: 'fast'"),
    ('{"timestep": null, "time_to_unpin": 1, "last_reset_time": 0}', r'lacks a valid'),
    ('not json', r'is not JSON \(Expecting value: line 1 column 1 \(char 0\)\)\.'),
    ('[1, 2]', r"is not a JSON object: '\[1, 2\]'\."),
])
def test_a_bad_config_is_refused_with_what_is_wrong(text: str, message: str) -> None:
    with pytest.raises(SimConfigError, match=message):
        SimConfig.from_json(text)


def test_parse_keeps_an_incomplete_object() -> None:
    """Replay counts resets over every config, of which only the last must be complete."""
    assert parse_sim_config('{"last_reset_time": 1.5}') == {'last_reset_time': 1.5}
    assert json.loads(CONFIG.to_json()) == CONFIG.to_dict()
