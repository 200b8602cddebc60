"""The last accepted plan, its age and the backup's anchor (the loop's phases 2 and 3).

Phases of the loop (``docs/verify.md``): (1) a plan that passes the exact arc check and the
terminal condition is accepted; (2) otherwise the last accepted plan is replayed, shifted by the
periods elapsed (valid for N − 1 periods); (3) once it is exhausted, the backup law runs about the
anchor p* = the nominal end position of that plan; (4) a new accepted plan resumes tracking.
:class:`PlanMemory` holds what phases 2 and 3 need.
"""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np

__all__ = ["PlanMemory", "ZERO_INPUT"]

#: The zero input (read-only); used only when there is neither a plan to replay nor a backup.
ZERO_INPUT = np.zeros(3)
ZERO_INPUT.setflags(write=False)


@dataclass
class PlanMemory:
    """The last good plan, its age and the backup's anchor.

    Attributes
    ----------
    plan : array (N, 3) or None
        Inputs of the last non-fallback, finite plan (m/s, m/s, rad/s).
    age : int
        Sampling periods elapsed since ``plan`` was computed.
    anchor : array (3,) or None
        p*: the nominal end position (m) of the last *accepted* plan (None before the first).
    tracking : bool
        False while ``plan`` is a recovery plan (accepted for safety alone: tracking not in force).
    """

    plan: np.ndarray | None = None
    age: int = 0
    anchor: np.ndarray | None = None
    tracking: bool = True

    def remember(self, plan: np.ndarray, fallback: bool, accepted: bool = False, end: np.ndarray | None = None,
                 tracking: bool = True) -> bool:
        """Keep ``plan`` (N, 3) of a usable result when it is a good one; return the result's ``fallback`` flag.

        ``accepted`` (it passed :func:`tubekit.loop.plan_check.check_plan`) makes any finite plan a good
        one; ``end`` (its nominal end state, m and rad) then becomes the backup's anchor; ``tracking`` False
        marks a recovery plan.
        """
        plan = np.asarray(plan, dtype=float)
        if (accepted or not fallback) and plan.ndim == 2 and np.all(np.isfinite(plan)):
            self.plan, self.age, self.tracking = plan, 0, bool(tracking)
            if accepted and end is not None:
                self.anchor = np.asarray(end, dtype=float)[:3].copy()
        else:
            self.age += 1
        return bool(fallback)

    @property
    def exhausted(self) -> bool:
        """True when there is no plan left to replay (none yet, or older than its length)."""
        return self.plan is None or self.age >= len(self.plan)

    def replacement(self) -> np.ndarray:
        """v̂ (3,) replacing an unusable result: the last good plan shifted by its age, else zero.

        Zero is today's answer without a backup; the loop runs the backup law instead whenever
        the tightening has one (check :attr:`exhausted`).
        """
        self.age += 1
        if self.plan is not None and self.age < len(self.plan):
            return self.plan[self.age].copy()
        return ZERO_INPUT.copy()
