"""The subcommands of the verifier and the paper: ``audit``, ``certify``, ``envelope``, ``recheck``, ``falsify``.

Each is a ``configure_*(parser)`` adding its options and a ``run_*(args) -> exit code``;
:mod:`tubekit.app.cli` registers them. Handlers import verify (and the plots) when they run.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from tubekit.checks import check_log_size, check_run_inputs, require_one_period, unit_hints
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario, load_scenario, paper_scenario
from tubekit.validation import bounded_int, duration_seconds, gain, positive
from tubekit.app.exit_codes import EXIT_NOT_CERTIFIED, EXIT_OK
from tubekit.app.output import check_figure_target, check_file_target, emit_json, write_json_creating_dirs

if TYPE_CHECKING:  # the progress bar's type only; tqdm is imported where a command runs
    from tqdm import tqdm

LOGGER = logging.getLogger(__name__)

__all__ = ["configure_audit", "run_audit", "configure_certify", "run_certify", "configure_envelope", "run_envelope",
           "configure_recheck", "run_recheck", "configure_falsify", "run_falsify", "add_law_option", "checked_law",
           "load_checked", "MAX_SAMPLES", "MAX_SEED", "MAX_BOXES", "MAX_BUDGET", "FALSIFY_DURATION_S"]

#: Largest ``audit --samples`` (points per term).
MAX_SAMPLES = 10 ** 6
#: Largest ``--seed`` (the seeds are 32-bit).
MAX_SEED = 2 ** 32 - 1
#: Largest ``certify --max-boxes`` (boxes per gain entry).
MAX_BOXES = 10 ** 7
#: Largest ``falsify --budget`` (starts or simulations).
MAX_BUDGET = 10 ** 6
#: ``falsify --closed-loop``: simulated time of each run when ``--duration`` is not given (s).
FALSIFY_DURATION_S = 3.0


def add_law_option(parser: argparse.ArgumentParser) -> None:
    """``--law NAME``: the one definition of every subcommand that takes it."""
    parser.add_argument("--law", default=None, metavar="NAME",
                        help="ancillary law, a registered name (built in: 'paper', 'corrected'; "
                             "default: the scenario's controller.law)")


def checked_law(law: str | None, scenario: Scenario) -> str:
    """The ``--law`` option, else the scenario's; an unknown name is a :class:`ConfigError` naming ``--law``."""
    from tubekit.model.ancillary import LAWS

    name = law if law is not None else scenario.controller.law
    if name not in LAWS:
        raise ConfigError("--law" if law is not None else "controller.law", f"one of {tuple(LAWS)}", name)
    return name


def load_checked(config: str | None, duration: float | None = None) -> Scenario:
    """The scenario of CONFIG (default: the paper's) after every pre-run check of
    :func:`tubekit.checks.check_run_inputs`, the same for every command; unit hints logged."""
    scenario = paper_scenario() if config is None else load_scenario(config)
    check_run_inputs(scenario, duration)
    log_unit_hints(scenario)
    return scenario


def log_unit_hints(scenario: Scenario) -> None:
    """Log each :func:`tubekit.checks.unit_hints` of ``scenario`` as one warning line on stderr."""
    for hint in unit_hints(scenario):
        LOGGER.warning("hint: %s", hint)


def _verify_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", nargs="?", metavar="CONFIG", default=None,
                        help="scenario TOML (default: the paper's Section VI scenario)")
    add_law_option(parser)
    parser.add_argument("--json", default=None, metavar="FILE", help="write the result as JSON ('-' = stdout)")


def _json_target(path: str | None) -> None:
    """``--json FILE`` (or ``-``): a file in an existing, writable directory."""
    if path in (None, "-"):
        return
    if not Path(path).parent.exists():
        raise ConfigError("--json", "a file in an existing directory", path)
    check_file_target("--json", path)


# ---- audit ----------------------------------------------------------------------------------------------

def configure_audit(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", metavar="FILE", help="write the audit as JSON to FILE")
    parser.add_argument("--samples", type=int, default=2000,
                        help=f"random points per term, 10 to {MAX_SAMPLES} (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help=f"RNG seed, 0 to {MAX_SEED} (default 0)")


def run_audit(args: argparse.Namespace) -> int:
    """Run the audit, print the table, optionally write JSON."""
    from tubekit.paper.audit import audit

    bounded_int("--samples", args.samples, 10, MAX_SAMPLES)
    bounded_int("--seed", args.seed, 0, MAX_SEED)
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
                             f"depend on machine load; 1 to {MAX_BOXES}, default 4000)")
    parser.add_argument("--search-region", action="store_true",
                        help="certify on a fixed grid of (region.e_o_max, region.e_d_max) and report every "
                             "verdict; exit 0 if any certifies (the best is printed), else 3")


def run_certify(args: argparse.Namespace) -> int:
    """Certify; print the summary; 0 certified, 3 not certified (``--search-region``: any point of the grid).

    The summary is the short certificate (the verdict, each failed condition with the field and value that would
    make it hold, the tube, the backup, the design key); ``-v`` prints the full one (every number, condition,
    premise and assumption) and every sigma tried with its failed conditions; ``-q`` prints no summary.
    """
    from verify import certify
    from verify.certificate.report import tried_lines

    scenario = load_checked(args.config)
    law = checked_law(args.law, scenario)
    _json_target(args.json)
    bounded_int("--max-boxes", args.max_boxes, 1, MAX_BOXES)
    show = not args.quiet and args.json != "-"
    if args.search_region:
        from verify.studies.region_search import search_region

        found = search_region(scenario, law)
        if show:
            print(found.summary())
        if args.json is not None:
            emit_json(args.json, found.to_dict())
        return EXIT_OK if found.best is not None else EXIT_NOT_CERTIFIED
    cert = certify(scenario, law, max_boxes=args.max_boxes)
    if show:
        print(cert.summary(verbose=args.verbose))
        if args.verbose:
            print("\n".join(tried_lines(cert)))
    if args.json is not None:
        emit_json(args.json, cert.to_dict())
    return EXIT_OK if cert.certified else EXIT_NOT_CERTIFIED


def configure_envelope(parser: argparse.ArgumentParser) -> None:
    _verify_options(parser)
    parser.add_argument("--plot", default=None, metavar="FILE",
                        help="save the envelope plot; the suffix picks the format (.png, .pdf, .svg, ...)")
    parser.add_argument("--quick", action="store_true",
                        help="a faster, coarser run (smoke test): fewer speeds and bisection steps")
    parser.add_argument("--eps", type=float, default=None, metavar="E",
                        help="epsilon = min e_d in m for both frontiers (default: the scenario's)")


def _advance(bar: tqdm, done: int, total: int) -> None:
    """Move the envelope's progress bar to ``done`` of ``total`` speeds."""
    bar.total = total
    bar.update(done - bar.n)


def run_envelope(args: argparse.Namespace) -> int:
    """Certified and physical-necessity frontiers at one epsilon; print the table and the ratio; JSON, plot."""
    from verify import envelope

    from tubekit.app.plots import plot_envelope

    scenario = load_checked(args.config)
    law = checked_law(args.law, scenario)
    if args.plot is not None:
        check_figure_target("--plot", args.plot)
    _json_target(args.json)
    eps = None if args.eps is None else positive("--eps", args.eps)
    if eps is not None and eps >= scenario.region.e_d_max:
        raise ConfigError("--eps", f"a number < region.e_d_max = {scenario.region.e_d_max:g} m", args.eps)
    from tqdm.auto import tqdm

    # each speed is a bisection of certificates (minutes on a dynamic plant): a bar on a terminal only
    with tqdm(desc="envelope", unit="speed", leave=False, disable=not sys.stderr.isatty()) as bar:
        result = envelope(scenario, law, eps=eps, quick=args.quick, on_speed=lambda done, total: _advance(
            bar, done, total))
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
    from verify.studies.recheck import recheck_file

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
    add_law_option(parser)
    parser.add_argument("--budget", type=int, default=None, metavar="N",
                        help=f"one-period starts searched by hypothesis (default 500), or with --closed-loop "
                             f"simulations (default 20); at most {MAX_BUDGET}")
    parser.add_argument("--seed", type=int, default=0, help=f"search seed, 0 to {MAX_SEED} (default 0)")
    parser.add_argument("--sigma", type=float, help="override the ancillary gain sigma (1/s; one-period search)")
    parser.add_argument("--closed-loop", action="store_true",
                        help="attack whole runs of the loop with disturbance sequences (greedy + evolution)")
    parser.add_argument("--duration", type=float, default=None, metavar="S",
                        help=f"simulated time of each closed-loop run in seconds (with --closed-loop; "
                             f"default {FALSIFY_DURATION_S:g})")
    parser.add_argument("--json", metavar="FILE", help="write the result as JSON")


def _falsify_inputs(args: argparse.Namespace) -> tuple[Scenario, int, float]:
    """The checked scenario, budget and closed-loop duration (s) of ``falsify``; every error names its option."""
    if args.duration is not None and not args.closed_loop:
        raise ConfigError("--duration", "--duration only with --closed-loop (it is each run's length)",
                          args.duration)
    if args.sigma is not None and args.closed_loop:
        raise ConfigError("--sigma", "--sigma only with the one-period search (not with --closed-loop)",
                          args.sigma)
    duration = FALSIFY_DURATION_S if args.duration is None else duration_seconds("--duration", args.duration)
    scenario = load_checked(args.config)
    if args.closed_loop:
        require_one_period("--duration", duration, scenario.controller.dt)
        check_log_size(scenario, duration)
    checked_law(args.law, scenario)
    if args.sigma is not None:
        gain("--sigma", args.sigma)
    budget = (20 if args.closed_loop else 500) if args.budget is None else args.budget
    bounded_int("--budget", budget, 1, MAX_BUDGET)
    bounded_int("--seed", args.seed, 0, MAX_SEED)
    if args.json:
        check_file_target("--json", args.json)
    return scenario, budget, duration


def run_falsify(args: argparse.Namespace) -> int:
    """3 when a counterexample is found or the scenario is not certified, 0 when a certified scenario resists.

    On a scenario that is not certified the search attacks the best-effort tube (no promise); the
    output says so in its last line, and the exit code is 3 whatever the search found.
    """
    from verify.falsify.one_period import falsify, falsify_closed_loop

    scenario, budget, duration = _falsify_inputs(args)
    if args.closed_loop:
        result = falsify_closed_loop(scenario, args.law, budget=budget, seed=args.seed, duration=duration)
        certified = bool(result.certified)
    else:
        result = falsify(scenario, args.law, budget=budget, seed=args.seed, sigma=args.sigma)
        certified = bool(result.space.certified)
    print(result.summary())
    if not certified:
        print("NOT CERTIFIED: the scenario is not certified, so this search tested its best-effort tube, which "
              "promises nothing (exit 3 whatever it found; `tubekit certify -v` lists what fails)")
    if args.json:
        write_json_creating_dirs(args.json, result.to_dict())
    return EXIT_NOT_CERTIFIED if result.found or not certified else EXIT_OK
