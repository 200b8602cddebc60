"""Input validators: an error table naming the field."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.exceptions import ConfigError, ShapeError
from tubekit.validation import as_vector, finite, nonnegative, positive


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
