"""The re-derivation of the backup, the safe-only design and the tiers (part of :mod:`verify.studies.rederive`).

:func:`derive_tiers` rebuilds, from the stored scenario, the safe-only design (when the derived
tracking design does not certify, :func:`verify.theorem.tiers.safe_only_design`) and re-runs
:func:`verify.backup.certify_backup` on the *stored* law and safe set with the re-derived
disturbance bounds, limits, tick and hand-over margins (:func:`verify.theorem.tiers.recertify_backup`, through
the law's registered proof, :func:`verify.backup.proof_for`; a stored law whose kind has no proof is a
ConfigError naming ``certificate.backup.law.kind``).
:func:`check_tiers` records the comparisons: a stored law or safe set that does not certify is a
disagreement naming ``backup.law`` or ``backup.safe_set`` (whichever differs from the backup
:func:`verify.theorem.tiers.backup_of` designs afresh); a stored bound (ω̄, the rate bound, the hand-over,
the yaw-rate error E_r the proof holds against) smaller than derived, a missing block or a tier stronger
than derived names its field. On the dynamic plant the stored law's command rate is checked against the
velocity loop's bound by :mod:`verify.studies.rederive` (``velocity_loop``, ``loop_consistent``).
"""

from __future__ import annotations

from dataclasses import dataclass

from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario
from tubekit.tiers import Tiers

from verify.backup import BackupCertificate, proof_for
from verify.certificate.record import CertificateRecord
from verify.kernel.region import Region
from verify.studies.ledger import Ledger
from verify.theorem.design import Condition, Design, DisturbanceBounds
from verify.theorem.terminal import with_terminal
from verify.theorem.tiers import backup_of, recertify_backup, safe_only_design, tiers_of

__all__ = ["DerivedTiers", "derive_tiers", "check_tiers"]


@dataclass(frozen=True)
class DerivedTiers:
    """The derived safe-only design, the stored backup re-certified, and (only when that fails) a fresh design."""

    safe: Design | None
    backup: BackupCertificate | None
    fresh: BackupCertificate | None = None
    design: Design | None = None


def _with_terminal(cert: CertificateRecord, scenario: Scenario, region: Region, dist: DisturbanceBounds,
                   design: Design) -> Design:
    """The tracking design with its terminal ingredients re-derived (:func:`verify.theorem.terminal.with_terminal`)
    against the backup for its margins: designed afresh on the kinematic plant (as ``certify`` does), the stored
    law re-certified on the dynamic one (whose design needs the velocity loop's fit)."""
    if not design.certified:
        return design
    if scenario.plant.dynamic and cert.backup is not None:
        bk = recertify_backup(scenario, cert.backup.law, cert.backup.safe_set, dist, design.margins,
                              cert.backup.anchor_reach)
    else:
        bk = backup_of(scenario, dist, design.margins)
    return with_terminal(scenario, design, region, bk.safe_set if bk.certified else None)


def derive_tiers(cert: CertificateRecord, scenario: Scenario, region: Region, dist: DisturbanceBounds,
                 design: Design) -> DerivedTiers:
    """The tracking design with its terminal ingredients, the safe-only design (None when tracking certifies)
    and the stored backup re-certified (module doc)."""
    design = _with_terminal(cert, scenario, region, dist, design)
    safe = None if design.certified else safe_only_design(scenario, region, cert.gains, dist)
    if cert.backup is None:
        return DerivedTiers(safe, None, design=design)
    try:
        proof_for(cert.backup.law)
    except ConfigError as exc:
        raise ConfigError("certificate.backup.law.kind", exc.expected, exc.received) from None
    margins = (safe if safe is not None else design).margins
    bk = recertify_backup(scenario, cert.backup.law, cert.backup.safe_set, dist, margins, cert.backup.anchor_reach)
    return DerivedTiers(safe, bk, None if bk.certified else backup_of(scenario, dist, margins), design=design)


def _backup(raw: dict, cert: CertificateRecord, derived: DerivedTiers, led: Ledger) -> None:
    stored, bk, fresh = cert.backup, derived.backup, derived.fresh
    if stored is None or bk is None:
        led.check("backup", False, None, "a backup block", "every certificate carries its backup")
        return
    named = cert.inputs.scenario.controller.backup
    led.check("backup.law.kind", stored.law.kind == named, stored.law.kind, named,
              "the law the scenario names (controller.backup): the loop runs the certificate's law")
    for k in ("omega_xy", "omega_z", "rate_bound", "yaw_rate_error"):
        led.at_least(f"backup.{k}", getattr(stored, k), getattr(bk, k))
    led.equal("backup.tick", stored.tick, bk.tick)
    led.each("at_least", "backup.handover", list(stored.handover), list(bk.handover))
    claimed = (raw.get("backup") or {}).get("certified") is True
    failed = [c.condition for c in bk.failures]
    name = "backup.certified"
    if fresh is not None:
        name = ("backup.law" if stored.law != fresh.law else "backup.safe_set" if stored.safe_set != fresh.safe_set
                else name)
    led.check(name, not claimed or bk.certified, claimed, failed or True,
              "the stored law and safe set certified with the derived bounds and margins (verify.backup)")


def _safe_design(cert: CertificateRecord, safe: Design | None, led: Ledger) -> None:
    stored = cert.safe_design
    if safe is None:
        if stored is not None:
            led.notes.append("safe_design stored although the derived tracking design certifies")
        return
    if stored is None or stored.margins is None:
        led.check("safe_design", False, None, "the safe-only design", "present when tracking does not certify")
        return
    for k in ("p_xy", "p_z", "psi"):
        led.at_least(f"safe_design.tube.{k}", getattr(stored.tube, k), getattr(safe.tube, k))
    for k in ("position", "e_z"):
        led.each("at_least", f"safe_design.margins.{k}", getattr(stored.margins, k), getattr(safe.margins, k))
    led.each("at_most", "safe_design.v_bar", list(stored.v_bar or []), list(safe.v_bar or []))
    led.each("at_least", "safe_design.arc_rates", list(stored.rates), list(safe.rates))


def check_tiers(raw: dict, cert: CertificateRecord, design: Design, tiers: DerivedTiers, led: Ledger,
                plant: tuple[Condition, ...] = ()) -> Tiers:
    """Record the backup, safe-design and tier checks; return the derived tiers (``plant``: the dynamic
    plant's derived conditions, :func:`verify.vehicle.compose.solve_dynamic`)."""
    _backup(raw, cert, tiers, led)
    _safe_design(cert, tiers.safe, led)
    derived = tiers_of(design, tiers.safe, tiers.backup, plant)
    stored = raw.get("tiers") if isinstance(raw.get("tiers"), dict) else {}
    for k, v in derived.to_dict().items():
        claim = stored.get(k)
        led.check(f"tiers.{k}", claim is not True or v, claim, v, "a tier not stronger than derived")
    return derived
