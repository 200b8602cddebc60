"""Tests of tubekit.model.jit: the options every compiled routine takes, and the import where no cache directory
is writable."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import pytest

from tubekit.model.jit import routine


def _ratio(a: float, b: float) -> float:
    return a / b


def test_a_routine_divides_as_ieee_does_instead_of_raising():
    compiled = routine(_ratio)
    assert compiled(1.0, 0.0) == math.inf and compiled(-1.0, 0.0) == -math.inf
    assert math.isnan(compiled(0.0, 0.0))
    with pytest.raises(ZeroDivisionError):
        _ratio(1.0, 0.0)


@pytest.mark.slow
def test_without_a_writable_cache_the_routines_compile_in_the_process():
    """numba refuses cache=True when no cache locator applies (here: only IPython's, which never does for a
    file); the compiled modules still import and compute."""
    code = ("import numpy as np; from tubekit.model import compiled_arcs as k; "
            "print(k.rollout(np.zeros(4), np.array([[0.5, 0.0, 0.0]]), 2.0)[1, 0])")
    env = dict(os.environ, NUMBA_CACHE_LOCATOR_CLASSES="IPythonCacheLocator")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "1.0"
