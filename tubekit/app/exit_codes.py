"""Exit codes of the ``tubekit`` command line, and the one table mapping an error type to its code.

=====  ==========================================================================================
code   meaning
=====  ==========================================================================================
0      success / certified
1      internal error (:class:`SolverError`, any other :class:`TubekitError`) or an optional
       backend not available (:class:`NotAvailableError`, ``ImportError``; with the install hint)
2      bad input (:class:`ConfigError`, :class:`ShapeError`, a file-system error naming the file)
3      not certified (:class:`verify.certificate.NotCertifiedError`) or a counterexample found
4      a certified promise broken in a run (``simulate``, ``reproduce``, ``campaign``)
130    interrupted (``KeyboardInterrupt``)
=====  ==========================================================================================

Codes 0, 3 and 4 are also outcomes a command returns (a verdict, not an error);
:func:`handle_error` turns an exception into its code and one line on stderr.
"""

from __future__ import annotations

import sys
from typing import Callable

from tubekit.exceptions import ConfigError, NotAvailableError, ShapeError, SolverError, TubekitError

__all__ = ["EXIT_OK", "EXIT_FAILURE", "EXIT_BAD_INPUT", "EXIT_NOT_CERTIFIED", "EXIT_PROMISE_BROKEN",
           "EXIT_INTERRUPTED", "INSTALL_HINT", "error_table", "handle_error"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2
#: ``certify``: not certified; ``falsify``: counterexample found; ``NotCertifiedError``.
EXIT_NOT_CERTIFIED = 3
#: ``simulate``/``reproduce``/``campaign``: a certified scenario's run broke a promise of its certificate.
EXIT_PROMISE_BROKEN = 4
#: Interrupted (Ctrl-C); an interrupted study leaves ``--out`` as it was.
EXIT_INTERRUPTED = 130
#: What to do when an optional backend is missing.
INSTALL_HINT = "Try: pip install -e . (it installs every dependency of the commands)."

#: How an error is reported: ``message(exc) -> the text after "tubekit COMMAND: "``.
Message = Callable[[BaseException], str]


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _os_error(exc: BaseException) -> str:
    name = getattr(exc, "filename", None) or "a file"
    return f"error: {name}: {getattr(exc, 'strerror', None) or exc}"


def _not_certified_error() -> type[BaseException] | None:
    """:class:`verify.certificate.NotCertifiedError` (None where verify cannot be imported)."""
    try:
        from verify.certificate import NotCertifiedError
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
        (NotAvailableError, EXIT_FAILURE, lambda e: f"not available: {_first_line(e)}. {INSTALL_HINT}"),
        (ImportError, EXIT_FAILURE, lambda e: f"not available: {_first_line(e)}. {INSTALL_HINT}"),
        (BrokenPipeError, EXIT_OK, lambda e: ""),
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
