"""The ``tubekit`` console script: one parser, one subcommand per capability.

Every subcommand is a :class:`Subcommand` in :data:`SUBCOMMANDS`: its help line,
the function adding its options and the function running it (in
:mod:`tubekit.app.commands_study` and :mod:`tubekit.app.commands_verify`). Handlers
import what they need (the study, verify, the plots) when they run, so a missing
optional dependency disables only the commands that use it. Output paths and
``--json`` follow one policy (:mod:`tubekit.app.output`).

Exit codes (:mod:`tubekit.app.exit_codes`, one table by error type): 0 success / certified,
1 internal error or an optional backend not available (with the install hint), 2 bad input
(one message, no traceback), 3 not certified / counterexample found, 4 a certified promise
broken in a run (simulate, reproduce, campaign), 130 interrupted (Ctrl-C).

Every command takes ``-v`` (debug diagnostics; ``certify -v`` also prints the full certificate instead of
the short one, and every sigma tried with its failed conditions) and ``-q`` (warnings and errors only;
``certify -q`` prints no summary either): diagnostics go through :mod:`logging` to stderr; results are
printed on stdout. Every file-system error (an unreadable or binary CONFIG, an ``--out`` naming a file or an unwritable
place, an ``--out`` another run holds) is one line naming the option, exit 2; a full disk is the
machine's fault, not the input's: one line with the path, exit 1.

One meaning per option across subcommands: ``--law NAME`` is a registered ancillary law (built in:
paper, corrected), checked the same way everywhere; ``--duration S`` is the simulated time of each
closed-loop run in seconds (reproduce, simulate; falsify with ``--closed-loop``); ``--quick`` is a
faster, coarser smoke test (reproduce, simulate: ``--duration`` = :data:`tubekit.app.QUICK_S`;
envelope: fewer speeds and bisection steps). ``falsify`` exits 0 only when a certified scenario
resists the search: 3 when a counterexample is found or when the scenario is not certified (its
best-effort tube promises nothing; the output says so).
"""

from __future__ import annotations

import argparse
import logging
import sys
from dataclasses import dataclass
from typing import Callable

from tubekit import __version__
from tubekit.app import commands_study as study_cmd
from tubekit.app import commands_verify as verify_cmd
from tubekit.app.exit_codes import (EXIT_BAD_INPUT, EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_NOT_CERTIFIED, EXIT_OK,
                                    EXIT_PROMISE_BROKEN, INSTALL_HINT, handle_error)

__all__ = ["main", "build_parser", "Subcommand", "SUBCOMMANDS", "EXIT_OK", "EXIT_FAILURE", "EXIT_BAD_INPUT",
           "EXIT_NOT_CERTIFIED", "EXIT_PROMISE_BROKEN", "EXIT_INTERRUPTED", "configure_logging"]


@dataclass(frozen=True)
class Subcommand:
    """One subcommand: a one-line help, ``configure(parser)`` adding its options, ``run(args) -> exit code``."""

    help: str
    configure: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


SUBCOMMANDS: dict[str, Subcommand] = {
    "reproduce": Subcommand("reproduce the paper's Section VI simulation study (the main job)",
                            study_cmd.configure_reproduce, study_cmd.run_reproduce),
    "simulate": Subcommand("simulate any scenario given as TOML", study_cmd.configure_simulate,
                           study_cmd.run_simulate),
    "audit": Subcommand("audit the paper's printed error dynamics against the sympy derivation",
                        verify_cmd.configure_audit, verify_cmd.run_audit),
    "certify": Subcommand("certify the loop that runs: sampled-data tube, sigma, tightened sets, named conditions",
                          verify_cmd.configure_certify, verify_cmd.run_certify),
    "envelope": Subcommand("the certified frontier beside physical necessity", verify_cmd.configure_envelope,
                           verify_cmd.run_envelope),
    "recheck": Subcommand("re-check a certificate JSON: checksum, design key, each number re-derived",
                          verify_cmd.configure_recheck, verify_cmd.run_recheck),
    "falsify": Subcommand("search for a run or period that breaks the certified tube", verify_cmd.configure_falsify,
                          verify_cmd.run_falsify),
    "campaign": Subcommand("many closed-loop runs on dask: Monte Carlo and falsification, resumable",
                           study_cmd.configure_campaign, study_cmd.run_campaign),
}


#: ``-v`` / ``-q`` help where a subcommand does more than the logging level.
VERBOSITY_HELP: dict[str, tuple[str, str]] = {
    "certify": ("the full certificate (every number, condition, premise and assumption) and every sigma tried with "
                "its failed conditions on stdout, debug diagnostics on stderr",
                "warnings and errors only on stderr, and no summary on stdout"),
}


def _verbosity_options(command: str) -> argparse.ArgumentParser:
    """``-v`` / ``-q`` of one subcommand (a parent parser), with that subcommand's help."""
    verbose, quiet = VERBOSITY_HELP.get(command, ("debug diagnostics on stderr",
                                                  "warnings and errors only on stderr (results still on stdout)"))
    parent = argparse.ArgumentParser(add_help=False)
    group = parent.add_mutually_exclusive_group()
    group.add_argument("-v", "--verbose", action="store_true", help=verbose)
    group.add_argument("-q", "--quiet", action="store_true", help=quiet)
    return parent


def configure_logging(verbose: bool = False, quiet: bool = False) -> None:
    """Send the ``tubekit`` and ``verify`` loggers to the current stderr, one plain line per record.

    Level: DEBUG with ``verbose``, WARNING with ``quiet``, else INFO.
    """
    level = logging.DEBUG if verbose else logging.WARNING if quiet else logging.INFO
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(message)s"))
    for name in ("tubekit", "verify"):
        logger = logging.getLogger(name)
        for old in list(logger.handlers):
            if getattr(old, "_tubekit_cli", False):
                logger.removeHandler(old)
        handler._tubekit_cli = True  # type: ignore[attr-defined]
        logger.addHandler(handler)
        logger.setLevel(level)


def build_parser() -> argparse.ArgumentParser:
    """The ``tubekit`` parser with every subcommand of :data:`SUBCOMMANDS`.

    A subcommand whose options cannot be built (a missing dependency) is kept,
    marked unavailable, so the others still work.
    """
    parser = argparse.ArgumentParser(prog="tubekit", description="Robust tube-based NMPC for underactuated AUVs.")
    parser.add_argument("--version", action="version", version=f"tubekit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, command in SUBCOMMANDS.items():
        subparser = sub.add_parser(name, help=command.help, description=command.help,
                                   parents=[_verbosity_options(name)])
        try:
            command.configure(subparser)
        except ImportError as exc:
            subparser.set_defaults(_unavailable=str(exc))
            continue
        subparser.set_defaults(_run=command.run)
    return parser


def _not_available(command: str, reason: str) -> int:
    print(f"tubekit {command}: not available: {reason}. {INSTALL_HINT}", file=sys.stderr)
    return EXIT_FAILURE


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code (errors by type: :func:`tubekit.app.exit_codes.error_table`)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return EXIT_BAD_INPUT
    if getattr(args, "_unavailable", None):
        return _not_available(args.command, args._unavailable)
    configure_logging(getattr(args, "verbose", False), getattr(args, "quiet", False))
    try:
        return int(args._run(args))
    except (Exception, KeyboardInterrupt) as exc:  # noqa: BLE001 - the table decides; no row: re-raised
        code = handle_error(args.command, exc)
        if code is None:
            raise
        return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
