"""The certificate as text: :func:`summary_text` (``tubekit certify``, at most about 25 lines: the verdict, each
failed condition with the field that would make it hold, the tube, the backup, the design key) and
:func:`certificate_text` (``tubekit certify -v``: every number, condition, premise and assumption)."""

from __future__ import annotations

import math
from typing import Any

from tubekit.design_inputs import THEOREM_VERSION

from verify.certificate.knobs import Knob, knobs_for
from verify.certificate.record import CertificateRecord

__all__ = ["certificate_text", "summary_text", "verdict_line", "tiers_line", "compare", "tried_lines", "knob_text",
           "FAILURE_LINES", "LOOP_NOT_CLOSED"]

#: Failed conditions listed one per line in :func:`summary_text`; the others are named on one more line.
FAILURE_LINES = 12
#: Said under the failures when the velocity loop's fixed point did not close: ω̄, the tube and the backup were
#: derived with the loop error the last round assumed, which no loop bound confirms.
LOOP_NOT_CLOSED = ("loop_fixed_point -- the velocity loop's bound did not close, so every condition that reads "
                   "omega_bar (keep_up, e_bar, the tube, the backup's) reads it with a loop error no bound confirms: "
                   "make loop_fixed_point hold first")


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
        b = cert.backup
        reach = (f"; the anchor may be placed up to {_f(b.anchor_reach)} m from the plan's end (the rest of "
                 f"the hand-over distance is the last arc's margin {_f(b.handover[0] - b.anchor_reach)} m)"
                 if b.anchor_reach else " (the last arc's margins)")
        out.append(f"  hand-over: within {_f(b.handover[0])} m horizontally, {_f(b.handover[1])} m in depth of the "
                   f"anchor{reach}")
    return out


def verdict_line(cert: CertificateRecord) -> str:
    """The first line of either text: scenario, law, verdict and the tiers (:func:`tiers_line`)."""
    n_fail = len(cert.failures)
    status = "CERTIFIED" if cert.certified else f"NOT CERTIFIED ({n_fail} failed condition{'s' * (n_fail != 1)})"
    return f"tubekit certificate: scenario '{cert.scenario_name}', law '{cert.law}': {status} -- {tiers_line(cert)}"


def knob_text(knobs: tuple[Knob, ...]) -> str:
    """`` — set limits.u_max >= 0.503 m/s or |trajectory.rate| <= 0.0933 rad/s`` ('' without a knob): each knob
    alone makes the condition hold."""
    return " — set " + " or ".join(k.clause() for k in knobs) if knobs else ""


def certificate_text(cert: CertificateRecord) -> str:
    """Human-readable certificate: verdict, region, disturbance, tube, conditions, premises, assumptions."""
    dist = cert.disturbance
    lines = [verdict_line(cert),
             "Theorem: the sampled-data loop as it runs (nominal reset every period, kappa held at the ancillary "
             "rate, plans accepted by the exact arc check and the terminal condition, the previous plan replayed "
             "otherwise, the certified backup law once the replay is exhausted).",
             "Region R (every bound holds over it):", cert.region.describe(),
             f"Disturbance: ||omega_xy|| <= {_f(dist.omega_xy)} m/s, |omega_z| <= {_f(dist.omega_z)} m/s "
             f"(sway gamma_bar = {_f(dist.gamma)} m/s from the sway model over V; declared {_f(dist.declared_sway)})"]
    lines += _tracking_bound_lines(cert)
    lines += _tube_lines(cert)
    if getattr(cert, "velocity_loop", None) is not None:  # dynamic plant: the derived loop bound
        lines += cert.velocity_loop.summary_lines()
    lines += _tier_lines(cert)
    lines.append("Conditions:")
    for c in cert.conditions:
        tag = {True: "ok  ", False: "FAIL", None: "n/a "}[c.ok]
        lines.append(f"  [{tag}] {c.condition}: {c.inequality}: {compare(c.lhs, c.rhs)}"
                     + (f"  ({c.detail})" if c.detail and c.ok is not True else "")
                     + knob_text(knobs_for(cert, c)))
    lines.append("Premises (checked in every run; a premise failure is reported as such, never as a broken promise):")
    lines.extend(f"  - {p}" for p in cert.premises)
    lines.append("Assumptions (outside the model):")
    lines.extend(f"  - {a}" for a in cert.assumptions)
    if cert.paper_route is not None:  # a report beside the verdict (verify.lemma1.route), never the verdict
        lines.extend(cert.paper_route.summary_lines())
    lines.append(f"Design key: {cert.design_key} (theorem {THEOREM_VERSION})")
    lines.append(f"Elapsed: {cert.elapsed_s:.2f} s")
    return "\n".join(lines)


def _failure_lines(cert: CertificateRecord) -> list[str]:
    """Each condition that does not hold, one line with its numbers and its knob, those with a knob first (at most
    :data:`FAILURE_LINES`, the rest named on one more line)."""
    open_ = [c for c in cert.conditions if c.ok is not True]
    knobs = {c.condition: knobs_for(cert, c) for c in open_}
    open_.sort(key=lambda c: not knobs[c.condition])  # stable: the ones with a knob first, each group in order
    if not open_:
        return [f"Every condition holds ({len(cert.conditions)}; each with its numbers: tubekit certify -v)."]
    out = [f"Failed conditions ({len(open_)}; the field that makes each hold, where one field decides it):"]
    for c in open_[:FAILURE_LINES]:
        numbers = compare(c.lhs, c.rhs) if c.ok is False else "not evaluated"
        if c.lhs is None and c.detail:  # no number to compare: say why (a root cause, or what it waits for)
            numbers = c.detail
        elif c.condition.startswith(("path_", "initial_terminal")) and c.detail:  # where, when and how much
            numbers = f"{numbers} ({c.detail})"
        out.append(f"  {c.condition}: {c.inequality}: {numbers}{knob_text(knobs[c.condition])}")
    rest = open_[FAILURE_LINES:]
    if rest:
        out.append(f"  ... and {len(rest)} more: " + ", ".join(c.condition for c in rest))
    if any(c.condition == "loop_fixed_point" and c.ok is False for c in open_):
        out.append(f"  root cause first: {LOOP_NOT_CLOSED}")
    return out


def _short_tube_lines(cert: CertificateRecord) -> list[str]:
    """σ and the tube of the chosen design in one line; the safe-only design in one more when there is one."""
    d, tried = cert.design, ", ".join(f"{_f(x.sigma)}{'*' if x.certified else ''}" for x in cert.tried)
    head = f"sigma = {_f(d.sigma)} 1/s (tried {tried}; * = certified); "
    t = d.tube
    if not t.certified:
        out = [head + f"one-period tube: none ({t.reason})"]
    else:
        last = f", position margin {_f(d.margins.position[-1], 3)} m on the last arc" if d.margins is not None else ""
        out = [head + f"one-period tube |rho| <= {_vec(t.rho)} (e_d m, e_z m, e_o){last}"]
    if cert.safe_design is not None:
        sd = cert.safe_design
        out.append(f"Safe tier's design: sigma = 0, position tube {_f(sd.tube.p_xy)} m per period, position margin "
                   f"{_f(sd.margins.position[-1], 3) if sd.margins is not None else 'n/a'} m on the last arc")
    return out


def _terminal_lines(cert: CertificateRecord) -> list[str]:
    """The certified terminal set and law in one line (none when tracking has none): X_f's faces, its gains and
    whether its yaw row feeds the line of sight's turn forward (``docs/verify.md`` step 17e)."""
    law = cert.design.terminal
    if law is None:
        return []
    faces = [f"d in [{_f(law.d_lo, 4)}, {_f(law.d_hi, 4)}] m", f"|alpha| <= {_f(law.alpha_max, 3)} rad",
             f"|e_z| <= {_f(law.z_max, 3)} m"]
    if law.has_bearing:
        faces.append(f"|bearing| <= {_f(law.bearing_max, 3)} rad")
    if law.has_rows:
        faces.append(f"row faces {_vec((law.row_u, law.row_w, law.row_r))}")
    fed = " and the line of sight's turn fed forward" if law.los_feedforward else ""
    return [f"Terminal set X_f: {', '.join(faces)}; law: turn g = {_f(law.turn, 3)}{fed}, lambda = "
            f"{_f(law.gain_d, 3)} 1/s, lambda_z = {_f(law.gain_z, 3)} 1/s"]


def _short_backup_lines(cert: CertificateRecord) -> list[str]:
    """The backup (its verdict, safe set and hand-over) and, on the dynamic plant, the velocity loop: a line each."""
    out: list[str] = []
    b = cert.backup
    if b is not None:
        s = b.safe_set
        reach = f", anchor within {_f(b.anchor_reach)} m of the plan's end" if b.anchor_reach else ""
        out.append(f"{b.summary_lines()[0]}; safe radius {s.radius:.3f} m, depth band ±{s.depth:.3f} m, hand-over "
                   f"within {_f(b.handover[0])} m ({_f(b.handover[1])} m in depth){reach}")
    loop = getattr(cert, "velocity_loop", None)
    if loop is not None:
        e = loop.error
        out.append(f"velocity loop (derived bound): {'certified' if loop.certified else 'NOT certified'}; "
                   f"loop error E = ({_f(e[0])} m/s, {_f(e[1])} m/s, {_f(e[2])} rad/s)"
                   + ("; the loop starts settled at limits.initial (no start transient: [plant] start)"
                      if cert.inputs.scenario.plant.settled else ""))
    return out


def _tracking_bound_lines(cert: CertificateRecord) -> list[str]:
    """On the dynamic plant, where the tracking design's ω̄ is the plans-only loop bound's (``docs/verify.md`` step
    17d), that ω̄; nothing where it is the certificate's."""
    p, dist = cert.design.problem, cert.disturbance
    if getattr(cert, "velocity_loop", None) is None or (p.omega_xy, p.omega_z) == (dist.omega_xy, dist.omega_z):
        return []
    return [f"Tracking tier's disturbance: ||omega_xy|| <= {_f(p.omega_xy)} m/s, |omega_z| <= {_f(p.omega_z)} m/s, "
            f"yaw-rate error <= {_f(p.yaw_rate_error)} rad/s (the plans-only loop bound: no backup runs under that tier)"]


def summary_text(cert: CertificateRecord) -> str:
    """The short certificate (``tubekit certify``): at most about 25 lines — the verdict with the tiers, each failed
    condition with both numbers and the field and value that would make it hold (:mod:`verify.certificate.knobs`),
    the disturbance, σ and the tube, the backup, the design key. :func:`certificate_text` is the full one."""
    dist = cert.disturbance
    lines = [verdict_line(cert)] + _failure_lines(cert)
    lines.append(f"Disturbance: ||omega_xy|| <= {_f(dist.omega_xy)} m/s, |omega_z| <= {_f(dist.omega_z)} m/s "
                 f"(sway gamma_bar = {_f(dist.gamma)} m/s)")
    lines += _tracking_bound_lines(cert)
    lines += _short_tube_lines(cert) + _terminal_lines(cert) + _short_backup_lines(cert)
    lines.append(f"Design key: {cert.design_key} (theorem {THEOREM_VERSION})")
    lines.append("Full text (every number, condition, premise and assumption): tubekit certify -v, "
                 "Certificate.summary(verbose=True)")
    return "\n".join(lines)
