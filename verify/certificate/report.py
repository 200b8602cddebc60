"""The certificate as text (``tubekit certify`` prints it)."""

from __future__ import annotations

import math
from typing import Any

from tubekit.design_inputs import THEOREM_VERSION

from verify.certificate.record import CertificateRecord

__all__ = ["certificate_text", "tiers_line", "compare", "tried_lines"]


def _f(x: Any, d: int = 4) -> str:
    if x is None:
        return "n/a"
    x = float(x)
    return f"{x:.{d}g}" if math.isfinite(x) else ("inf" if x > 0 else "-inf")


def _vec(xs: Any, d: int = 4) -> str:
    return "[" + ", ".join(_f(x, d) for x in xs) + "]"


def compare(lhs: Any, rhs: Any) -> str:
    """``lhs OP rhs`` with OP the relation of the two numbers (<, = or >), shown with enough digits
    (6 to 17 significant) that two different numbers never print alike (``0.9999996 < 1``, not ``1 vs 1``)."""
    if lhs is None or rhs is None or not (math.isfinite(float(lhs)) and math.isfinite(float(rhs))):
        return f"{_f(lhs, 6)} vs {_f(rhs, 6)}"
    a, b = float(lhs), float(rhs)
    op = "<" if a < b else ">" if a > b else "="
    for digits in range(6, 18):
        left, right = _f(a, digits), _f(b, digits)
        if (left != right) == (a != b):
            break
    return f"{left} {op} {right}"


def _sigma_source(cert: CertificateRecord) -> str:
    """Why this sigma: the certificate's rule, or, when no sigma tried certified, what the shown design is."""
    if cert.certified or any(trial.certified for trial in cert.tried):
        return cert.sigma_source
    return "none tried certified: shown is the design with a finite tube, the fewest failed conditions and the " \
           "largest slack"


def tried_lines(cert: CertificateRecord) -> list[str]:
    """Every sigma tried, its verdict and its failed conditions (``tubekit certify -v``)."""
    out = [f"Designs tried ({len(cert.tried)}):"]
    for trial in cert.tried:
        verdict = "certified" if trial.certified else f"{len(trial.failed)} failed: {', '.join(trial.failed)}"
        out.append(f"  sigma = {_f(trial.sigma)} 1/s: {verdict}; slack score {_f(trial.score)}")
    return out


def _tube_lines(cert: CertificateRecord) -> list[str]:
    d = cert.design
    t = d.tube
    out = [f"sigma = {_f(d.sigma)} 1/s ({_sigma_source(cert)}); tried: "
           + ", ".join(f"{_f(x.sigma)}{'*' if x.certified else ''}" for x in cert.tried)
           + "  (* = certified)"]
    if not t.certified:
        out.append(f"One-period tube: none ({t.reason})")
        return out
    p = d.problem
    out.append(f"Sampled data: kappa held at f = {_f(1.0 / p.tick)} Hz (h = {_f(p.tick)} s), {p.ticks} ticks per "
               f"FHOCP period delta = {_f(p.period)} s, nominal input held over each period")
    out.append(f"One-period tube (box, restarts at 0 every {_f(cert.dt)} s): |rho| <= {_vec(t.rho)} "
               f"(e_d m, e_z m, e_o);  |theta - theta_hat| <= {_f(t.theta)} rad")
    out.append(f"  Cartesian: ||dp_xy|| <= {_f(t.p_xy)} m, |dz| <= {_f(t.p_z)} m, |dpsi| <= {_f(t.psi)} rad;"
               f"  |kappa| <= {_vec(t.kappa)}")
    if d.v_bar is not None:
        out.append(f"V_bar = {_vec(d.v_bar)}")
    if d.margins is not None:
        m = d.margins
        out.append(f"Per-arc margins (arc 0 .. {len(m.e_d) - 1}): e_d {_vec(m.e_d, 3)}")
        out.append(f"  e_o {_vec(m.e_o, 3)};  position {_vec(m.position, 3)} m")
    return out


def tiers_line(cert: CertificateRecord) -> str:
    """``safe: certified; tracking: not certified (keep_up[u], yaw_budget)``: each tier, the failed conditions."""
    tiers, failed = cert.tiers.to_dict(), cert.tier_failures
    return "; ".join(f"{k}: certified" if tiers[k] else f"{k}: not certified ({', '.join(failed[k])})"
                     for k in ("safe", "tracking"))


def _tier_lines(cert: CertificateRecord) -> list[str]:
    out = [f"Tiers: {tiers_line(cert)}",
           "  safe (no collision, inside the workspace, v in V never clipped, for all time; premise: the "
           "disturbance bound) depends on: " + ", ".join(c.condition for c in cert.tier_conditions["safe"]),
           "  tracking (e in R, e_d >= epsilon, the tube, while a plan is followed) depends on: every condition "
           "of the chosen design and the backup's"]
    if cert.safe_design is not None:
        m = cert.safe_design.margins
        out.append(f"Safe-only design (sigma = 0, no feedback, inputs up to V): position tube "
                   f"{_f(cert.safe_design.tube.p_xy)} m per period; position margins {_vec(m.position, 3)} m "
                   "(e-coordinate margins not required)")
    if cert.backup is not None:
        out += cert.backup.summary_lines()
        out.append(f"  hand-over: within {_f(cert.backup.handover[0])} m horizontally, "
                   f"{_f(cert.backup.handover[1])} m in depth of the anchor (the last arc's margins)")
    return out


def certificate_text(cert: CertificateRecord) -> str:
    """Human-readable certificate: verdict, region, disturbance, tube, conditions, premises, assumptions."""
    n_fail = len(cert.failures)
    status = "CERTIFIED" if cert.certified else f"NOT CERTIFIED ({n_fail} failed condition{'s' * (n_fail != 1)})"
    dist = cert.disturbance
    lines = [f"tubekit certificate: scenario '{cert.scenario_name}', law '{cert.law}': {status} -- {tiers_line(cert)}",
             "Theorem: the sampled-data loop as it runs (nominal reset every period, kappa held at the ancillary "
             "rate, plans accepted by the exact arc check and the terminal condition, the previous plan replayed "
             "otherwise, the certified backup law once the replay is exhausted).",
             "Region R (every bound holds over it):", cert.region.describe(),
             f"Disturbance: ||omega_xy|| <= {_f(dist.omega_xy)} m/s, |omega_z| <= {_f(dist.omega_z)} m/s "
             f"(sway gamma_bar = {_f(dist.gamma)} m/s from the sway model over V; declared {_f(dist.declared_sway)})"]
    lines += _tube_lines(cert)
    if getattr(cert, "velocity_loop", None) is not None:  # dynamic plant: the derived loop bound
        lines += cert.velocity_loop.summary_lines()
    lines += _tier_lines(cert)
    lines.append("Conditions:")
    for c in cert.conditions:
        tag = {True: "ok  ", False: "FAIL", None: "n/a "}[c.ok]
        lines.append(f"  [{tag}] {c.condition}: {c.inequality}: {compare(c.lhs, c.rhs)}"
                     + (f"  ({c.detail})" if c.detail and c.ok is not True else ""))
    lines.append("Premises (checked in every run; a premise failure is reported as such, never as a broken promise):")
    lines.extend(f"  - {p}" for p in cert.premises)
    lines.append("Assumptions (outside the model):")
    lines.extend(f"  - {a}" for a in cert.assumptions)
    if cert.paper_route is not None:  # a report beside the verdict (verify.lemma1.route), never the verdict
        lines.extend(cert.paper_route.summary_lines())
    lines.append(f"Design key: {cert.design_key} (theorem {THEOREM_VERSION})")
    lines.append(f"Elapsed: {cert.elapsed_s:.2f} s")
    return "\n".join(lines)
