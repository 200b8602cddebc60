"""No backup law: safety as a consequence of the tracking theorem (``controller.backup = "none"``).

The safe tier's usual argument is a backup law that holds a safe set about the end of the last accepted plan, so
that a period without an accepted plan is safe. That law has a footprint (its safe set, 3–12 m on the shipped
vehicles) which every plan must keep clear of every obstacle at its end, and on the dynamic plant a command the
velocity loop is charged for. When the tracking theorem holds (``docs/verify.md`` step 17), a plan is accepted at
every period for all time, so the backup never runs, and every safe promise follows from the plans themselves (each
is checked against the obstacles, the workspace and V̄ with the tube's margins). :class:`NoBackup` states that
design: it is registered as a backup law so that the contract stays one (the protocol, the certificate's JSON, the
recheck), but its certificate (:mod:`verify.backup.none`) gives the safe tier **only together with the tracking
tier** (:func:`verify.theorem.tiers.tier_conditions`), and its safe set is a point (1 mm): the terminal condition
asks only that the plan's end keeps the vehicle clear.

If a run ever reaches a period without an accepted plan (a premise broken: a current above its bound, a hull
outside the box), the law keeps the last applied command (the vehicle coasts), and the run's ``plan_available``
promise reports the broken promise: nothing is claimed for that case.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from tubekit.model.backup import NoSway, register_backup_law

__all__ = ["NoBackup", "NO_BACKUP_KIND", "POINT_SET"]

#: The kind name (``controller.backup = "none"``).
NO_BACKUP_KIND = "none"
#: The radius and depth band (m) of the point safe set the certificate stores (a SafeSet must be positive).
POINT_SET = 1e-3


@register_backup_law
@dataclass(frozen=True)
class NoBackup(NoSway):
    """No backup law (module doc): the command applied last is kept, and the certificate claims nothing for it."""

    kind: ClassVar[str] = NO_BACKUP_KIND

    @property
    def blends(self) -> bool:
        """True: the command is continuous at the hand-over (it is the last command)."""
        return True

    @property
    def bounds(self) -> tuple[float, float, float]:
        """(0, 0, 0): the law adds no command of its own (it keeps the last one, which lies in V)."""
        return 0.0, 0.0, 0.0

    @property
    def min_surge(self) -> float:
        """0 (m/s): not read (the law keeps the last command; the certificate never relies on it)."""
        return 0.0

    @property
    def handover_command(self) -> tuple[float, float, float]:
        """(0, 0, 0) (not read: the law blends)."""
        return 0.0, 0.0, 0.0

    def within(self, u_max: float, w_max: float, r_max: float) -> bool:
        """True: the last command lies in V."""
        return True

    def command(self, state: tuple[float, float, float, float], anchor: tuple[float, float, float],
                elapsed: float = math.inf, start: tuple[float, float, float] = (0.0, 0.0, 0.0)
                ) -> tuple[float, float, float]:
        """``start``: the command applied at the hand-over, kept (m/s, m/s, rad/s)."""
        return float(start[0]), float(start[1]), float(start[2])

    def to_dict(self) -> dict[str, Any]:
        """``{"kind": "none"}``."""
        return {"kind": self.kind}
