"""The proof of ``controller.backup = "none"`` (:class:`tubekit.model.no_backup.NoBackup`): nothing to prove alone.

Without a backup law the safe tier is a corollary of the tracking tier (``docs/verify.md`` step 13g): the tracking
theorem gives an accepted plan at every period for all time (step 17: a plan at t = 0, and from every accepted
plan the candidate passes the exact check), every accepted plan keeps the vehicle clear of the obstacles, inside
the workspace and its inputs in V̄ with the tube's margins, and the velocity loop only ever follows plans (so its
error is the plans-only bound, step 17d). This proof therefore certifies a point safe set
(:data:`tubekit.model.no_backup.POINT_SET`) with one condition, ``backup_none``, which holds and says on what it
rests; :func:`verify.theorem.tiers.tier_conditions` makes the safe tier depend on every tracking condition, so a
design whose tracking tier fails gets no safe tier either. The law's command never changes (it keeps the last
one), so the velocity loop is charged nothing for it.

Steps of the protocol: :meth:`NoBackupProof.design` and :meth:`NoBackupProof.certify` — :func:`certify_none`;
:meth:`NoBackupProof.command_rate`, :meth:`NoBackupProof.tick_change`, :meth:`NoBackupProof.sway_change` — 0.
Importing this module registers :data:`NO_BACKUP_PROOF`.
"""

from __future__ import annotations

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupLaw, SafeSet
from tubekit.model.no_backup import POINT_SET, NoBackup
from verify.backup.protocol import BackupCertificate, Fits, register_backup_proof
from verify.theorem.design import Condition

__all__ = ["NoBackupProof", "NO_BACKUP_PROOF", "certify_none", "NONE_CONDITION"]

#: The one condition of the certificate (module doc).
NONE_CONDITION = "backup_none"


def certify_none(law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float, tick: float,
                 handover: tuple[float, float] = (0.0, 0.0), yaw_rate_error: float = 0.0) -> BackupCertificate:
    """The certificate of :class:`NoBackup` (module doc); ConfigError when ``law`` is another kind."""
    if not isinstance(law, NoBackup):
        raise ConfigError("backup.kind", f"a {NoBackup.kind!r} law", getattr(law, "kind", type(law).__name__))
    cond = Condition(NONE_CONDITION, "no backup law: the safe tier rests on the tracking tier (a plan accepted at "
                     "every period, docs/verify.md step 13g); the certificate gives it only with tracking", None, None,
                     True, "the safe set is a point: plans need only end clear of the obstacles")
    return BackupCertificate(law=law, safe_set=safe, omega_xy=omega_xy, omega_z=omega_z, tick=tick,
                             rate_bound=0.0, rate_sampled=0.0, boxes=0, conditions=(cond,),
                             handover=handover, yaw_rate_error=yaw_rate_error)


class NoBackupProof:
    """The proof of ``kind = "none"`` (module doc); a stateless object."""

    kind: str = NoBackup.kind

    def design(self, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
               handover: tuple[float, float], yaw_rate_error: float = 0.0, smooth: bool = False,
               fits: Fits | None = None, surge_floor: float | None = None) -> BackupCertificate:
        """:func:`certify_none` of the law and the point set (nothing else is read)."""
        return certify_none(NoBackup(), SafeSet(level=POINT_SET, shape=0.0, depth=POINT_SET), omega_xy=omega_xy,
                            omega_z=omega_z, tick=tick, handover=handover, yaw_rate_error=yaw_rate_error)

    def certify(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                yaw_rate_error: float = 0.0) -> BackupCertificate:
        """:func:`certify_none` (the stored law and set, re-read)."""
        return certify_none(law, safe, omega_xy=omega_xy, omega_z=omega_z, tick=tick, handover=handover,
                            yaw_rate_error=yaw_rate_error)

    def command_rate(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                     limits: tuple[float, float, float],
                     loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
        """(0, 0, 0): the kept command does not change."""
        return 0.0, 0.0, 0.0

    def tick_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> tuple[float, float, float]:
        """(0, 0, 0) per tick."""
        return 0.0, 0.0, 0.0

    def sway_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> float:
        """0: no sway command."""
        return 0.0

    def summary_lines(self, cert: BackupCertificate) -> list[str]:
        """One line: no backup, and what the safe tier rests on."""
        return ["backup: none -- the safe tier rests on the tracking tier (a plan accepted at every period); "
                "no law runs, plans need only end clear"]


#: The registered proof of ``controller.backup = "none"``.
NO_BACKUP_PROOF = register_backup_proof(NoBackupProof())
