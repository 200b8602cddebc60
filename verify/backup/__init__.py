"""The backup law's safe set, proved in Arb, one proof per backup-law kind.

The protocol and its registry (``protocol``: :class:`BackupProof`, :func:`proof_for`, :class:`BackupCertificate`);
the station-keeping proof (``station_keeping``, registered on import of this package) with its steps: the proof
(``proof``), the continuous yaw law's level-set bound (``continuous``), the command's rate (``rate``) and the design
search (``search``). The public names, in one place.
"""

from verify.backup.continuous import (cone_angle, continuous_rate_bound, continuous_rate_sampled, shape_enclosure,
                                      unstable_condition, yaw_shape_enclosure)
from verify.backup.protocol import (BACKUP_PROOFS, DEFAULT_BACKUP_KIND, BackupCertificate, BackupProof, Fits,
                                    proof_for, register_backup_proof)
from verify.backup.proof import BACKUP_MAX_BOXES, certify_backup, planar_rate_bound, ramp_window
from verify.backup.search import UNSTABLE_FRACTION, design_backup
from verify.backup.rate import backup_command_rate, backup_tick_change
from verify.backup.station_keeping import STATION_KEEPING_PROOF, StationKeepingProof
from verify.backup.loiter import LOITER_PROOF, LoiterProof, certify_loiter, design_loiter
from verify.backup.hold import HOLD_PROOF, HoldProof, certify_hold, design_hold
from verify.backup.none import NO_BACKUP_PROOF, NoBackupProof, certify_none

__all__ = ["BackupCertificate", "BackupProof", "Fits", "BACKUP_PROOFS", "DEFAULT_BACKUP_KIND", "proof_for",
           "register_backup_proof", "StationKeepingProof", "STATION_KEEPING_PROOF", "LoiterProof", "LOITER_PROOF",
           "certify_loiter", "design_loiter", "HoldProof", "HOLD_PROOF", "certify_hold", "design_hold", "NoBackupProof",
           "NO_BACKUP_PROOF", "certify_none", "planar_rate_bound",
           "certify_backup", "design_backup", "ramp_window", "backup_command_rate", "backup_tick_change",
           "BACKUP_MAX_BOXES", "UNSTABLE_FRACTION", "continuous_rate_bound", "continuous_rate_sampled",
           "unstable_condition", "cone_angle", "shape_enclosure", "yaw_shape_enclosure"]
