"""Property testing and falsification of the loop that runs.

* :mod:`verify.falsify.invariance` — one period of the sampled-data loop from a reset state;
* :mod:`verify.falsify.strategies` — hypothesis strategies, public for users' own property tests;
* :mod:`verify.falsify.one_period` — the one-period falsifier behind ``tubekit falsify``;
* :mod:`verify.falsify.closed_loop` — the closed-loop falsifier over disturbance sequences.

The only part of verify that runs the loop (it imports :mod:`tubekit.loop`).
"""

from __future__ import annotations

from verify.falsify.closed_loop import ClosedLoopResult, LoopRun, falsify_closed_loop
from verify.falsify.one_period import VIOLATION_TOL, FalsifyResult, SearchSpace, falsify, search_space

__all__ = ["falsify", "FalsifyResult", "SearchSpace", "search_space", "VIOLATION_TOL",
           "falsify_closed_loop", "ClosedLoopResult", "LoopRun"]
