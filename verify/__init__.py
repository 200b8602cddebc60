"""verify: certified bounds, tube radius and tightened sets for tubekit scenarios.

``certify(scenario, law)`` returns a :class:`Certificate` (Lemma 1, Section V
tightened sets, terminal set, horizon condition, obstacle separation), every
number rigorous (Arb interval arithmetic), every failure named;
``envelope(scenario, law)`` searches the certifiable design envelope.
See ``docs/verify.md``.

Submodules for property-based testing: :mod:`verify.strategies` (hypothesis
strategies), :mod:`verify.invariance` (rho^T rho_dot at a configuration) and
:mod:`verify.falsify` (the falsifier behind ``tubekit falsify``).

verify imports the tubekit core only: no argparse, no matplotlib. The envelope plot
is :func:`tubekit.app.plots.plot_envelope` (it was ``verify.plot_envelope``).
"""

from __future__ import annotations

from pathlib import Path

from tubekit.scenario import Scenario, load_scenario

from .bounds import BOUND_NAMES, BoundResult, Bounds, compute_bounds
from .certificate import Certificate, Condition, NotCertifiedError, certify
from .envelope import EnvelopeResult, envelope
from .region import Region

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
    "SCENARIOS_DIR",
    "certifiable_scenario",
]


def __getattr__(name: str):
    """Point the moved ``plot_envelope`` at its new home instead of a bare AttributeError."""
    if name == "plot_envelope":
        raise AttributeError("verify.plot_envelope moved to tubekit.app.plots.plot_envelope "
                             "(verify imports no plotting library)")
    raise AttributeError(f"module 'verify' has no attribute {name!r}")
