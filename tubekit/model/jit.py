"""How tubekit compiles a routine with numba: :func:`routine`, the one set of options every compiled module uses.

* ``cache=True``: the machine code is written beside the module (``__pycache__``) or, where that is read-only, in
  numba's user-wide cache, so a machine compiles each routine once; where no cache directory is writable at all
  numba refuses ``cache=True`` (a ``RuntimeError`` at decoration), and the routine is compiled in every process
  instead of failing the import;
* ``error_model="numpy"``: a division by zero gives IEEE inf or NaN, as numpy's, not Python's ZeroDivisionError;
* no fast-math: every floating-point operation in source order, so a routine written in the order of its numpy or
  Python reference returns that reference's very floats.

Importing this module imports numba; it is imported by the compiled modules only.
"""

from __future__ import annotations

from typing import Callable, TypeVar

import numba

__all__ = ["routine"]

F = TypeVar("F", bound=Callable)

_OPTIONS = {"nogil": True, "error_model": "numpy"}


def routine(fn: F) -> F:
    """``fn`` compiled by ``numba.njit`` with the options above (cached where a cache directory is writable)."""
    try:
        return numba.njit(cache=True, **_OPTIONS)(fn)
    except RuntimeError:  # numba: "cannot cache function ...: no locator available"
        return numba.njit(cache=False, **_OPTIONS)(fn)
