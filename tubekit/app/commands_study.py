"""The subcommands that run the loop: ``reproduce``, ``simulate`` (or a campaign run replayed), ``campaign``.

Each is a ``configure_*(parser)`` adding its options and a ``run_*(args) -> exit code``;
:mod:`tubekit.app.cli` registers them. Handlers import the study when they run.
"""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path
from typing import TYPE_CHECKING

from tubekit.checks import check_run_inputs
from tubekit.exceptions import ConfigError, NotAvailableError
from tubekit.scenario import Scenario, load_scenario, paper_scenario
from tubekit.validation import bounded_int, gain
from tubekit.app.commands_verify import add_law_option, checked_law, log_unit_hints
from tubekit.app.exit_codes import EXIT_FAILURE, EXIT_OK, EXIT_PROMISE_BROKEN, extra_hint
from tubekit.app.output import OutputLock, check_output_dir

if TYPE_CHECKING:  # the study (and with it verify and matplotlib) is imported when a command runs
    from tubekit.app.study import StudyResult

__all__ = ["configure_reproduce", "run_reproduce", "configure_simulate", "run_simulate", "configure_campaign",
           "run_campaign", "study_exit", "echo", "require_campaign_extra", "CAMPAIGN_MODULES", "MAX_WORKERS"]

#: Largest ``campaign --workers`` (local processes).
MAX_WORKERS = 256


def study_options(parser: argparse.ArgumentParser, default_out: str | None) -> None:
    from tubekit.app import QUICK_S as QUICK_DURATION_S

    parser.add_argument("--out", metavar="DIR", default=default_out,
                        help="output directory, locked while the run writes it" + (
                            f" (default: {default_out})" if default_out else " (default: results/<scenario name>)"))
    length = parser.add_mutually_exclusive_group()
    length.add_argument("--duration", type=float, metavar="S", default=None,
                        help="simulated time of each closed-loop run in seconds (default: the scenario's)")
    length.add_argument("--quick", action="store_true",
                        help=f"a faster, shorter run (smoke test): --duration {QUICK_DURATION_S:g}")
    add_law_option(parser)
    parser.add_argument("--sigma", type=float, metavar="S", default=None,
                        help="ancillary gain sigma (1/s) to certify and run (default: the scenario's, else the "
                             "verifier's choice)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--animate", action="store_true",
                        help="also write top_view.gif (and top_view.mp4 where ffmpeg exists)")


# ---- reproduce / simulate -------------------------------------------------------------------------------

def configure_reproduce(parser: argparse.ArgumentParser) -> None:
    study_options(parser, "results/reproduce")


def configure_simulate(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("config", metavar="CONFIG", nargs="?", default=None,
                        help="scenario TOML file (schema: docs/scenario.md); not with --from-campaign")
    study_options(parser, None)
    parser.add_argument("--from-campaign", metavar="DIR", default=None,
                        help="replay one run of a `tubekit campaign` output DIR exactly (with --run K)")
    parser.add_argument("--run", metavar="K", type=int, default=None, help="the run of --from-campaign to replay")


def _study_scenario(scenario: Scenario, args: argparse.Namespace) -> Scenario:
    """The scenario with ``--duration`` / ``--quick`` / ``--law`` applied and every pre-run check passed."""
    from tubekit.app.study import apply_overrides

    law = None if args.law is None else checked_law(args.law, scenario)
    scenario = apply_overrides(scenario, duration=args.duration, quick=args.quick, law=law)
    if getattr(args, "sigma", None) is not None:
        scenario = scenario.with_changes(**{"controller.sigma": gain("--sigma", args.sigma)})
    check_run_inputs(scenario)
    log_unit_hints(scenario)
    return scenario


def _locked_study(scenario: Scenario, out: Path, args: argparse.Namespace, **options) -> int:
    """The study into ``out`` under its lock (:class:`~tubekit.app.output.OutputLock`), checked first."""
    from tubekit.app.study import run_study

    check_output_dir(out)
    with OutputLock(out):
        result = run_study(scenario, out, progress=not args.no_progress, animate=args.animate, echo=echo, **options)
    return study_exit(result)


def run_reproduce(args: argparse.Namespace) -> int:
    """Section VI of the paper, tube against baseline, with the acceptance criteria."""
    scenario = _study_scenario(paper_scenario(), args)
    return _locked_study(scenario, Path(args.out or "results/reproduce"), args, with_acceptance=True, dynamic=True)


def run_simulate(args: argparse.Namespace) -> int:
    """The same study on a scenario from TOML; or, with ``--from-campaign DIR --run K``, a campaign run replayed."""
    from tubekit.app.study import output_dir_name

    if args.from_campaign is not None or args.run is not None:
        return _replay(args)
    if args.config is None:
        raise ConfigError("CONFIG", "a scenario TOML file (or --from-campaign DIR --run K)", None)
    scenario = _study_scenario(load_scenario(args.config), args)
    out = Path(args.out) if args.out else Path("results") / output_dir_name(scenario.name)
    return _locked_study(scenario, out, args, with_acceptance=False)


def _replay(args: argparse.Namespace) -> int:
    """``simulate --from-campaign DIR --run K``: 0 identical, 4 a certified promise broken, 1 not identical."""
    from tubekit.app.campaign import replay_into

    if args.from_campaign is None or args.run is None or args.config is not None:
        raise ConfigError("--from-campaign", "--from-campaign DIR together with --run K (and no CONFIG)",
                          args.from_campaign)
    if args.out is None:
        replay = replay_into(args.from_campaign, args.run, args.out, echo=echo)
    else:
        check_output_dir(Path(args.out))
        with OutputLock(Path(args.out)):
            replay = replay_into(args.from_campaign, args.run, args.out, echo=echo)
    return EXIT_PROMISE_BROKEN if replay.broken else EXIT_OK if replay.identical else EXIT_FAILURE


def echo(message: str) -> None:
    """A result line on stdout, flushed (the study's table, promises, ``wrote ...``)."""
    print(message, flush=True)


def study_exit(result: StudyResult) -> int:
    """4 when a certified run of the study (tube, or dynamic) broke a promise (``result.check()`` False), else 0."""
    return EXIT_OK if result.check() else EXIT_PROMISE_BROKEN


# ---- campaign -------------------------------------------------------------------------------------------

#: Modules of the ``campaign`` extra of pyproject.toml.
CAMPAIGN_MODULES = ("distributed", "pyarrow")


def _missing_campaign_modules() -> list[str]:
    """The modules of :data:`CAMPAIGN_MODULES` not installed (cheap: nothing is imported)."""
    return [m for m in CAMPAIGN_MODULES if importlib.util.find_spec(m) is None]


def configure_campaign(parser: argparse.ArgumentParser) -> None:
    """The campaign's options: always listed, whether or not the ``campaign`` extra is installed."""
    parser.add_argument("spec", metavar="SPEC", help="campaign TOML (schema: docs/campaign.md)")
    parser.add_argument("--out", metavar="DIR", required=True,
                        help="campaign directory (a rerun resumes it; locked while a campaign writes it)")
    parser.add_argument("--workers", type=int, default=2, metavar="N",
                        help=f"local worker processes, 1 to {MAX_WORKERS} (default 2)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="an existing dask scheduler, tcp://HOST:PORT")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    missing = _missing_campaign_modules()
    if missing:
        parser.epilog = f"Needs the campaign extra ({', '.join(missing)} missing): {extra_hint('campaign')}"


def require_campaign_extra() -> None:
    """Raise :class:`NotAvailableError` naming the ``campaign`` extra when dask or pyarrow is missing (exit 1)."""
    missing = _missing_campaign_modules()
    if missing:
        raise NotAvailableError(f"{' and '.join(missing)} not installed (the campaign extra). "
                                f"{extra_hint('campaign')}")


def run_campaign(args: argparse.Namespace) -> int:
    """Monte Carlo closed-loop runs on dask; 0 done, 4 when a certified run broke a promise."""
    require_campaign_extra()
    from tubekit.app.campaign import run_campaign, summary_line
    from tubekit.app.campaign_spec import load_spec

    bounded_int("--workers", args.workers, 1, MAX_WORKERS)
    spec = load_spec(args.spec)
    out = Path(args.out)
    check_output_dir(out)
    with OutputLock(out):
        summary = run_campaign(spec, args.out, workers=args.workers, scheduler=args.scheduler,
                               progress=not args.no_progress)
    echo(summary_line(summary, args.out))
    return EXIT_PROMISE_BROKEN if summary["violations_certified"] else EXIT_OK
