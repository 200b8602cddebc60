"""The subcommands that run the loop: ``reproduce``, ``simulate`` (or a campaign run replayed), ``campaign``.

Each is a ``configure_*(parser)`` adding its options and a ``run_*(args) -> exit code``;
:mod:`tubekit.app.cli` registers them. Handlers import the study when they run.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from tubekit.app.exit_codes import EXIT_FAILURE, EXIT_OK, EXIT_PROMISE_BROKEN

if TYPE_CHECKING:  # the study (and with it verify and matplotlib) is imported when a command runs
    from tubekit.app.study import StudyResult

__all__ = ["configure_reproduce", "run_reproduce", "configure_simulate", "run_simulate", "configure_campaign",
           "run_campaign", "study_exit", "echo"]


def study_options(parser: argparse.ArgumentParser, default_out: str | None) -> None:
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


def run_reproduce(args: argparse.Namespace) -> int:
    """Section VI of the paper, tube against baseline, with the acceptance criteria."""
    from tubekit.app.study import apply_overrides, run_study

    scenario = apply_overrides(paper_scenario(), duration=args.duration, quick=args.quick, law=args.law)
    out = Path(args.out or "results/reproduce")
    result = run_study(scenario, out, progress=not args.no_progress, with_acceptance=True, animate=args.animate,
                       dynamic=True, echo=echo)
    return study_exit(result)


def run_simulate(args: argparse.Namespace) -> int:
    """The same study on a scenario from TOML; or, with ``--from-campaign DIR --run K``, a campaign run replayed."""
    from tubekit.app.study import apply_overrides, output_dir_name, run_study

    if args.from_campaign is not None or args.run is not None:
        from tubekit.app.campaign import replay_into

        if args.from_campaign is None or args.run is None or args.config is not None:
            raise ConfigError("--from-campaign", "--from-campaign DIR together with --run K (and no CONFIG)",
                              args.from_campaign)
        replay = replay_into(args.from_campaign, args.run, args.out, echo=echo)
        return EXIT_PROMISE_BROKEN if replay.broken else EXIT_OK if replay.identical else EXIT_FAILURE
    if args.config is None:
        raise ConfigError("CONFIG", "a scenario TOML file (or --from-campaign DIR --run K)", None)
    scenario = apply_overrides(load_scenario(args.config), duration=args.duration, quick=args.quick, law=args.law)
    out = Path(args.out) if args.out else Path("results") / output_dir_name(scenario.name)
    result = run_study(scenario, out, progress=not args.no_progress, with_acceptance=False, animate=args.animate,
                       echo=echo)
    return study_exit(result)


def echo(message: str) -> None:
    """A result line on stdout, flushed (the study's table, promises, ``wrote ...``)."""
    print(message, flush=True)


def study_exit(result: StudyResult) -> int:
    """4 when a certified run of the study (tube, or dynamic) broke a promise (``result.check()`` False), else 0."""
    return EXIT_OK if result.check() else EXIT_PROMISE_BROKEN


# ---- campaign -------------------------------------------------------------------------------------------

def configure_campaign(parser: argparse.ArgumentParser) -> None:
    from tubekit.app.campaign_spec import require_dependencies

    require_dependencies()
    parser.add_argument("spec", metavar="SPEC", help="campaign TOML (schema: docs/campaign.md)")
    parser.add_argument("--out", metavar="DIR", required=True, help="campaign directory (a rerun resumes it)")
    parser.add_argument("--workers", type=int, default=2, metavar="N", help="local worker processes (default 2)")
    parser.add_argument("--scheduler", metavar="ADDRESS", help="an existing dask scheduler, tcp://HOST:PORT")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def run_campaign(args: argparse.Namespace) -> int:
    """Monte Carlo closed-loop runs on dask; 0 done, 4 when a certified run broke a promise."""
    from tubekit.app.campaign import run_campaign, summary_line
    from tubekit.app.campaign_spec import load_spec

    summary = run_campaign(load_spec(args.spec), args.out, workers=args.workers, scheduler=args.scheduler,
                           progress=not args.no_progress)
    echo(summary_line(summary, args.out))
    return EXIT_PROMISE_BROKEN if summary["violations_certified"] else EXIT_OK
