"""The station-keeping law's proof (:class:`tubekit.model.backup.StationKeeping`), the first :class:`BackupProof`.

Each step of the protocol is a function of its own module:

* :meth:`StationKeepingProof.design` — :func:`verify.backup.search.design_backup` (the grid search; with
  ``smooth`` the faded, ramped, continuous-yaw law; with ``fits`` the gentle search);
* :meth:`StationKeepingProof.certify` — :func:`verify.backup.proof.certify_backup` (the level set's first-exit
  proof in Arb, with :func:`verify.backup.continuous.continuous_rate_bound` for the continuous yaw law);
* :meth:`StationKeepingProof.command_rate` — :func:`verify.backup.rate.backup_command_rate`;
* :meth:`StationKeepingProof.tick_change` — :func:`verify.backup.rate.backup_tick_change`.

Importing this module registers :data:`STATION_KEEPING_PROOF` (``verify/backup/__init__.py`` imports it).
"""

from __future__ import annotations

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupLaw, SafeSet, StationKeeping
from verify.backup.proof import certify_backup
from verify.backup.protocol import BackupCertificate, Fits, register_backup_proof
from verify.backup.rate import backup_command_rate, backup_tick_change
from verify.backup.search import design_backup

__all__ = ["StationKeepingProof", "STATION_KEEPING_PROOF"]


class StationKeepingProof:
    """The proof of ``kind = "station_keeping"`` (module doc); a stateless object."""

    kind: str = StationKeeping.kind

    def design(self, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
               handover: tuple[float, float], yaw_rate_error: float = 0.0, smooth: bool = False,
               fits: Fits | None = None, surge_floor: float | None = None) -> BackupCertificate:
        """:func:`verify.backup.search.design_backup` (the smallest certified safe set on its grid; with ``fits``
        the smallest whose command the velocity loop can follow). ``surge_floor`` is not read: the law stops."""
        return design_backup(omega_xy=omega_xy, omega_z=omega_z, limits=limits, tick=tick, handover=handover,
                             yaw_rate_error=yaw_rate_error, smooth=smooth, fits=fits)

    def certify(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                yaw_rate_error: float = 0.0) -> BackupCertificate:
        """:func:`verify.backup.proof.certify_backup` (ConfigError when ``law`` is not a StationKeeping)."""
        return certify_backup(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits, tick=tick,
                              handover=handover, yaw_rate_error=yaw_rate_error)

    def command_rate(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                     limits: tuple[float, float, float],
                     loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
        """:func:`verify.backup.rate.backup_command_rate` (m/s², m/s², rad/s²)."""
        return backup_command_rate(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                   loop_error=loop_error)

    def tick_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> tuple[float, float, float]:
        """:func:`verify.backup.rate.backup_tick_change` (m/s, m/s, rad/s per tick)."""
        return backup_tick_change(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                  loop_error=loop_error, tick=tick)

    def sway_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> float:
        """0 (m/s): the law never commands sway."""
        return 0.0

    def summary_lines(self, cert: BackupCertificate) -> list[str]:
        """The station-keeping backup's lines: verdict, safe set, gains, level-set rate, fades and ramp."""
        s, law = cert.safe_set, _station_keeping(cert.law)
        head = "certified" if cert.certified else "NOT certified: " + ", ".join(c.condition for c in cert.failures)
        return [f"backup (station keeping): {head}",
                f"  safe set: horizontal radius {s.radius:.3f} m, depth band ±{s.depth:.3f} m; hand-over within "
                f"{s.handover_radius:.3f} m of the anchor (any heading)",
                f"  law: u_b {law.surge:g} m/s, k {law.yaw_rate:g} rad/s, w_b {law.heave:g} m/s; against "
                f"ω̄_xy {cert.omega_xy:.4g} m/s, ω̄_z {cert.omega_z:.4g} m/s",
                f"  sup V̇ on the level set <= {cert.rate_bound:.4g} m/s (sampled {cert.rate_sampled:.4g}, "
                f"{cert.boxes} intervals)"] + _smooth_lines(cert)


def _station_keeping(law: BackupLaw) -> StationKeeping:
    """``law`` as a StationKeeping (ConfigError ``backup.kind`` when it is another kind)."""
    if not isinstance(law, StationKeeping):
        raise ConfigError("backup.kind", f"a {StationKeeping.kind} law", getattr(law, "kind", type(law).__name__))
    return law


def _smooth_lines(cert: BackupCertificate) -> list[str]:
    """The fades, the ramp, E_r and the continuous yaw law, when any is on."""
    law = _station_keeping(cert.law)
    if not (law.surge_fade or law.yaw_fade or law.ramp or cert.yaw_rate_error):
        return []
    yaw = ([f"  continuous yaw law: unstable axis angle χ_u {law.unstable:.4g} rad, band χ_0 {law.yaw_band:.4g} rad"]
           if law.yaw_law == "continuous" else [])
    return [f"  fades d_0 {law.surge_fade:.4g} m, d_1 {law.yaw_fade:.4g} m, ramp t_r {law.ramp:.4g} s; "
            f"yaw-rate error E_r {cert.yaw_rate_error:.4g} rad/s"] + yaw


#: The registered station-keeping proof.
STATION_KEEPING_PROOF = register_backup_proof(StationKeepingProof())
