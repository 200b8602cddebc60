"""The ``tubekit`` console script: one parser, one subcommand per capability.

Every subcommand is a :class:`Subcommand` in :data:`SUBCOMMANDS`: its help line,
the function adding its options and the function running it. Handlers import
what they need (the study, verify, the plots) when they run, so a missing
optional dependency disables only the commands that use it.

Exit codes: 0 success / certified, 1 failure (a command not available),
2 bad input (one message, no traceback), 3 not certified / counterexample found,
4 a certified promise broken in a run (simulate, reproduce), 130 interrupted (Ctrl-C).

Every command takes ``-v`` (debug diagnostics) and ``-q`` (warnings and errors
only): diagnostics go through :mod:`logging` to stderr; results are printed on
stdout. Every file-system error (an unreadable or binary CONFIG, an ``--out``
naming a file or an unwritable place) is one line naming the option, exit 2.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from tubekit import __version__
from tubekit.exceptions import ConfigError, TubekitError
from tubekit.jsonable import dumps, write_json
from tubekit.scenario import Scenario, load_scenario, paper_scenario
from tubekit.validation import positive

__all__ = ["main", "build_parser", "Subcommand", "SUBCOMMANDS", "EXIT_OK", "EXIT_FAILURE", "EXIT_BAD_INPUT",
           "EXIT_NOT_CERTIFIED", "EXIT_PROMISE_BROKEN", "EXIT_INTERRUPTED", "configure_logging"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_BAD_INPUT = 2
#: ``certify``: not certified; ``falsify``: counterexample found.
EXIT_NOT_CERTIFIED = 3
#: ``simulate``/``reproduce``: a certified scenario's run broke a promise of its certificate.
EXIT_PROMISE_BROKEN = 4
#: Interrupted (Ctrl-C); an interrupted study leaves ``--out`` as it was.
EXIT_INTERRUPTED = 130


@dataclass(frozen=True)
class Subcommand:
    """One subcommand: a one-line help, ``configure(parser)`` adding its options, ``run(args) -> exit code``."""

    help: str
    configure: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


# ---- shared option groups and helpers -------------------------------------------------------------------

def _study_options(parser: argparse.ArgumentParser, default_out: str | None) -> None:
    from tubekit.app import QUICK_S as QUICK_DURATION_S

    parser.add_argument("--out", metavar="DIR", default=default_out,
                        help="output directory" + (f" (default: {default_out})" if default_out else
                                                   " (default: results/<scenario name>)"))
    length = parser.add_mutually_exclusive_group()
    length.add_argument("--duration", type=float, metavar="S", default=None,
                        help="simulated time in seconds (default: the scenario's)")
    length.add_argument("--quick", action="store_true",
                        help=f"shorthand for --duration {QUICK_DURATION_S:g} (smoke test)")
    parser.add_argument("--law", choices=("paper", "corrected"), default=None,
                        help="ancillary law (default: the scenario's controller.law)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--animate", action="store_true",
                        help="also write top_view.gif (and top_view.mp4 where ffmpeg exists)")


def _verify_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", nargs="?", metavar="CONFIG", default=None,
                        help="scenario TOML (default: the paper's Section VI scenario)")
    parser.add_argument("--law", default=None, metavar="NAME",
                        help="ancillary law: 'paper' or 'corrected' (default: the scenario's controller.law)")
    parser.add_argument("--json", default=None, metavar="FILE", help="write the result as JSON ('-' = stdout)")


def _scenario(config: str | None) -> Scenario:
    return paper_scenario() if config is None else load_scenario(config)


def _check_file_target(option: str, path: str) -> None:
    """A file ``path`` that ``option`` may create: not a directory, under a writable directory."""
    target = Path(path)
    if target.is_dir():
        raise ConfigError(option, "a file path", path, "It names a directory.")
    ancestor = target.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir() or not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError(option, "a file in a writable directory", path)


def _law(args: argparse.Namespace, scenario: Scenario) -> str:
    """The ``--law`` option, else the scenario's; unknown names raise :class:`ConfigError`."""
    from tubekit.model.ancillary import get_law

    law = args.law if args.law is not None else scenario.controller.law
    get_law(law)
    return law


def _emit_json(path: str, data: Any) -> None:
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


def _write_json_creating_dirs(path: str, data: Any) -> None:
    """``--json FILE`` of audit/falsify/recheck: strict JSON to FILE, creating its directory."""
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_json(path, data)
    except OSError as exc:
        raise ConfigError("--json", "a writable file", path, exc.strerror or str(exc)) from None


# ---- reproduce / simulate -------------------------------------------------------------------------------

def _configure_reproduce(parser: argparse.ArgumentParser) -> None:
    _study_options(parser, "results/reproduce")


def _configure_simulate(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", metavar="CONFIG", nargs="?", default=None,
                        help="scenario TOML file (schema: docs/scenario.md); not with --from-campaign")
    _study_options(parser, None)
    parser.add_argument("--from-campaign", metavar="DIR", default=None,
                        help="replay one run of a `tubekit campaign` output DIR exactly (with --run K)")
    parser.add_argument("--run", metavar="K", type=int, default=None, help="the run of --from-campaign to replay")


def _run_reproduce(args: argparse.Namespace) -> int:
    """Section VI of the paper, tube against baseline, with the acceptance criteria."""
    from tubekit.app.study import apply_overrides, run_study

    scenario = apply_overrides(paper_scenario(), duration=args.duration, quick=args.quick, law=args.law)
    out = Path(args.out or "results/reproduce")
    metrics = run_study(scenario, out, progress=not args.no_progress, with_acceptance=True, animate=args.animate,
                        dynamic=True, echo=_echo)
    return _study_exit(metrics)


def _run_simulate(args: argparse.Namespace) -> int:
    """The same study on a scenario from TOML; or, with ``--from-campaign DIR --run K``, a campaign run replayed."""
    from tubekit.app.study import apply_overrides, output_dir_name, run_study

    if args.from_campaign is not None or args.run is not None:
        from tubekit.app.campaign import replay_into

        if args.from_campaign is None or args.run is None or args.config is not None:
            raise ConfigError("--from-campaign", "--from-campaign DIR together with --run K (and no CONFIG)",
                              args.from_campaign)
        replay = replay_into(args.from_campaign, args.run, args.out, echo=_echo)
        return EXIT_PROMISE_BROKEN if replay["broken"] else EXIT_OK if replay["identical"] else EXIT_FAILURE
    if args.config is None:
        raise ConfigError("CONFIG", "a scenario TOML file (or --from-campaign DIR --run K)", None)
    scenario = apply_overrides(load_scenario(args.config), duration=args.duration, quick=args.quick, law=args.law)
    out = Path(args.out) if args.out else Path("results") / output_dir_name(scenario.name)
    metrics = run_study(scenario, out, progress=not args.no_progress, with_acceptance=False, animate=args.animate,
                        echo=_echo)
    return _study_exit(metrics)


def _echo(message: str) -> None:
    """A result line on stdout, flushed (the study's table, promises, ``wrote ...``)."""
    print(message, flush=True)


def _study_exit(metrics: dict) -> int:
    """4 when a certified scenario's tube run broke a promise, else 0."""
    broken = metrics["certified"] and not metrics["promises_kept"]
    dyn = metrics.get("dynamic")
    broken = broken or bool(dyn and dyn["certified"] and not dyn["promises_kept"])
    return EXIT_PROMISE_BROKEN if broken else EXIT_OK


# ---- audit ----------------------------------------------------------------------------------------------

def _configure_audit(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", metavar="FILE", help="write the audit as JSON to FILE")
    parser.add_argument("--samples", type=int, default=2000, help="random points per term (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help="RNG seed (default 0)")


def _run_audit(args: argparse.Namespace) -> int:
    """Run the audit, print the table, optionally write JSON."""
    from tubekit.paper.audit import audit

    if args.samples < 10:
        raise ConfigError("--samples", "an integer >= 10", args.samples)
    if args.json:
        _check_file_target("--json", args.json)
    report = audit(samples=args.samples, seed=args.seed)
    print(report.table())
    if args.json:
        _write_json_creating_dirs(args.json, report.to_dict())
        print(f"\nwrote {args.json}")
    return EXIT_OK


# ---- certify / envelope ---------------------------------------------------------------------------------

def _configure_certify(parser: argparse.ArgumentParser) -> None:
    _verify_options(parser)
    parser.add_argument("--max-boxes", type=int, default=4000, metavar="N",
                        help="branch-and-bound budget per gain entry, in boxes (a work unit: the verdict does not "
                             "depend on machine load; default 4000)")
    parser.add_argument("--search-region", action="store_true",
                        help="certify on a fixed grid of (region.e_o_max, region.e_d_max) and report every "
                             "verdict; exit 0 if any certifies (the best is printed), else 3")


def _run_certify(args: argparse.Namespace) -> int:
    """Certify; print the summary; 0 certified, 3 not certified (``--search-region``: any point of the grid)."""
    from verify import certify

    scenario = _scenario(args.config)
    law = _law(args, scenario)
    if args.json not in (None, "-"):
        if not Path(args.json).parent.exists():
            raise ConfigError("--json", "a file in an existing directory", args.json)
        _check_file_target("--json", args.json)
    if args.search_region:
        from verify.region_search import search_region

        found = search_region(scenario, law)
        if not args.quiet and args.json != "-":
            print(found.summary())
        if args.json is not None:
            _emit_json(args.json, found.to_dict())
        return EXIT_OK if found.best is not None else EXIT_NOT_CERTIFIED
    if args.max_boxes < 1:
        raise ConfigError("--max-boxes", "an integer >= 1", args.max_boxes)
    cert = certify(scenario, law, max_boxes=args.max_boxes)
    if not args.quiet and args.json != "-":
        print(cert.summary())
    if args.json is not None:
        _emit_json(args.json, cert.to_dict())
    return EXIT_OK if cert.certified else EXIT_NOT_CERTIFIED


def _configure_envelope(parser: argparse.ArgumentParser) -> None:
    _verify_options(parser)
    parser.add_argument("--plot", default=None, metavar="FILE", help="save the envelope plot (PNG/PDF/SVG)")
    parser.add_argument("--quick", action="store_true", help="fewer speeds and bisection steps (faster)")
    parser.add_argument("--eps", type=float, default=None, metavar="E",
                        help="epsilon = min e_d in m for both frontiers (default: the scenario's)")


def _run_envelope(args: argparse.Namespace) -> int:
    """Certified and physical-necessity frontiers at one epsilon; print the table and the ratio; JSON, plot."""
    from verify import envelope

    from tubekit.app.plots import plot_envelope

    scenario = _scenario(args.config)
    law = _law(args, scenario)
    if args.plot is not None and not Path(args.plot).parent.exists():
        raise ConfigError("--plot", "a file in an existing directory", args.plot)
    if args.plot is not None:
        _check_file_target("--plot", args.plot)
    if args.json not in (None, "-"):
        _check_file_target("--json", args.json)
    eps = None if args.eps is None else positive("--eps", args.eps)
    result = envelope(scenario, law, eps=eps, quick=args.quick)
    if args.json != "-":
        print(result.summary())
    if args.json is not None:
        _emit_json(args.json, result.to_dict())
    if args.plot is not None:
        try:
            plot_envelope(result, args.plot)
        except OSError as exc:
            raise ConfigError("--plot", "a writable file", args.plot, exc.strerror or str(exc)) from None
        if args.json != "-":
            print(f"plot written to {args.plot}")
    return EXIT_OK


def _configure_recheck(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("cert", metavar="CERT", help="a certificate JSON written by tubekit certify --json")
    parser.add_argument("--json", metavar="FILE", help="write the recheck as JSON")


def _run_recheck(args: argparse.Namespace) -> int:
    """0 when the certificate is confirmed, 3 when it is not certified or the recheck disagrees."""
    from verify.recheck import recheck_file

    if args.json:
        _check_file_target("--json", args.json)
    try:
        result = recheck_file(args.cert)
    except UnicodeDecodeError:
        raise ConfigError("CERT", "a UTF-8 JSON file", args.cert, "It is binary or not UTF-8.") from None
    except OSError as exc:
        raise ConfigError("CERT", "a readable JSON file", args.cert, exc.strerror or str(exc)) from None
    print(result.summary())
    if args.json:
        _write_json_creating_dirs(args.json, result.to_dict())
    return EXIT_OK if result.confirmed else EXIT_NOT_CERTIFIED


# ---- falsify --------------------------------------------------------------------------------------------

def _configure_falsify(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", nargs="?", metavar="CONFIG",
                        help="scenario TOML (default: the paper's Section VI scenario)")
    parser.add_argument("--law", choices=("paper", "corrected"), help="ancillary law (default: the scenario's)")
    parser.add_argument("--budget", type=int, default=None,
                        help="one-period starts searched by hypothesis (default 500), or with --closed-loop "
                             "simulations (default 20)")
    parser.add_argument("--seed", type=int, default=0, help="search seed (default 0)")
    parser.add_argument("--sigma", type=float, help="override the ancillary gain sigma (1/s; one-period search)")
    parser.add_argument("--closed-loop", action="store_true",
                        help="attack whole runs of the loop with disturbance sequences (greedy + evolution)")
    parser.add_argument("--duration", type=float, default=3.0, help="seconds per closed-loop run (default 3)")
    parser.add_argument("--json", metavar="FILE", help="write the result as JSON")


def _run_falsify(args: argparse.Namespace) -> int:
    """3 when a counterexample is found (ratio > 1 or a promise broken), 0 when none within the budget."""
    from verify.falsify.one_period import falsify, falsify_closed_loop

    scenario = _scenario(args.config)
    if args.sigma is not None:
        positive("--sigma", args.sigma)
    positive("--duration", args.duration)
    if args.json:
        _check_file_target("--json", args.json)
    if args.closed_loop:
        budget = 20 if args.budget is None else args.budget
        result = falsify_closed_loop(scenario, args.law, budget=budget, seed=args.seed, duration=args.duration)
    else:
        budget = 500 if args.budget is None else args.budget
        result = falsify(scenario, args.law, budget=budget, seed=args.seed, sigma=args.sigma)
    print(result.summary())
    if args.json:
        _write_json_creating_dirs(args.json, result.to_dict())
    return EXIT_NOT_CERTIFIED if result.found else EXIT_OK


# ---- campaign -------------------------------------------------------------------------------------------

def _configure_campaign(parser: argparse.ArgumentParser) -> None:
    from tubekit.app.campaign_spec import require_dependencies

    require_dependencies()
    parser.add_argument("spec", metavar="SPEC", help="campaign TOML (schema: docs/campaign.md)")
    parser.add_argument("--out", metavar="DIR", required=True, help="campaign directory (a rerun resumes it)")
    parser.add_argument("--workers", type=int, default=2, metavar="N", help="local worker processes (default 2)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="an existing dask scheduler, tcp://HOST:PORT")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def _run_campaign(args: argparse.Namespace) -> int:
    """Monte Carlo closed-loop runs on dask; 0 done, 4 when a certified run broke a promise."""
    from tubekit.app.campaign import run_campaign, summary_line
    from tubekit.app.campaign_spec import load_spec

    summary = run_campaign(load_spec(args.spec), args.out, workers=args.workers, scheduler=args.scheduler,
                           progress=not args.no_progress)
    _echo(summary_line(summary, args.out))
    return EXIT_PROMISE_BROKEN if summary["violations_certified"] else EXIT_OK


# ---- the parser and the entry point ---------------------------------------------------------------------

SUBCOMMANDS: dict[str, Subcommand] = {
    "reproduce": Subcommand("reproduce the paper's Section VI simulation study (the main job)",
                            _configure_reproduce, _run_reproduce),
    "simulate": Subcommand("simulate any scenario given as TOML", _configure_simulate, _run_simulate),
    "audit": Subcommand("audit the paper's printed error dynamics against the sympy derivation",
                        _configure_audit, _run_audit),
    "certify": Subcommand("certify the loop that runs: sampled-data tube, sigma, tightened sets, named conditions",
                          _configure_certify, _run_certify),
    "envelope": Subcommand("the certified frontier beside physical necessity", _configure_envelope,
                           _run_envelope),
    "recheck": Subcommand("re-check a certificate JSON: every condition from its stored numbers, no search",
                          _configure_recheck, _run_recheck),
    "falsify": Subcommand("search for a run or period that breaks the certified tube", _configure_falsify,
                          _run_falsify),
    "campaign": Subcommand("many closed-loop runs on dask: Monte Carlo and falsification, resumable",
                           _configure_campaign, _run_campaign),
}


def _verbosity_options() -> argparse.ArgumentParser:
    """``-v`` / ``-q``, shared by every subcommand (a parent parser)."""
    parent = argparse.ArgumentParser(add_help=False)
    group = parent.add_mutually_exclusive_group()
    group.add_argument("-v", "--verbose", action="store_true", help="debug diagnostics on stderr")
    group.add_argument("-q", "--quiet", action="store_true",
                       help="warnings and errors only on stderr (certify: no summary either)")
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
    verbosity = _verbosity_options()
    for name, command in SUBCOMMANDS.items():
        subparser = sub.add_parser(name, help=command.help, description=command.help, parents=[verbosity])
        try:
            command.configure(subparser)
        except ImportError as exc:
            subparser.set_defaults(_unavailable=str(exc))
            continue
        subparser.set_defaults(_run=command.run)
    return parser


def _not_available(command: str, reason: str) -> int:
    print(f"tubekit {command}: not available: {reason}. "
          f"Try: pip install -e . (it installs every dependency of the commands).", file=sys.stderr)
    return EXIT_FAILURE


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code."""
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
    except ImportError as exc:  # a dependency of this command only
        return _not_available(args.command, str(exc))
    except TubekitError as exc:
        print(f"tubekit {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:  # e.g. `tubekit certify | head`
        sys.stderr.close()
        return EXIT_OK
    except OSError as exc:  # any other file-system error: one line naming the file
        print(f"tubekit {args.command}: error: {exc.filename or 'a file'}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print(f"tubekit {args.command}: interrupted (outputs of a study are left as they were)", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
