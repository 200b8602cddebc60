"""The backup law's safe set, proved in Arb: the proof (``proof``), the continuous yaw law's level-set bound
(``continuous``), the command's rate (``rate``) and the design search (``search``). The public names, in one place."""

from verify.backup.continuous import (cone_angle, continuous_rate_bound, continuous_rate_sampled, shape_enclosure,
                                      unstable_condition, yaw_shape_enclosure)
from verify.backup.proof import BACKUP_MAX_BOXES, BackupCertificate, certify_backup, planar_rate_bound, ramp_window
from verify.backup.search import UNSTABLE_FRACTION, design_backup
from verify.backup.rate import backup_command_rate, backup_tick_change

__all__ = ["BackupCertificate", "planar_rate_bound", "certify_backup", "design_backup", "ramp_window",
           "backup_command_rate", "backup_tick_change", "BACKUP_MAX_BOXES", "UNSTABLE_FRACTION",
           "continuous_rate_bound", "continuous_rate_sampled", "unstable_condition", "cone_angle",
           "shape_enclosure", "yaw_shape_enclosure"]
