"""The subcommands of the verifier and the paper: ``audit``, ``certify``, ``envelope``, ``recheck``, ``falsify``.

Each is a ``configure_*(parser)`` adding its options and a ``run_*(args) -> exit code``;
:mod:`tubekit.app.cli` registers them. Handlers import verify (and the plots) when they run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario, load_scenario, paper_scenario
from tubekit.validation import positive
from tubekit.app.exit_codes import EXIT_NOT_CERTIFIED, EXIT_OK
from tubekit.app.output import check_file_target, emit_json, write_json_creating_dirs

__all__ = ["configure_audit", "run_audit", "configure_certify", "run_certify", "configure_envelope", "run_envelope",
           "configure_recheck", "run_recheck", "configure_falsify", "run_falsify"]


def _verify_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", nargs="?", metavar="CONFIG", default=None,
                        help="scenario TOML (default: the paper's Section VI scenario)")
    parser.add_argument("--law", default=None, metavar="NAME",
                        help="ancillary law: 'paper' or 'corrected' (default: the scenario's controller.law)")
    parser.add_argument("--json", default=None, metavar="FILE", help="write the result as JSON ('-' = stdout)")


def _scenario(config: str | None) -> Scenario:
    return paper_scenario() if config is None else load_scenario(config)


def _law(args: argparse.Namespace, scenario: Scenario) -> str:
    """The ``--law`` option, else the scenario's; unknown names raise :class:`ConfigError`."""
    from tubekit.model.ancillary import get_law

    law = args.law if args.law is not None else scenario.controller.law
    get_law(law)
    return law


# ---- audit ----------------------------------------------------------------------------------------------

def configure_audit(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", metavar="FILE", help="write the audit as JSON to FILE")
    parser.add_argument("--samples", type=int, default=2000, help="random points per term (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help="RNG seed (default 0)")


def run_audit(args: argparse.Namespace) -> int:
    """Run the audit, print the table, optionally write JSON."""
    from tubekit.paper.audit import audit

    if args.samples < 10:
        raise ConfigError("--samples", "an integer >= 10", args.samples)
    if args.json:
        check_file_target("--json", args.json)
    report = audit(samples=args.samples, seed=args.seed)
    print(report.table())
    if args.json:
        write_json_creating_dirs(args.json, report.to_dict())
        print(f"\nwrote {args.json}")
    return EXIT_OK


# ---- certify / envelope ---------------------------------------------------------------------------------

def configure_certify(parser: argparse.ArgumentParser) -> None:
    _verify_options(parser)
    parser.add_argument("--max-boxes", type=int, default=4000, metavar="N",
                        help="branch-and-bound budget per gain entry, in boxes (a work unit: the verdict does not "
                             "depend on machine load; default 4000)")
    parser.add_argument("--search-region", action="store_true",
                        help="certify on a fixed grid of (region.e_o_max, region.e_d_max) and report every "
                             "verdict; exit 0 if any certifies (the best is printed), else 3")


def run_certify(args: argparse.Namespace) -> int:
    """Certify; print the summary; 0 certified, 3 not certified (``--search-region``: any point of the grid)."""
    from verify import certify

    scenario = _scenario(args.config)
    law = _law(args, scenario)
    if args.json not in (None, "-"):
        if not Path(args.json).parent.exists():
            raise ConfigError("--json", "a file in an existing directory", args.json)
        check_file_target("--json", args.json)
    if args.search_region:
        from verify.region_search import search_region

        found = search_region(scenario, law)
        if not args.quiet and args.json != "-":
            print(found.summary())
        if args.json is not None:
            emit_json(args.json, found.to_dict())
        return EXIT_OK if found.best is not None else EXIT_NOT_CERTIFIED
    if args.max_boxes < 1:
        raise ConfigError("--max-boxes", "an integer >= 1", args.max_boxes)
    cert = certify(scenario, law, max_boxes=args.max_boxes)
    if not args.quiet and args.json != "-":
        print(cert.summary())
    if args.json is not None:
        emit_json(args.json, cert.to_dict())
    return EXIT_OK if cert.certified else EXIT_NOT_CERTIFIED


def configure_envelope(parser: argparse.ArgumentParser) -> None:
    _verify_options(parser)
    parser.add_argument("--plot", default=None, metavar="FILE", help="save the envelope plot (PNG/PDF/SVG)")
    parser.add_argument("--quick", action="store_true", help="fewer speeds and bisection steps (faster)")
    parser.add_argument("--eps", type=float, default=None, metavar="E",
                        help="epsilon = min e_d in m for both frontiers (default: the scenario's)")


def run_envelope(args: argparse.Namespace) -> int:
    """Certified and physical-necessity frontiers at one epsilon; print the table and the ratio; JSON, plot."""
    from verify import envelope

    from tubekit.app.plots import plot_envelope

    scenario = _scenario(args.config)
    law = _law(args, scenario)
    if args.plot is not None and not Path(args.plot).parent.exists():
        raise ConfigError("--plot", "a file in an existing directory", args.plot)
    if args.plot is not None:
        check_file_target("--plot", args.plot)
    if args.json not in (None, "-"):
        check_file_target("--json", args.json)
    eps = None if args.eps is None else positive("--eps", args.eps)
    result = envelope(scenario, law, eps=eps, quick=args.quick)
    if args.json != "-":
        print(result.summary())
    if args.json is not None:
        emit_json(args.json, result.to_dict())
    if args.plot is not None:
        try:
            plot_envelope(result, args.plot)
        except OSError as exc:
            raise ConfigError("--plot", "a writable file", args.plot, exc.strerror or str(exc)) from None
        if args.json != "-":
            print(f"plot written to {args.plot}")
    return EXIT_OK


def configure_recheck(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("cert", metavar="CERT", help="a certificate JSON written by tubekit certify --json")
    parser.add_argument("--json", metavar="FILE", help="write the recheck as JSON")


def run_recheck(args: argparse.Namespace) -> int:
    """0 when the certificate is confirmed, 3 when it is not certified or the recheck disagrees."""
    from verify.recheck import recheck_file

    if args.json:
        check_file_target("--json", args.json)
    try:
        result = recheck_file(args.cert)
    except UnicodeDecodeError:
        raise ConfigError("CERT", "a UTF-8 JSON file", args.cert, "It is binary or not UTF-8.") from None
    except OSError as exc:
        raise ConfigError("CERT", "a readable JSON file", args.cert, exc.strerror or str(exc)) from None
    print(result.summary())
    if args.json:
        write_json_creating_dirs(args.json, result.to_dict())
    return EXIT_OK if result.confirmed else EXIT_NOT_CERTIFIED


# ---- falsify --------------------------------------------------------------------------------------------

def configure_falsify(parser: argparse.ArgumentParser) -> None:
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


def run_falsify(args: argparse.Namespace) -> int:
    """3 when a counterexample is found (ratio > 1 or a promise broken), 0 when none within the budget."""
    from verify.falsify.one_period import falsify, falsify_closed_loop

    scenario = _scenario(args.config)
    if args.sigma is not None:
        positive("--sigma", args.sigma)
    positive("--duration", args.duration)
    if args.json:
        check_file_target("--json", args.json)
    if args.closed_loop:
        budget = 20 if args.budget is None else args.budget
        result = falsify_closed_loop(scenario, args.law, budget=budget, seed=args.seed, duration=args.duration)
    else:
        budget = 500 if args.budget is None else args.budget
        result = falsify(scenario, args.law, budget=budget, seed=args.seed, sigma=args.sigma)
    print(result.summary())
    if args.json:
        write_json_creating_dirs(args.json, result.to_dict())
    return EXIT_NOT_CERTIFIED if result.found else EXIT_OK
