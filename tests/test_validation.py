"""Input validators: an error table naming the field."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.validation import (as_vector, finite, interval, nonnegative, nonnegative_triple, positive,
                                positive_triple)


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
    assert finite("x", "1.5") == 1.5 and positive("x", 2) == 2.0 and nonnegative("x", 0) == 0.0


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
    assert interval("i", ["-1", 2]) == (-1.0, 2.0)


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
