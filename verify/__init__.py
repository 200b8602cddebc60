"""verify: certificates of the loop that runs, for tubekit scenarios.

``certify(scenario, law)`` returns a :class:`Certificate`: the sampled-data tube of one
FHOCP period under the nominal reset (:mod:`verify.sampled`), the per-arc margins of the
replayed plan, V̄, and every named condition with both sides' numbers, in Arb interval
arithmetic and with budgets in work units (the same verdict on any machine). See
``docs/verify.md``. ``recheck`` re-derives a certificate from its JSON; ``envelope`` draws
the certified frontier beside physical necessity; ``search_region`` looks for a region that
certifies.

Submodules for property-based testing: :mod:`verify.strategies` (hypothesis strategies),
:mod:`verify.invariance` (one period of the sampled-data loop from a reset state) and
:mod:`verify.falsify` (the one-period and closed-loop falsifiers behind ``tubekit falsify``).

verify imports the tubekit core only: no argparse, no matplotlib. The envelope plot is
:func:`tubekit.app.plots.plot_envelope` (it was ``verify.plot_envelope``).
"""

from __future__ import annotations

from pathlib import Path

from tubekit.scenario import Scenario, load_scenario

from .bounds import BOUND_NAMES, BoundResult, Bounds, compute_bounds
from .certificate import Certificate, Condition, NotCertifiedError, certify
from .envelope import EnvelopeResult, envelope
from .recheck import RecheckResult, recheck, recheck_file
from .region import Region
from .region_search import RegionSearchResult, search_region

__version__ = "0.1.0"

#: Directory of the scenarios shipped with verify.
SCENARIOS_DIR = Path(__file__).resolve().parent / "scenarios"


def certifiable_scenario() -> Scenario:
    """The documented scenario the corrected law certifies (``scenarios/certifiable.toml``)."""
    return load_scenario(SCENARIOS_DIR / "certifiable.toml")


__all__ = [
    "__version__",
    "certify",
    "Certificate",
    "Condition",
    "NotCertifiedError",
    "Region",
    "compute_bounds",
    "Bounds",
    "BoundResult",
    "BOUND_NAMES",
    "envelope",
    "EnvelopeResult",
    "recheck",
    "recheck_file",
    "RecheckResult",
    "search_region",
    "RegionSearchResult",
    "SCENARIOS_DIR",
    "certifiable_scenario",
]


def __getattr__(name: str):
    """Point the moved ``plot_envelope`` at its new home instead of a bare AttributeError."""
    if name == "plot_envelope":
        raise AttributeError("verify.plot_envelope moved to tubekit.app.plots.plot_envelope "
                             "(verify imports no plotting library)")
    raise AttributeError(f"module 'verify' has no attribute {name!r}")
