"""Why the certificate's σ was chosen, and what the tube is where the tube is visible.

The verifier keeps, among the σ it tries, the certified one with the most slack; that is often σ = 0
(no ancillary feedback, a zero tube in e), so a run shows no tube although the paper's idea is the tube.
:func:`sigma_story` says so in a few lines: the σ chosen and why, and the one-period tube at the largest
σ tried that has one, with whether tracking is certified there and how to run it (``--sigma``).
"""

from __future__ import annotations

from dataclasses import replace

import verify
from verify.certificate import Certificate

from tubekit.scenario import Scenario

__all__ = ["sigma_story"]


def _fmt(values: tuple[float, ...]) -> str:
    return "[" + ", ".join(f"{v:.4g}" for v in values) + "]"


def _tube_line(certificate: Certificate) -> str:
    """What the chosen design promises about e − ê."""
    if not certificate.tiers.tracking:
        failed = ", ".join(certificate.tier_failures["tracking"][:3])
        return f"  tracking not certified ({failed}): no tube is promised; the safe tier runs at sigma = 0"
    why = " (no feedback: the disturbance alone)" if certificate.inputs.sigma == 0.0 else ""
    return f"  one-period tube |e - e_hat| <= {_fmt(certificate.tube.rho)} (e_d m, e_z m, e_o){why}"


def _visible(scenario: Scenario, certificate: Certificate) -> str:
    """The tube at the largest σ tried above the chosen one that has a finite tube, and what holds there."""
    for trial in sorted(certificate.tried, key=lambda t: -t.sigma):
        if trial.sigma <= certificate.inputs.sigma:
            break
        at = verify.certify(replace(scenario, controller=replace(scenario.controller, sigma=trial.sigma)),
                            certificate.law)
        if not at.tube.certified:
            continue
        verdict = (f"tracking certified there: run it with --sigma {trial.sigma:g}" if at.tiers.tracking else
                   "tracking not certified there (" + ", ".join(at.tier_failures["tracking"][:3]) + ")")
        return (f"  at sigma = {trial.sigma:g} 1/s the one-period tube would be {_fmt(at.tube.rho)} "
                f"(e_d m, e_z m, e_o); {verdict}")
    return "  no larger sigma tried gives a finite one-period tube here"


def sigma_story(scenario: Scenario, certificate: Certificate) -> list[str]:
    """Lines explaining the σ of ``certificate`` (certified for ``scenario``) and the tube at a visible σ."""
    tried = ", ".join(f"{t.sigma:g}" for t in certificate.tried)
    lines = [f"sigma = {certificate.inputs.sigma:g} 1/s ({certificate.sigma_source}; tried {tried})",
             _tube_line(certificate)]
    if len(certificate.tried) > 1:
        lines.append(_visible(scenario, certificate))
    return lines
