"""Where results go: the one output-path and ``--json`` policy of the command line.

* a results directory (``--out DIR`` of reproduce / simulate / campaign) is checked first
  (:func:`check_output_dir`, creates nothing) and written atomically (:class:`StagedOutput`:
  a staging directory next to it, then one rename);
* a file an option may create (``--json FILE``, ``--plot FILE``) is checked first
  (:func:`check_file_target`); ``--json -`` prints strict JSON on stdout (:func:`emit_json`);
* every file-system problem is a :class:`~tubekit.exceptions.ConfigError` naming the option
  (exit 2), never a traceback.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
from pathlib import Path
from typing import Any

from tubekit.exceptions import ConfigError
from tubekit.jsonable import dumps, write_json

__all__ = ["StagedOutput", "check_output_dir", "check_file_target", "emit_json", "write_json_creating_dirs"]


class StagedOutput:
    """An output directory written atomically: a temporary directory next to it, then one rename.

    Use as a context manager; :attr:`path` is the staging directory to write into.
    On a clean exit it replaces ``target`` (the previous contents are removed only
    after the new ones are in place); on any exception, ``KeyboardInterrupt``
    included, the staging directory is removed and ``target`` is untouched.
    """

    def __init__(self, target: Path) -> None:
        self.target = Path(target)
        self.path = self.target

    def __enter__(self) -> "StagedOutput":
        parent = self.target.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self.path = Path(tempfile.mkdtemp(prefix=f".{self.target.name}.tmp-", dir=parent))
            umask = os.umask(0)
            os.umask(umask)
            self.path.chmod(0o777 & ~umask)
        except OSError as exc:
            raise ConfigError("--out", "a directory that can be created and written", str(self.target),
                              exc.strerror or str(exc)) from None
        return self

    def __exit__(self, kind: type | None, error: BaseException | None, trace: Any) -> None:
        if kind is not None:
            shutil.rmtree(self.path, ignore_errors=True)
            return
        self._commit()

    def _commit(self) -> None:
        """Swap the staging directory in; the old ``target`` goes only after the new one is in place."""
        old = None
        try:
            if self.target.exists():
                old = self.target.with_name(f".{self.target.name}.old-{os.getpid()}-{time.time_ns()}")
                os.replace(self.target, old)
            os.replace(self.path, self.target)
        except OSError as exc:
            if old is not None and not self.target.exists():
                os.replace(old, self.target)
            shutil.rmtree(self.path, ignore_errors=True)
            raise ConfigError("--out", "a directory that can be replaced", str(self.target),
                              exc.strerror or str(exc)) from None
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def check_output_dir(out: Path) -> None:
    """Raise ``ConfigError('--out', ...)`` unless ``out`` can become a results directory; creates nothing.

    ``out`` must be a directory or not exist; its nearest existing ancestor must be a
    writable directory (the staging directory is created next to ``out``).
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError("--out", "a directory (or a path that does not exist yet)", str(out),
                          "It names an existing file.")
    ancestor = out.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise ConfigError("--out", "a path under a directory", str(out), f"{ancestor} is a file.")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError("--out", "a path in a writable directory", str(out), f"{ancestor} is not writable.")
    if out.exists() and not os.access(out, os.W_OK | os.X_OK):
        raise ConfigError("--out", "a writable directory", str(out), "permission denied")


def check_file_target(option: str, path: str) -> None:
    """A file ``path`` that ``option`` may create: not a directory, under a writable directory."""
    target = Path(path)
    if target.is_dir():
        raise ConfigError(option, "a file path", path, "It names a directory.")
    ancestor = target.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir() or not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError(option, "a file in a writable directory", path)


def emit_json(path: str, data: Any) -> None:
    """``--json FILE`` of certify/envelope: strict JSON to FILE ('-' = stdout); the directory must exist."""
    if path == "-":
        print(dumps(data))
        return
    target = Path(path)
    if not target.parent.exists():
        raise ConfigError("--json", "a file in an existing directory", path)
    try:
        write_json(target, data)
    except OSError as exc:
        raise ConfigError("--json", "a writable file", path, exc.strerror or str(exc)) from None


def write_json_creating_dirs(path: str, data: Any) -> None:
    """``--json FILE`` of audit/falsify/recheck: strict JSON to FILE, creating its directory."""
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_json(path, data)
    except OSError as exc:
        raise ConfigError("--json", "a writable file", path, exc.strerror or str(exc)) from None
