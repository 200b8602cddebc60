"""verify: certificates of the loop that runs, for tubekit scenarios.

``certify(scenario, law)`` returns a :class:`Certificate`: the sampled-data tube of one
FHOCP period under the nominal reset (:mod:`verify.theorem.sampled`), the per-arc margins of the
replayed plan, V̄, and every named condition with both sides' numbers, in Arb interval
arithmetic and with budgets in work units (the same verdict on any machine). See
``docs/verify.md``. ``recheck`` re-derives a certificate from its JSON; ``envelope`` draws
the certified frontier beside physical necessity; ``search_region`` looks for a region that
certifies.

Role subpackages: :mod:`verify.lemma1` (the paper's Lemma-1 quantities, a reference) and
:mod:`verify.falsify` (hypothesis strategies, one period from a reset state, the one-period and
closed-loop falsifiers behind ``tubekit falsify``).

verify imports the tubekit core only (only :mod:`verify.falsify` runs the loop): no argparse, no
matplotlib. ``import verify`` loads no sympy either: the names below are imported on first use. The envelope plot is
:func:`tubekit.app.plots.plot_envelope` (it was ``verify.plot_envelope``).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

from tubekit.scenario import Scenario, load_scenario
from tubekit.version import __version__

#: Directory of the scenarios shipped with verify.
SCENARIOS_DIR = Path(__file__).resolve().parent / "scenarios"

#: Public name -> the module that defines it, imported on first access (PEP 562).
_LAZY: dict[str, str] = {
    "certify": "verify.certificate.certify", "Certificate": "verify.certificate.certify", "Condition": "verify.certificate.certify",
    "NotCertifiedError": "verify.certificate.certify",
    "Region": "verify.kernel.region",
    "compute_bounds": "verify.lemma1.bounds", "Bounds": "verify.lemma1.bounds",
    "BoundResult": "verify.lemma1.bounds", "BOUND_NAMES": "verify.lemma1.bounds",
    "envelope": "verify.studies.envelope", "EnvelopeResult": "verify.studies.envelope",
    "recheck": "verify.studies.recheck", "recheck_file": "verify.studies.recheck", "RecheckResult": "verify.studies.recheck",
    "search_region": "verify.studies.region_search", "RegionSearchResult": "verify.studies.region_search",
}


def certifiable_scenario() -> Scenario:
    """The documented scenario the corrected law certifies (``scenarios/certifiable.toml``)."""
    return load_scenario(SCENARIOS_DIR / "certifiable.toml")


__all__ = ["__version__", *_LAZY, "SCENARIOS_DIR", "certifiable_scenario"]


def __getattr__(name: str) -> Any:
    """Import a public name's module on first use; point the moved ``plot_envelope`` at its new home."""
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name == "plot_envelope":
        raise AttributeError("verify.plot_envelope moved to tubekit.app.plots.plot_envelope "
                             "(verify imports no plotting library)")
    raise AttributeError(f"module 'verify' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
