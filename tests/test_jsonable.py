"""The strict-JSON converter and the atomic writer."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from tubekit.jsonable import dumps, json_number, to_jsonable, write_json, write_text


def test_non_finite_floats_become_null():
    data = {"a": math.nan, "b": [math.inf, -math.inf, 1.5], "c": np.float64("nan"), "d": np.array([1.0, np.inf])}
    assert to_jsonable(data) == {"a": None, "b": [None, None, 1.5], "c": None, "d": [1.0, None]}
    assert json.loads(dumps(data)) == to_jsonable(data)


def test_numpy_and_python_containers_become_plain_python():
    out = to_jsonable({1: np.int64(3), "f": np.float32(0.5), "b": np.bool_(True), "t": (1, 2), "s": {4},
                       "p": Path("x/y"), "m": np.zeros((2, 2)), "n": None, "str": "ok"})
    assert out == {"1": 3, "f": 0.5, "b": True, "t": [1, 2], "s": [4], "p": "x/y", "m": [[0.0, 0.0], [0.0, 0.0]],
                   "n": None, "str": "ok"}
    assert type(out["1"]) is int and type(out["f"]) is float and type(out["b"]) is bool


def test_json_number():
    assert json_number(None) is None and json_number(float("nan")) is None and json_number(np.int32(2)) == 2.0


def test_unknown_types_are_refused():
    with pytest.raises(TypeError, match="object"):
        to_jsonable({"x": object()})


def test_dumps_is_strict_json():
    text = dumps({"x": [math.nan]})
    assert "NaN" not in text and json.loads(text) == {"x": [None]}


def test_write_json_is_atomic_and_leaves_no_temporary(tmp_path):
    path = write_json(tmp_path / "out.json", {"v": np.arange(3), "bad": math.inf})
    assert json.loads(path.read_text()) == {"v": [0, 1, 2], "bad": None}
    assert path.read_text().endswith("\n")
    assert sorted(os.listdir(tmp_path)) == ["out.json"]


def test_write_text_replaces_and_cleans_up_on_failure(tmp_path):
    target = tmp_path / "t.txt"
    write_text(target, "first")
    write_text(target, "second")
    assert target.read_text() == "second"
    with pytest.raises(FileNotFoundError):
        write_text(tmp_path / "missing" / "t.txt", "x")
    with pytest.raises(TypeError):
        write_text(target, 3)  # type: ignore[arg-type]
    assert target.read_text() == "second" and sorted(os.listdir(tmp_path)) == ["t.txt"]
