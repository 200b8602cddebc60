"""Strict JSON for every output: one converter and one atomic writer.

:func:`to_jsonable` turns nested dicts, lists, tuples, sets, numpy arrays and
numpy scalars into plain Python; non-finite floats (NaN, ±inf) become ``None``,
so the text is strict JSON (``allow_nan=False``). :func:`write_json` and
:func:`write_text` write atomically: a temporary file in the target's directory,
then :func:`os.replace`, so a reader never sees a half-written file.
"""

from __future__ import annotations

import json
import math
import os
import uuid
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["json_number", "to_jsonable", "dumps", "write_text", "write_json"]


def json_number(value: Any) -> float | None:
    """``float(value)`` if finite, else ``None`` (also for ``None``)."""
    if value is None:
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def to_jsonable(obj: Any) -> Any:
    """Recursively convert ``obj`` to JSON types; non-finite floats become ``None``.

    Dict keys become strings; tuples, sets and numpy arrays become lists; numpy
    scalars become Python scalars; paths become strings.

    Raises
    ------
    TypeError
        For any other type (nothing is silently stringified).
    """
    if obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return json_number(obj)
    if isinstance(obj, dict):
        return {str(key): to_jsonable(value) for key, value in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset, np.ndarray)):
        return [to_jsonable(value) for value in obj]
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def dumps(obj: Any, *, indent: int | None = 2) -> str:
    """Strict JSON text of ``obj`` (after :func:`to_jsonable`)."""
    return json.dumps(to_jsonable(obj), indent=indent, allow_nan=False)


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (temporary file in the same directory, then ``os.replace``).

    The directory must exist. The file gets the usual permissions (0o666 minus the umask).
    """
    target = Path(path)
    temporary = target.with_name(f".{target.name}.{uuid.uuid4().hex}.tmp")
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    try:
        with os.fdopen(descriptor, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(temporary, target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return target


def write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as strict, indented JSON (plus a final newline) to ``path`` atomically."""
    return write_text(path, dumps(obj) + "\n")
