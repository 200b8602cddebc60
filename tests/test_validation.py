"""Input validators: an error table naming the field."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.validation import (StrChoice, as_vector, bounded_int, choice, duration_seconds, finite, interval,
                                nonnegative, nonnegative_triple, period_count, positive, positive_triple,
                                replace_fields, speed_bound, text, ticks_per_period)


@pytest.mark.parametrize("fn, value, match", [
    (finite, "abc", "x: expected a finite number"),
    (finite, float("inf"), "x: expected a finite number"),
    (finite, True, "x: expected a finite number"),
    (positive, 0.0, "x: expected a number > 0"),
    (positive, -2, "x: expected a number > 0"),
    (nonnegative, -1e-9, "x: expected a number >= 0"),
])
def test_scalar_errors(fn, value, match):
    with pytest.raises(ConfigError, match=match):
        fn("x", value)


def test_scalar_ok():
    assert finite("x", 1.5) == 1.5 and positive("x", 2) == 2.0 and nonnegative("x", 0) == 0.0
    assert finite("x", np.float32(0.5)) == 0.5 and type(finite("x", np.int64(3))) is float


@pytest.mark.parametrize("fn, value", [
    (finite, "1.5"), (positive, "100"), (finite, None), (finite, True), (positive, np.bool_(True)),
    (finite, 10 ** 400), (duration_seconds, "100"), (duration_seconds, False), (duration_seconds, 10 ** 400),
])
def test_types_are_strict(fn, value):
    """Issue 24 item 2: a string, a bool, None or an int beyond the float range is not a number."""
    with pytest.raises(ConfigError, match=r"^x: expected a (finite number|number of seconds > 0), received"):
        fn("x", value)


@pytest.mark.parametrize("value", [["1", 2, 3], np.array(["1", "2", "3"]), [1, None, 2], [10 ** 400, 0, 0]])
def test_vectors_are_strict(value):
    with pytest.raises(ConfigError, match="^v: expected"):
        as_vector("v", value, 3)


@pytest.mark.parametrize("value, exc, match", [
    ([1, 2], ShapeError, r"v: expected shape \(3,\)"),
    ([1, 2, float("nan")], ConfigError, "v: expected finite numbers"),
    ([1, True, 2], ConfigError, "v: expected 3 numbers"),
    (["a", "b", "c"], ConfigError, "v: expected 3 numbers"),
])
def test_vector_errors(value, exc, match):
    with pytest.raises(exc, match=match):
        as_vector("v", value, 3)


def test_vector_ok():
    assert np.array_equal(as_vector("v", (1, 2, 3), 3), [1.0, 2.0, 3.0])


@pytest.mark.parametrize("value, match", [
    (1.0, r"i: expected a pair \[lo, hi\]"),
    ((1, 2, 3), r"i: expected a pair \[lo, hi\]"),
    ((float("nan"), 1.0), r"i\[0\]: expected a finite number"),
    ((0.0, True), r"i\[1\]: expected a finite number"),
    ((2.0, 1.0), r"i: expected lo < hi \(a non-empty interval\)"),
    ((1.0, 1.0), r"i: expected lo < hi"),
])
def test_interval_errors(value, match):
    with pytest.raises(ConfigError, match=match):
        interval("i", value)


def test_interval_ok():
    assert interval("i", [-1, 2]) == (-1.0, 2.0)


@pytest.mark.parametrize("fn, value, match", [
    (positive_triple, 3.0, "t: expected three numbers"),
    (positive_triple, (1, 2), "t: expected three numbers"),
    (positive_triple, (1, 0, 2), "t: expected three numbers > 0"),
    (nonnegative_triple, (1, -0.1, 2), "t: expected three numbers >= 0"),
    (nonnegative_triple, (1, float("inf"), 2), r"t\[1\]: expected a finite number"),
])
def test_triple_errors(fn, value, match):
    with pytest.raises(ConfigError, match=match):
        fn("t", value)


def test_triple_ok():
    assert positive_triple("t", [1, 2, 3]) == (1.0, 2.0, 3.0)
    assert nonnegative_triple("t", np.zeros(3)) == (0.0, 0.0, 0.0)


# ---- str-valued enums, durations, dotted replacement ---------------------------------------------

class _Colour(StrChoice):
    RED = "red"
    DARK_BLUE = "dark blue"


def test_str_choice_members_behave_as_their_strings():
    import json
    assert _Colour.RED == "red" and {"red": 1}[_Colour.RED] == 1
    assert str(_Colour.DARK_BLUE) == f"{_Colour.DARK_BLUE}" == "dark blue" and f"{_Colour.RED:>5}" == "  red"
    assert json.dumps({"c": _Colour.RED}) == '{"c": "red"}'
    assert _Colour.values() == ("red", "dark blue")


def test_choice_maps_explicitly_and_lists_the_allowed_values():
    assert choice("colour", _Colour, "dark blue") is _Colour.DARK_BLUE
    assert choice("colour", _Colour, _Colour.RED) is _Colour.RED
    for bad in ("DARK_BLUE", "Red", 1, None):
        with pytest.raises(ConfigError, match=r"^colour: expected one of \('red', 'dark blue'\)"):
            choice("colour", _Colour, bad)


@pytest.mark.parametrize("value", [0, -1.0, float("nan"), float("inf"), True, "5", None])
def test_duration_seconds_errors(value):
    with pytest.raises(ConfigError, match=r"^--duration: expected a number of seconds > 0"):
        duration_seconds("--duration", value)


def test_duration_seconds_ok():
    assert duration_seconds("duration", 3) == 3.0 and isinstance(duration_seconds("duration", np.int64(2)), float)


@dataclasses.dataclass(frozen=True)
class _Inner:
    a: float = 1.0

    def __post_init__(self):
        positive("inner.a", self.a)


@dataclasses.dataclass(frozen=True)
class _Outer:
    inner: _Inner = dataclasses.field(default_factory=_Inner)
    n: int = 0


def test_replace_fields_reaches_nested_fields_and_validates_them():
    out = replace_fields(_Outer(), {"inner.a": 2.0, "n": 3})
    assert out == _Outer(_Inner(2.0), 3)
    with pytest.raises(ConfigError, match="inner.a: expected a number > 0"):
        replace_fields(_Outer(), {"inner.a": -1.0})


@pytest.mark.parametrize("changes, match", [
    ({"m": 1}, r"^m: expected a field of _Outer, one of \['inner', 'n'\]"),
    ({"inner.b": 1}, r"^inner\.b: expected a field of _Inner"),
    ({"n.x": 1}, r"^n\.x: expected no dotted part \(n is a int\)"),
    ({"inner": _Inner(), "inner.a": 2.0}, r"^inner: expected the whole field or dotted parts of it, not both"),
])
def test_replace_fields_errors_name_the_field(changes, match):
    with pytest.raises(ConfigError, match=match):
        replace_fields(_Outer(), changes)


@pytest.mark.parametrize("call, match", [
    (lambda: period_count("d", 1e308, 0.1), r"^d: expected at most 1e\+09 FHOCP periods of 0\.1 s"),
    (lambda: ticks_per_period("c.rate", 100.0, "c.dt", 1e-9), r"^c\.dt: expected at least one tick 1/rate = 0\.01 s"),
    (lambda: ticks_per_period("c.rate", 1e308, "c.dt", 10.0), r"^c\.rate: expected at most 1e\+06 ticks"),
    (lambda: ticks_per_period("c.rate", 155.0, "c.dt", 0.1), r"^c\.rate: expected a positive multiple of 1/dt"),
    (lambda: speed_bound("v", float("inf"), [1e308]), r"^v: expected a speed of magnitude <= 1e\+06 m/s"),
    (lambda: text("name", 5), r"^name: expected a string, received 5"),
    (lambda: bounded_int("n", 10 ** 12, 1, 10), r"^n: expected an integer in \[1, 10\]"),
    (lambda: bounded_int("n", True, 0, 10), r"^n: expected an integer in \[0, 10\]"),
    (lambda: bounded_int("n", 2.0, 0, 10), r"^n: expected an integer in \[0, 10\]"),
])
def test_counts_and_magnitudes_are_bounded(call, match):
    """Issue 24 item 1: a count or a product that would overflow is refused, naming the field."""
    with pytest.raises(ConfigError, match=match):
        call()


def test_counts_within_bounds_pass():
    assert ticks_per_period("r", 100.0, "dt", 0.1) == 10 and period_count("d", 100.0, 0.1) == pytest.approx(1000)
    assert bounded_int("n", 10, 1, 10) == 10 and text("name", "x") == "x"
