"""Edits of a certificate's JSON dict for the tamper tables of the tests: a deep copy with one key removed or set."""

from __future__ import annotations

import json

__all__ = ["without", "with_value"]


def _copy_to_parent(d: dict, path: tuple[str, ...]) -> tuple[dict, dict]:
    """(a deep copy of ``d``, the node in it that holds ``path[-1]``)."""
    out = json.loads(json.dumps(d))
    node = out
    for key in path[:-1]:
        node = node[key]
    return out, node


def without(d: dict, *path: str) -> dict:
    """A deep copy of ``d`` without the key at ``path``."""
    out, node = _copy_to_parent(d, path)
    del node[path[-1]]
    return out


def with_value(d: dict, value, *path: str) -> dict:
    """A deep copy of ``d`` with ``value`` at ``path``."""
    out, node = _copy_to_parent(d, path)
    node[path[-1]] = value
    return out
