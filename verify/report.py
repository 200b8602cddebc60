"""The certificate as text (``tubekit certify`` prints it)."""

from __future__ import annotations

import math
from typing import Any

__all__ = ["certificate_text", "tiers_line"]


def _f(x: Any, d: int = 4) -> str:
    if x is None:
        return "n/a"
    x = float(x)
    return f"{x:.{d}g}" if math.isfinite(x) else ("inf" if x > 0 else "-inf")


def _vec(xs: Any, d: int = 4) -> str:
    return "[" + ", ".join(_f(x, d) for x in xs) + "]"


def _tube_lines(cert) -> list[str]:
    d = cert.design
    t = d.tube
    out = [f"sigma = {_f(d.sigma)} 1/s ({cert.sigma_source}); tried: "
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


def tiers_line(cert) -> str:
    """``safe: certified; tracking: not certified (keep_up[u], yaw_budget)``: each tier, the failed conditions."""
    tiers, failed = cert.tiers, cert.tier_failures
    return "; ".join(f"{k}: certified" if tiers[k] else f"{k}: not certified ({', '.join(failed[k])})"
                     for k in ("safe", "tracking"))


def _tier_lines(cert) -> list[str]:
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


def certificate_text(cert) -> str:
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
    lines += _tier_lines(cert)
    lines.append("Conditions:")
    for c in cert.conditions:
        tag = {True: "ok  ", False: "FAIL", None: "n/a "}[c.ok]
        lines.append(f"  [{tag}] {c.condition}: {c.inequality}: {_f(c.lhs, 6)} vs {_f(c.rhs, 6)}"
                     + (f"  ({c.detail})" if c.detail and c.ok is not True else ""))
    lines.append("Premises (checked in every run; a premise failure is reported as such, never as a broken promise):")
    lines.extend(f"  - {p}" for p in cert.premises)
    lines.append("Assumptions (outside the model):")
    lines.extend(f"  - {a}" for a in cert.assumptions)
    if cert.paper_route is not None:  # a report beside the verdict (verify.lemma1.route), never the verdict
        lines.extend(cert.paper_route.summary_lines())
    lines.append(f"Design key: {cert.design_key} (theorem {cert.design_fields.get('theorem_version', 'n/a')})")
    lines.append(f"Elapsed: {cert.elapsed_s:.2f} s")
    return "\n".join(lines)
