"""The run: sensing, plan acceptance, the closed loop, its result, metrics and promises.

:func:`~tubekit.loop.closed_loop.run_closed_loop` runs sense → solve → accept (arc check and
:func:`~tubekit.loop.terminal.terminal_condition`) or replay, then the backup law → ticks → log;
:class:`~tubekit.loop.result.SimulationResult` holds the log; :mod:`~tubekit.loop.metrics`
measures it; :func:`~tubekit.loop.promises.check_promises` checks what a certificate promised.
"""

from __future__ import annotations

from tubekit.loop.closed_loop import PlanMemory, run_closed_loop, saturate
from tubekit.loop.metrics import METRIC_KEYS, compute_metrics
from tubekit.loop.plan_check import PlanCheck, check_plan
from tubekit.loop.promises import Promise, broken_promises, check_promises
from tubekit.loop.result import CSV_COLUMNS, SimulationResult
from tubekit.loop.sensing import ObstacleMap
from tubekit.loop.terminal import TerminalCheck, terminal_condition

__all__ = ["run_closed_loop", "PlanMemory", "saturate", "SimulationResult", "CSV_COLUMNS", "compute_metrics",
           "METRIC_KEYS", "check_plan", "PlanCheck", "Promise", "check_promises", "broken_promises", "ObstacleMap",
           "terminal_condition", "TerminalCheck"]
