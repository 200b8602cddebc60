"""From a certificate to the :class:`tubekit.tightening.Tightening` the FHOCP and the closed loop use.

Certified: V̄ = V - κ̄, the per-arc margins, the tube and the arc-rate bounds as
certified; the FHOCP's node constraints are the largest margin plus the
inter-node allowance rate · δ / 2 (a plan meeting them usually passes the exact
arc check of :mod:`tubekit.loop.plan_check`, which is what the theorem relies on).

Best effort (not certified): the same construction from the best design found,
each input limit kept at >= max(``min_input_fraction`` · V_i, the keep-up need)
and each node constraint keeping >= a quarter of R's half-width; flagged
``certified=False`` — it carries no guarantee.

Safe only (the tracking tier does not certify, the safe tier does, :attr:`Certificate.tiers`): the
safe-only design at σ = 0 (:func:`verify.theorem.tiers.safe_only_design`): ``v_max`` = V (no feedback,
nothing to reserve), ``sigma`` = 0, ``tube`` = 0, margins whose e-columns are zero (not enforced:
plan acceptance checks only the position constraints) and whose position column is the
certified position margins, FHOCP node bounds on e those of R (nothing about e is promised or checked at
acceptance, so R is not shrunk by an uncertified design's margins) but for e_d_min, which keeps the best-effort
tracking design's margin (plans stay off ε), ``obstacle_margin`` = the largest
position margin plus its inter-node allowance; ``certified`` = True, ``tiers`` = ``{"safe": True,
"tracking": False}``.

With the tracking tier, the tightening carries the terminal set and law of the tracking theorem
(``terminal_law``, :func:`verify.theorem.terminal.design_terminal`): plans must end in its set, the candidate
is completed by its law.

Every tightening carries its ``tiers`` (:class:`tubekit.tiers.Tiers`) and the backup (:class:`tubekit.model.backup.BackupPlan`: the
law, its safe set, the hand-over it was proved for) when the certificate has one — also a best-effort
one (then the backup is not certified either, ``tiers`` says so). ``certified`` is True when the
safe tier is certified. All carry the design they were certified for (``design``: the certificate's
:class:`tubekit.design_inputs.DesignInputs`), so a run of another design refuses them before it starts
(:meth:`tubekit.tightening.Tightening.require`).
"""

from __future__ import annotations

import numpy as np

from tubekit.model.backup import BackupPlan
from tubekit.tightening import DisturbanceBound, RegionBounds, Tightening

from verify.certificate.record import CertificateRecord

__all__ = ["tightening_of", "MIN_KEPT_FRACTION"]

#: Fraction of R's half-width every node constraint keeps (best effort and allowance clamp).
MIN_KEPT_FRACTION = 0.25


def _input_limits(cert: CertificateRecord, min_input_fraction: float) -> np.ndarray:
    v = np.asarray(cert.limits, dtype=float)
    d = cert.design
    if cert.certified:
        return np.asarray(d.v_bar, dtype=float)
    kappa = np.asarray(d.tube.kappa, dtype=float) if d.tube.certified else np.full(3, np.inf)
    p = d.problem
    need = np.array([min(p.pd_xy + cert.disturbance.omega_xy, v[0]), min(p.pd_z + cert.disturbance.omega_z, v[1]),
                     0.0])
    floor = np.maximum(min_input_fraction * v, need)
    return np.maximum(v - kappa, floor)


def _lower_corner(cert: CertificateRecord, v_max: np.ndarray) -> np.ndarray | None:
    """The nominal box's lower corner with a minimum surge: V's lower corner raised by what V̄ reserves,
    limits.lower + (V − V̄) (so v̂ + κ >= u_min); None for the symmetric box (−V̄)."""
    limits = cert.inputs.scenario.limits
    if limits.u_min is None:
        return None
    return np.minimum(limits.lower + (np.asarray(cert.limits, dtype=float) - v_max), v_max)


def _clamped(cert: CertificateRecord, margins: np.ndarray) -> np.ndarray:
    """Best effort: each margin column capped so Ē keeps MIN_KEPT_FRACTION of R (plans can be accepted)."""
    reg = cert.region
    caps = (1 - MIN_KEPT_FRACTION) * np.array([0.5 * (reg.e_d[1] - reg.e_d[0]), min(-reg.e_z[0], reg.e_z[1]),
                                               min(-reg.e_o[0], reg.e_o[1]), cert.design.problem.eps])
    return np.minimum(np.where(np.isfinite(margins), margins, np.inf), caps[None, :])


def _node_bounds(cert: CertificateRecord, margins: np.ndarray, rates: np.ndarray) -> dict[str, float]:
    reg = cert.region
    allowance = 0.5 * cert.dt * rates
    worst = margins.max(axis=0) + allowance if margins.size else allowance * 0.0
    ed_half = 0.5 * (reg.e_d[1] - reg.e_d[0])
    keep = MIN_KEPT_FRACTION
    ez_half, eo_half = min(-reg.e_z[0], reg.e_z[1]), min(-reg.e_o[0], reg.e_o[1])
    md = min(worst[0], (1 - keep) * ed_half)
    return {"e_d_min": reg.e_d[0] + md, "e_d_max": reg.e_d[1] - md,
            "e_z_max": ez_half - min(worst[1], (1 - keep) * ez_half),
            "e_o_max": eo_half - min(worst[2], (1 - keep) * eo_half),
            "obstacle_margin": float(worst[3])}


def _backup_plan(cert: CertificateRecord) -> BackupPlan | None:
    b = cert.backup
    return None if b is None else BackupPlan(law=b.law, safe_set=b.safe_set, handover=tuple(b.handover),
                                                anchor_reach=b.anchor_reach)


def _common(cert: CertificateRecord) -> dict[str, object]:
    reg = cert.region
    return dict(region=RegionBounds(epsilon=reg.e_d[0], e_d_max=reg.e_d[1], e_z_max=min(-reg.e_z[0], reg.e_z[1]),
                                    e_o_max=min(-reg.e_o[0], reg.e_o[1])),
                disturbance=DisturbanceBound(omega_xy=cert.disturbance.omega_xy, omega_z=cert.disturbance.omega_z,
                                             sway=cert.disturbance.gamma),
                design=cert.inputs, backup=_backup_plan(cert), tiers=cert.tiers,
                velocity_loop=None if cert.velocity_loop is None or not cert.velocity_loop.certified
                else tuple(cert.velocity_loop.error))


def _safe_only(cert: CertificateRecord) -> Tightening:
    """The safe-only tightening (module doc)."""
    d = cert.safe_design
    m = d.margins
    n = len(m.position)
    margins = np.column_stack([np.zeros(n), np.zeros(n), np.zeros(n), np.asarray(m.position, dtype=float)])
    rates = np.asarray(d.rates, dtype=float)
    nodes = _safe_only_nodes(cert)
    v_max = np.asarray(cert.limits, dtype=float)
    return Tightening(v_max=v_max, v_min=_lower_corner(cert, v_max), e_d_min=nodes["e_d_min"], e_d_max=nodes["e_d_max"],
                      e_z_max=nodes["e_z_max"], e_o_max=nodes["e_o_max"],
                      obstacle_margin=float(m.position[-1] + 0.5 * cert.dt * rates[3]), sigma=cert.inputs.sigma,
                      margins=margins, rates=rates, tube=np.zeros(3), **_common(cert))


def _safe_only_nodes(cert: CertificateRecord) -> dict[str, float]:
    """The FHOCP's e-node bounds of a safe-only tightening: R's, except e_d_min (m, m, m, -).

    The safe tier promises nothing about e, and plan acceptance does not check it, so R is not shrunk by the
    margins of a tracking design that did not certify: those margins only narrowed the plans (|e_o| <= 0.19 instead of
    R's 0.5 pinned the transit behind its first rock for 112 of 150 s; ``benchmarks/mission.py``). The
    lower end keeps the tracking design's best-effort margin (clamped to keep a quarter of R), so plans stay off
    the ε the user declared: without it the paper's run came within 0.09 m of the target, ε = 0.1 m.
    """
    reg = cert.region
    nodes = {"e_d_min": reg.e_d[0], "e_d_max": reg.e_d[1], "e_z_max": min(-reg.e_z[0], reg.e_z[1]),
             "e_o_max": min(-reg.e_o[0], reg.e_o[1])}
    d = cert.design
    if d.tube.certified and d.margins is not None:
        margins = _clamped(cert, np.column_stack([d.margins.e_d, d.margins.e_z, d.margins.e_o, d.margins.position]))
        best = _node_bounds(cert, np.where(np.isfinite(margins), margins, 0.0), np.asarray(d.rates, dtype=float))
        nodes["e_d_min"] = best["e_d_min"]
    return nodes


def tightening_of(cert: CertificateRecord, min_input_fraction: float = 0.5) -> Tightening:
    """The Tightening of ``cert`` (certified, safe only, or best effort, see the module doc)."""
    if cert.tiers.safe_only and cert.safe_design is not None:
        return _safe_only(cert)
    d = cert.design
    has_tube = d.tube.certified and d.margins is not None
    margins = (np.column_stack([d.margins.e_d, d.margins.e_z, d.margins.e_o, d.margins.position])
               if has_tube else np.zeros((0, 4)))
    if has_tube and not cert.certified:
        margins = _clamped(cert, margins)
    rates = np.asarray(d.rates, dtype=float)
    nodes = _node_bounds(cert, np.where(np.isfinite(margins), margins, 0.0) if margins.size else margins, rates)
    tube = np.asarray(d.tube.rho, dtype=float) if d.tube.certified else np.zeros(3)
    terminal = cert.design.terminal if cert.tiers.tracking else None
    v_max = _input_limits(cert, min_input_fraction)
    return Tightening(v_max=v_max, v_min=_lower_corner(cert, v_max), sigma=cert.inputs.sigma, margins=margins,
                      rates=rates, tube=tube, terminal_law=terminal, **_common(cert), **nodes)
