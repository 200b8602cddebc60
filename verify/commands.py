"""``tubekit certify`` and ``tubekit envelope`` (wired by :mod:`tubekit.cli`).

Exit codes of ``certify``: 0 certified, 3 not certified, 2 bad input (one
message naming the field, no traceback; raised as :class:`ConfigError` and
printed by the CLI). ``envelope`` returns 0 when the search ran.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

from tubekit.ancillary import get_law
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario, load_scenario, paper_scenario

from .certificate import DEFAULT_TIME_BUDGET_S, certify
from .envelope import envelope, plot_envelope

__all__ = ["configure_certify", "run_certify", "configure_envelope", "run_envelope", "EXIT_CERTIFIED",
           "EXIT_NOT_CERTIFIED"]

EXIT_CERTIFIED = 0
EXIT_NOT_CERTIFIED = 3


def _scenario(config: str | None) -> Scenario:
    return paper_scenario() if config is None else load_scenario(config)


def _positive(field: str, value: float) -> float:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ConfigError(field, "a finite number > 0", value)
    return float(value)


def _write_json(path: str, data: dict) -> None:
    text = json.dumps(data, indent=2, allow_nan=False)
    if path == "-":
        print(text)
        return
    p = Path(path)
    if not p.parent.exists():
        raise ConfigError("--json", "a file in an existing directory", path)
    try:
        p.write_text(text + "\n")
    except OSError as exc:
        raise ConfigError("--json", "a writable file", path, str(exc)) from None


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", nargs="?", metavar="CONFIG", default=None,
                        help="scenario TOML (default: the paper's Section VI scenario)")
    parser.add_argument("--law", default=None, metavar="NAME",
                        help="ancillary law: 'paper' or 'corrected' (default: the scenario's controller.law)")
    parser.add_argument("--json", default=None, metavar="FILE", help="write the result as JSON ('-' = stdout)")


def configure_certify(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``tubekit certify [CONFIG] [--law NAME] [--json FILE]``."""
    _common(parser)
    parser.add_argument("--time-budget", type=float, default=DEFAULT_TIME_BUDGET_S, metavar="S",
                        help=f"branch-and-bound budget per bound in seconds (default {DEFAULT_TIME_BUDGET_S:g})")
    parser.add_argument("--gap", type=float, default=0.05, metavar="FRACTION",
                        help="target relative gap sampled vs certified (default 0.05)")
    parser.add_argument("--quiet", action="store_true", help="do not print the summary")


def run_certify(args: argparse.Namespace) -> int:
    """Certify; print the summary; exit 0 certified, 3 not certified."""
    scenario = _scenario(args.config)
    law = args.law if args.law is not None else scenario.controller.law
    get_law(law)
    budget = _positive("--time-budget", args.time_budget)
    gap = _positive("--gap", args.gap)
    if gap >= 1:
        raise ConfigError("--gap", "a number in (0, 1)", gap)
    cert = certify(scenario, law, time_budget_s=budget, gap=gap)
    if not args.quiet and args.json != "-":
        print(cert.summary())
    if args.json is not None:
        _write_json(args.json, cert.to_dict())
    return EXIT_CERTIFIED if cert.certified else EXIT_NOT_CERTIFIED


def configure_envelope(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``tubekit envelope [CONFIG] [--law NAME] [--json FILE] [--plot FILE] [--quick]``."""
    _common(parser)
    parser.add_argument("--plot", default=None, metavar="FILE", help="save the envelope plot (PNG/PDF/SVG)")
    parser.add_argument("--quick", action="store_true", help="coarser grids and looser bounds (faster)")


def run_envelope(args: argparse.Namespace) -> int:
    """Search the certifiable envelope; print it; optional JSON and plot; exit 0."""
    scenario = _scenario(args.config)
    law = args.law if args.law is not None else scenario.controller.law
    get_law(law)
    if args.plot is not None and not Path(args.plot).parent.exists():
        raise ConfigError("--plot", "a file in an existing directory", args.plot)
    res = envelope(scenario, law, quick=args.quick)
    if args.json != "-":
        print(res.summary())
    if args.json is not None:
        _write_json(args.json, res.to_dict())
    if args.plot is not None:
        plot_envelope(res, args.plot)
        if args.json != "-":
            print(f"plot written to {args.plot}")
    return 0
