"""verify.kernel.parts: the typed σ choice and Ē, and the strict readers every ``from_dict`` uses."""

from __future__ import annotations

import math

import pytest

from tubekit.exceptions import ConfigError
from verify.kernel.parts import EBar, SigmaChoice, SigmaTrial, bound, matrix, number, numbers, texts


def test_sigma_choice_round_trip():
    s = SigmaChoice(value=3.125, source="why", tried=(SigmaTrial(0.0, True, 0.25, ()),
                                                     SigmaTrial(3.125, False, None, ("tube", "sensing"))))
    d = s.to_dict()
    assert d["tried"][1] == {"sigma": 3.125, "certified": False, "score": None, "failed": ["tube", "sensing"]}
    assert SigmaChoice.from_dict(d) == s


def test_e_bar_round_trip_and_lost_bounds():
    e = EBar(e_d=(0.6, 2.9), e_z=(-0.9, 0.9), e_o=(-0.4, 0.4))
    assert EBar.from_dict(e.to_dict()) == e
    lost = EBar.from_dict({"e_d": [None, None], "e_z": [0.0, 1.0], "e_o": [-0.1, 0.1]})
    assert lost.e_d == (math.inf, -math.inf)      # an empty side, never a larger set


def test_a_null_bound_reads_as_no_finite_bound():
    assert bound({"x": None}, "x", "w") == math.inf
    assert numbers({"x": [1, None]}, "x", "w") == (1.0, math.inf)


READ_ERRORS = [
    (lambda: number({"x": "1"}, "x", "block"), "block.x: expected a number"),
    (lambda: number({"x": None}, "x", "block"), "block.x: expected a number"),
    (lambda: number({}, "x", "block"), "block.x: expected present"),
    (lambda: number([], "x", "block"), "block: expected a JSON object"),
    (lambda: number({"x": True}, "x", "block"), "block.x: expected a number"),
    (lambda: numbers({"x": [1, 2]}, "x", "block", 3), "block.x: expected a list of 3 numbers"),
    (lambda: numbers({"x": [1, None]}, "x", "block", none=None), r"block.x\[1\]: expected a number"),
    (lambda: matrix({"m": [[1, 2, 3], [1, 2, 3]]}, "m", "block"), "block.m: expected 3 rows"),
    (lambda: texts({"t": ["a", 1]}, "t", "block"), "block.t: expected a list of strings"),
    (lambda: SigmaChoice.from_dict({"value": 1.0, "source": "s", "tried": {}}), "certificate.sigma.tried"),
    (lambda: SigmaTrial.from_dict({"sigma": 1.0, "certified": 1, "score": None, "failed": []}, "w"),
     "w.certified: expected true or false"),
]


@pytest.mark.parametrize("read, match", READ_ERRORS)
def test_readers_name_the_key(read, match):
    with pytest.raises(ConfigError, match=match):
        read()
