"""The typed velocity-loop result (verify.vehicle.result): strict JSON round trip, summary, readers' errors."""

from __future__ import annotations

import json
import math

import pytest

from tubekit.exceptions import ConfigError
from tubekit.jsonable import to_jsonable
from tubekit.model.vehicle_sets import BLUEROV2_HEAVY, REMUS100
from verify.vehicle.result import LoopBound
from verify.vehicle.bound import velocity_loop_bound

KW = dict(v_max=(0.4, 0.3, 0.5), tick=0.01, period=0.1, jump_tick=(0.002, 0.002, 0.002),
          jump_period=(0.02, 0.02, 0.02))


@pytest.fixture(scope="module")
def bounds():
    """A certified bound (BlueROV2 Heavy, nominal point) and an uncertified one (REMUS 100, fins)."""
    return (velocity_loop_bound(BLUEROV2_HEAVY.nominal, **KW),
            velocity_loop_bound(REMUS100, **KW, rate=(0.1, 0.1, 0.1)))


def _strict(d: dict) -> dict:
    return json.loads(json.dumps(to_jsonable(d), allow_nan=False))


def test_both_round_trip_through_strict_json(bounds):
    ok, bad = bounds
    assert ok.certified and not bad.certified
    for b in bounds:
        assert LoopBound.from_dict(_strict(b.to_dict())) == b
    assert math.isinf(bad.error[0]) and bad.authority[2] < 0


def test_the_summary_names_the_failures(bounds):
    ok, bad = bounds
    assert ok.summary_lines()[0] == "velocity loop (derived bound): certified"
    text = "\n".join(bad.summary_lines())
    assert "NOT certified" in text and "loop_saturation[N]" in text and "rudder" in text


@pytest.mark.parametrize("key, value, field", [
    ("error", [1.0, 2.0], r"certificate.velocity_loop.error"),
    ("assumed", [[1.0, 2.0, 3.0, 4.0]], r"certificate.velocity_loop.assumed"),
    ("gains", {}, r"certificate.velocity_loop.gains"),
    ("conditions", "none", r"certificate.velocity_loop.conditions"),
    ("iterations", 2.5, r"certificate.velocity_loop.iterations"),
    ("tick", "fast", r"certificate.velocity_loop.tick"),
])
def test_a_bad_block_is_refused_naming_the_key(bounds, key, value, field):
    d = _strict(bounds[0].to_dict())
    d[key] = value
    with pytest.raises(ConfigError, match=field):
        LoopBound.from_dict(d)


def test_a_missing_key_is_named():
    with pytest.raises(ConfigError, match="certificate.velocity_loop.conditions"):
        LoopBound.from_dict({})
