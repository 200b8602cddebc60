"""Where results go: the one output-path and ``--json`` policy of the command line.

* a results directory (``--out DIR`` of reproduce / simulate / campaign) is checked first
  (:func:`check_output_dir`, creates nothing) and written atomically (:class:`StagedOutput`:
  a staging directory next to it, then one rename);
* a file an option may create (``--json FILE``, ``--plot FILE``) is checked first
  (:func:`check_file_target`); ``--json -`` prints strict JSON on stdout (:func:`emit_json`);
* a results directory is locked while a run writes it (:class:`OutputLock`): a second run into the
  same ``--out`` refuses with one line (exit 2);
* every file-system problem is a :class:`~tubekit.exceptions.ConfigError` naming the option
  (exit 2), never a traceback -- except an OS error of the machine (a full disk, a quota, an I/O
  error), which passes on naming the path (exit 1: the input was fine).
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
from tubekit.app.exit_codes import is_environment_error

__all__ = ["StagedOutput", "check_output_dir", "check_file_target", "check_figure_target", "figure_formats",
           "emit_json", "write_json_creating_dirs", "OutputLock"]


def _machine_error_passes(exc: OSError, path: str | Path) -> None:
    """Re-raise an OS error of the machine (a full disk: exit 1, :data:`~tubekit.app.exit_codes.ENVIRONMENT_ERRNOS`)
    naming ``path``; return for any other, which the caller reports as bad input."""
    if is_environment_error(exc):
        if not exc.filename:
            exc.filename = str(path)
        raise exc


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
            _machine_error_passes(exc, self.target)
            raise ConfigError("--out", "a directory that can be created and written", str(self.target),
                              exc.strerror or str(exc)) from None
        return self

    def __exit__(self, kind: type | None, error: BaseException | None, trace: Any) -> None:
        if kind is not None:
            shutil.rmtree(self.path, ignore_errors=True)
            if isinstance(error, OSError) and not error.filename:
                error.filename = str(self.target)  # a write without a file name (a full disk): name --out
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
            _machine_error_passes(exc, self.target)
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


def figure_formats() -> tuple[str, ...]:
    """The file suffixes matplotlib can save a figure as (``png``, ``pdf``, ``svg``, ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return tuple(sorted(FigureCanvasBase.get_supported_filetypes()))


def check_figure_target(option: str, path: str) -> None:
    """A figure file ``option`` may create: a suffix matplotlib can write, in an existing writable directory."""
    suffix = Path(path).suffix.lower().lstrip(".")
    formats = figure_formats()
    if suffix not in formats:
        raise ConfigError(option, f"a file name ending in one of {', '.join('.' + f for f in formats)}", path)
    if not Path(path).parent.exists():
        raise ConfigError(option, "a file in an existing directory", path)
    check_file_target(option, path)


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
        _machine_error_passes(exc, path)
        raise ConfigError("--json", "a writable file", path, exc.strerror or str(exc)) from None


def write_json_creating_dirs(path: str, data: Any) -> None:
    """``--json FILE`` of audit/falsify/recheck: strict JSON to FILE, creating its directory."""
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_json(path, data)
    except OSError as exc:
        _machine_error_passes(exc, path)
        raise ConfigError("--json", "a writable file", path, exc.strerror or str(exc)) from None


class OutputLock:
    """A lock on a results directory (``--out``): the file ``.<name>.lock`` beside it holding the owner's pid.

    Created atomically (a hard link of a file already holding the pid, else ``O_CREAT | O_EXCL``), so of
    two runs into one ``--out`` exactly one proceeds; the other gets a :class:`ConfigError` naming
    ``--out`` (exit 2). A lock whose pid no longer runs (a killed run) is taken over. The lock is removed
    on exit, on errors and on Ctrl-C too. Use as a context manager, after the inputs are checked.
    """

    def __init__(self, target: Path, option: str = "--out") -> None:
        self.target, self.option = Path(target), option
        self.path = self.target.parent / f".{self.target.name}.lock"
        self._held = False

    def __enter__(self) -> "OutputLock":
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
            for _ in range(2):
                if self._create():
                    self._held = True
                    return self
                owner = _lock_owner(self.path)
                if owner is not None and _running(owner):
                    raise ConfigError(self.option, "a directory no other tubekit run is writing", str(self.target),
                                      f"Another run (pid {owner}) holds {self.path}; wait for it or choose "
                                      f"another {self.option}")
                _remove_if_owner(self.path, owner)  # stale: its owner is gone
        except OSError as exc:
            _machine_error_passes(exc, self.path)
            raise ConfigError(self.option, "a directory whose lock file can be created", str(self.target),
                              exc.strerror or str(exc)) from None
        raise ConfigError(self.option, "a directory no other tubekit run is writing", str(self.target),
                          f"{self.path} is being taken by another run")

    def __exit__(self, kind: type | None, error: BaseException | None, trace: Any) -> None:
        if self._held:
            _remove_if_owner(self.path, os.getpid())
            self._held = False

    def _create(self) -> bool:
        """Create the lock holding this pid; False when it exists already."""
        fd, temp = tempfile.mkstemp(prefix=f".{self.target.name}.lock-", dir=self.path.parent)
        try:
            os.write(fd, f"{os.getpid()}\n".encode())
            os.close(fd)
            try:
                os.link(temp, self.path)
                return True
            except FileExistsError:
                return False
            except OSError:  # no hard links here: an exclusive create, then the pid
                try:
                    lock = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
                except FileExistsError:
                    return False
                os.write(lock, f"{os.getpid()}\n".encode())
                os.close(lock)
                return True
        finally:
            os.unlink(temp)


def _lock_owner(path: Path) -> int | None:
    """The pid written in a lock file; None when it is gone or holds no pid."""
    try:
        text = path.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


def _running(pid: int) -> bool:
    """Whether a process ``pid`` exists (one of another user counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _remove_if_owner(path: Path, owner: int | None) -> None:
    """Remove the lock file if it still names ``owner`` (another run may have taken it meanwhile)."""
    if _lock_owner(path) == owner:
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass
