"""The tiers of promise in the app's reports: which tier holds, which promise depends on what (issue 21).

A certificate gives two tiers (``verify.Certificate.tiers``): **safe** (no collision, inside the
workspace, v ∈ V never clipped, for all time; premise: the disturbance bound) and **tracking**
(e ∈ R, e_d >= ε, the tube, while a plan is followed). :func:`tier_report` joins the certificate's
verdict per tier (and the conditions that failed) with the run's promises (each carries its
``tier`` and ``depends_on``, :mod:`tubekit.loop.promises`) into the ``tiers_report`` entry of
``metrics.json``; :func:`tier_lines` and :func:`activity_line` are the text summary's lines.
"""

from __future__ import annotations

from typing import Any, Mapping

from verify.certificate.record import CertificateRecord

from tubekit.app.plots import tier_title

__all__ = ["TIER_MEANING", "tier_report", "tier_lines", "activity_line", "report_title"]

#: What each tier promises, in words.
TIER_MEANING: dict[str, str] = {
    "safe": "no collision, inside the workspace, v in V never clipped, for all time",
    "tracking": "e in R, e_d >= epsilon, the tube; while a plan is followed, not while the backup law runs",
}


def tier_report(certificate: CertificateRecord, metrics: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """Per tier: ``certified``, ``failed_conditions``, ``promises`` (names), ``depends_on`` (premises) and the run's
    ``outcome`` (kept, BROKEN, not in force: :func:`tubekit.loop.promises.tier_outcomes`; None without a run).

    Parameters
    ----------
    certificate : verify.Certificate
        Its ``tiers`` and ``tier_failures``.
    metrics : mapping
        A tube run's metrics (:func:`tubekit.loop.metrics.run_metrics`): its ``promises``.
    """
    tiers, failures = certificate.tiers.to_dict(), dict(certificate.tier_failures)
    out: dict[str, dict[str, Any]] = {}
    for name in ("safe", "tracking"):
        mine = [p for p in metrics.get("promises", []) if p.get("tier") == name]
        depends = sorted({d for p in mine for d in p.get("depends_on", [])})
        out[name] = {"certified": bool(tiers.get(name, False)), "promises": [p["name"] for p in mine],
                     "depends_on": depends, "failed_conditions": list(failures.get(name, ())),
                     "meaning": TIER_MEANING[name], "outcome": (metrics.get("outcome") or {}).get(name)}
    return out


def report_title(report: Mapping[str, Mapping[str, Any]]) -> str:
    """The one-line verdict of :func:`tier_report` (the figures' title line)."""
    return tier_title({k: v["certified"] for k, v in report.items()},
                      {k: v["failed_conditions"] for k, v in report.items()},
                      {k: v["outcome"] for k, v in report.items() if v.get("outcome")})


def tier_lines(report: Mapping[str, Mapping[str, Any]]) -> list[str]:
    """``tiers: safe: certified; tracking: ...`` then, per tier, its promises and what they depend on."""
    lines = [f"tiers: {report_title(report)}"]
    for name, tier in report.items():
        premises = ", ".join(tier["depends_on"]) or "nothing measured on the run"
        lines.append(f"  {name} ({tier['meaning']}): promises {', '.join(tier['promises']) or 'none'}; "
                     f"{'given' if tier['certified'] else 'NOT given'}; depends on {premises}")
    return lines


def activity_line(metrics: Mapping[str, Any]) -> str:
    """Replaced steps and backup time of a run: ``replaced steps 12 of 200; backup active 3.4 s (2 times, 1.7 %)``."""
    steps = int(metrics.get("steps") or 0)
    backup = float(metrics.get("backup_s") or 0.0)
    duration = float(metrics.get("duration_s") or 0.0)
    share = f", {100.0 * backup / duration:.3g} % of the run" if duration > 0 else ""
    return (f"replaced steps {int(metrics.get('replaced_steps') or 0)} of {steps}; backup active {backup:.4g} s "
            f"({int(metrics.get('backup_engagements') or 0)} times{share})")
