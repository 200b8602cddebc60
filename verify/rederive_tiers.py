"""The re-derivation of the backup, the safe-only design and the tiers (part of :mod:`verify.rederive`).

:func:`derive_tiers` rebuilds, from the stored scenario, the safe-only design (when the derived
tracking design does not certify, :func:`verify.tiers.safe_only_design`) and re-runs
:func:`verify.backup.certify_backup` on the *stored* law and safe set with the re-derived
disturbance bounds, limits, tick and hand-over margins (:func:`verify.tiers.recertify_backup`).
:func:`check_tiers` records the comparisons: a stored law or safe set that does not certify is a
disagreement naming ``backup.law`` or ``backup.safe_set`` (whichever differs from the backup
:func:`verify.tiers.backup_of` designs afresh); a stored bound smaller than derived,
a missing block or a tier stronger than derived names its field.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from verify.backup import BackupCertificate
from verify.design import Design
from verify.tiers import backup_of, recertify_backup, safe_only_design, tiers_of

__all__ = ["DerivedTiers", "derive_tiers", "check_tiers"]


@dataclass(frozen=True)
class DerivedTiers:
    """The derived safe-only design, the stored backup re-certified, and (only when that fails) a fresh design."""

    safe: Design | None
    backup: BackupCertificate | None
    fresh: BackupCertificate | None = None


def derive_tiers(cert: Any, scenario: Any, region: Any, dist: Any, design: Design) -> DerivedTiers:
    """The safe-only design (None when tracking certifies) and the stored backup re-certified (module doc)."""
    safe = None if design.certified else safe_only_design(scenario, region, cert.gains, dist)
    if cert.backup is None:
        return DerivedTiers(safe, None)
    margins = (safe if safe is not None else design).margins
    bk = recertify_backup(scenario, cert.backup.law, cert.backup.safe_set, dist, margins)
    return DerivedTiers(safe, bk, None if bk.certified else backup_of(scenario, dist, margins))


def _backup(raw: dict, cert: Any, derived: DerivedTiers, led: Any) -> None:
    stored, bk, fresh = cert.backup, derived.backup, derived.fresh
    if stored is None or bk is None:
        led.check("backup", False, None, "a backup block", "every certificate carries its backup")
        return
    for k in ("omega_xy", "omega_z", "rate_bound"):
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


def _safe_design(cert: Any, safe: Design | None, led: Any) -> None:
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


def check_tiers(raw: dict, cert: Any, design: Design, tiers: DerivedTiers, led: Any,
                plant: tuple = ()) -> dict[str, bool]:
    """Record the backup, safe-design and tier checks; return the derived tiers (``plant``: the dynamic
    plant's derived conditions, :func:`verify.vehicle.compose.solve_dynamic`)."""
    _backup(raw, cert, tiers, led)
    _safe_design(cert, tiers.safe, led)
    derived = tiers_of(design, tiers.safe, tiers.backup, plant)
    stored = raw.get("tiers") if isinstance(raw.get("tiers"), dict) else {}
    for k, v in derived.items():
        claim = stored.get(k)
        led.check(f"tiers.{k}", claim is not True or v, claim, v, "a tier not stronger than derived")
    return derived
