"""Exit codes of the ``tubekit`` command line, and the one table mapping an error type to its code.

=====  ==========================================================================================
code   meaning
=====  ==========================================================================================
0      success / certified
1      internal error (:class:`SolverError`, any other :class:`TubekitError`), an optional
       backend not available (:class:`NotAvailableError`, ``ImportError``; with the install hint),
       or the machine failing a write (:data:`ENVIRONMENT_ERRNOS`: a full disk, a quota, an I/O
       error; the line gives the path) -- the input was fine, so it is not exit 2
2      bad input (:class:`ConfigError`, :class:`ShapeError`, any other file-system error naming the file)
3      not certified (:class:`verify.certificate.certify.NotCertifiedError`) or a counterexample found
4      a certified promise broken in a run (``simulate``, ``reproduce``, ``campaign``)
130    interrupted (``KeyboardInterrupt``)
=====  ==========================================================================================

Codes 0, 3 and 4 are also outcomes a command returns (a verdict, not an error);
:func:`handle_error` turns an exception into its code and one line on stderr.
"""

from __future__ import annotations

import contextlib
import errno
import signal
import sys
import threading
from typing import Callable, Iterator

from tubekit.exceptions import ConfigError, NotAvailableError, ShapeError, SolverError, TubekitError

__all__ = ["EXIT_OK", "EXIT_FAILURE", "EXIT_BAD_INPUT", "EXIT_NOT_CERTIFIED", "EXIT_PROMISE_BROKEN",
           "EXIT_INTERRUPTED", "INSTALL_HINT", "ENVIRONMENT_ERRNOS", "is_environment_error", "MachineError",
           "children_ignore_interrupts", "interrupts_remembered", "extra_hint", "error_table", "handle_error"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2
#: ``certify``: not certified; ``falsify``: counterexample found; ``NotCertifiedError``.
EXIT_NOT_CERTIFIED = 3
#: ``simulate``/``reproduce``/``campaign``: a certified scenario's run broke a promise of its certificate.
EXIT_PROMISE_BROKEN = 4
#: Interrupted (Ctrl-C); an interrupted study leaves ``--out`` as it was.
EXIT_INTERRUPTED = 130
#: What to do when an optional backend is missing (the extras are in pyproject.toml).
INSTALL_HINT = ('Try: pip install -e ".[campaign]" (dask) or ".[bench]" (CasADi/IPOPT): the plain install '
                'leaves the optional extras out.')
#: OS errors of the machine, not of the input: a full disk, a quota, an I/O error, out of memory (exit 1).
ENVIRONMENT_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.ENOMEM})


def is_environment_error(exc: BaseException) -> bool:
    """Whether ``exc`` is an OS error of the machine (:data:`ENVIRONMENT_ERRNOS`), not of the input."""
    return isinstance(exc, OSError) and exc.errno in ENVIRONMENT_ERRNOS


class _MachineErrorType(type):
    def __instancecheck__(cls, obj: object) -> bool:
        return isinstance(obj, BaseException) and is_environment_error(obj)


class MachineError(OSError, metaclass=_MachineErrorType):
    """The table's row for OS errors of the machine: ``isinstance(e, MachineError)`` is
    :func:`is_environment_error` (never raised itself)."""


def extra_hint(extra: str) -> str:
    """The install line of one optional extra of pyproject.toml, e.g. ``pip install -e ".[campaign]"``."""
    return f'Try: pip install -e ".[{extra}]"'


#: How an error is reported: ``message(exc) -> the text after "tubekit COMMAND: "``.
Message = Callable[[BaseException], str]


@contextlib.contextmanager
def children_ignore_interrupts() -> Iterator[None]:
    """Processes started inside the block ignore SIGINT (Ctrl-C): they inherit SIG_IGN, under which Python
    and asyncio install no KeyboardInterrupt handler. The parent alone turns Ctrl-C into exit 130 and
    stops them (a dask LocalCluster's workers: no worker traceback). A Ctrl-C inside the block itself is
    dropped. Off the main thread (where signals cannot be set) the block changes nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextlib.contextmanager
def interrupts_remembered() -> Iterator[None]:
    """Ctrl-C inside the block raises KeyboardInterrupt as usual and is also remembered: should a library swallow
    that KeyboardInterrupt (a cluster closing, a wait that retries), the block raises it again when it ends, so an
    interrupted command never exits 0. Off the main thread the block changes nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    seen = threading.Event()

    def remember(signum: int, frame: object) -> None:
        seen.set()
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, remember)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if seen.is_set():
        raise KeyboardInterrupt


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _os_error(exc: BaseException) -> str:
    name = getattr(exc, "filename", None) or "a file"
    return f"error: {name}: {getattr(exc, 'strerror', None) or exc}"


def _not_available(exc: BaseException) -> str:
    text = _first_line(exc)
    return f"not available: {text}" + ("" if "pip install" in text else f". {INSTALL_HINT}")


def _environment_error(exc: BaseException) -> str:
    name = getattr(exc, "filename", None) or "(path unknown)"
    return (f"cannot write {name}: {getattr(exc, 'strerror', None) or exc} (a problem of the machine, not of the "
            "input; nothing was replaced)")



def _not_certified_error() -> type[BaseException] | None:
    """:class:`verify.certificate.certify.NotCertifiedError` (None where verify cannot be imported)."""
    try:
        from verify.certificate.certify import NotCertifiedError
    except ImportError:
        return None
    return NotCertifiedError


def error_table() -> tuple[tuple[type[BaseException], int, Message], ...]:
    """The one table: (error type, exit code, message), first match wins (most specific first)."""
    rows: list[tuple[type[BaseException], int, Message]] = [
        (KeyboardInterrupt, EXIT_INTERRUPTED,
         lambda e: "interrupted (outputs of a study are left as they were)"),
        (ConfigError, EXIT_BAD_INPUT, lambda e: f"error: {_first_line(e)}"),
        (ShapeError, EXIT_BAD_INPUT, lambda e: f"error: {_first_line(e)}"),
        (SolverError, EXIT_FAILURE, lambda e: f"solver failed: {_first_line(e)}"),
        (NotAvailableError, EXIT_FAILURE, _not_available),
        (ImportError, EXIT_FAILURE, _not_available),
        (BrokenPipeError, EXIT_OK, lambda e: ""),
        (MachineError, EXIT_FAILURE, _environment_error),
        (OSError, EXIT_BAD_INPUT, _os_error),
        (TubekitError, EXIT_FAILURE, lambda e: f"internal error: {type(e).__name__}: {_first_line(e)}"),
    ]
    not_certified = _not_certified_error()
    if not_certified is not None:
        rows.insert(1, (not_certified, EXIT_NOT_CERTIFIED, lambda e: f"not certified: {_first_line(e)}"))
    return tuple(rows)


def handle_error(command: str, exc: BaseException) -> int | None:
    """The exit code of ``exc`` with its one line on stderr; None when the table has no row for it (re-raise).

    A broken pipe (e.g. ``tubekit certify | head``) exits 0 silently.
    """
    for kind, code, message in error_table():
        if isinstance(exc, kind):
            if isinstance(exc, BrokenPipeError):
                sys.stderr.close()
                return code
            print(f"tubekit {command}: {message(exc)}", file=sys.stderr)
            return code
    return None
