"""The ``tubekit`` console script: one subcommand per capability.

Each subcommand lives in its own module exposing ``configure(parser)`` and
``run(args) -> int``. Exit codes: 0 success/certified, 1 failure,
2 bad input (one message, no traceback), 3 not certified / counterexample found.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from . import __version__
from .exceptions import TubekitError

__all__ = ["main", "SUBCOMMANDS"]

# name -> (module, one-line help)
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "reproduce": ("tubekit.commands", "reproduce the paper's Section VI simulation study (the main job)"),
    "simulate": ("tubekit.commands", "simulate any scenario given as TOML"),
    "audit": ("tubekit.audit", "audit the paper's printed error dynamics against the sympy derivation"),
    "certify": ("verify.commands", "certify a scenario: bounds, sigma, tube radius, tightened sets"),
    "envelope": ("verify.commands", "design search: the certifiable envelope of a scenario"),
    "falsify": ("verify.falsify", "search for a counterexample to pointwise tube invariance"),
}


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tubekit", description="Robust tube-based NMPC for underactuated AUVs.")
    parser.add_argument("--version", action="version", version=f"tubekit {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (module_name, help_text) in SUBCOMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:  # a missing optional dependency must not break the other commands
            p.set_defaults(_unavailable=f"{module_name} cannot be imported: {exc}")
            continue
        getattr(module, f"configure_{name}")(p)
        p.set_defaults(_run=getattr(module, f"run_{name}"))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    if getattr(args, "_unavailable", None):
        print(f"tubekit {args.command}: not available: {args._unavailable}. "
              f"Try: pip install -e . (it installs every dependency of the commands).", file=sys.stderr)
        return 1
    try:
        return int(args._run(args))
    except TubekitError as exc:
        print(f"tubekit {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `tubekit certify | head`
        sys.stderr.close()
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
