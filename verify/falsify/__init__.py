"""Property testing and falsification of the loop that runs.

* :mod:`verify.falsify.invariance` — one period of the sampled-data loop from a reset state;
* :mod:`verify.falsify.strategies` — hypothesis strategies, public for users' own property tests;
* :mod:`verify.falsify.one_period` — the one-period falsifier behind ``tubekit falsify``;
* :mod:`verify.falsify.closed_loop` — the closed-loop falsifier over disturbance sequences;
* :mod:`verify.falsify.backup` — the backup law's safe set against currents (hand-over starts);
* :mod:`verify.falsify.backup_loop` — disturbance sequences against runs in which the backup engages.

The only part of verify that runs the loop (it imports :mod:`tubekit.loop`).
"""

from __future__ import annotations

from verify.falsify.backup import BackupAttack, falsify_backup
from verify.falsify.backup_loop import BackupLoopResult, falsify_backup_loop
from verify.falsify.closed_loop import ClosedLoopResult, LoopRun, falsify_closed_loop
from verify.falsify.one_period import VIOLATION_TOL, FalsifyResult, SearchSpace, falsify, search_space

__all__ = ["falsify", "FalsifyResult", "SearchSpace", "search_space", "VIOLATION_TOL",
           "falsify_closed_loop", "ClosedLoopResult", "LoopRun", "falsify_backup", "BackupAttack",
           "falsify_backup_loop", "BackupLoopResult"]
