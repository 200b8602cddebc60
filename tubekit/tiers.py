"""The two tiers of promise a certificate gives, as one typed value.

* **safe** — no collision, inside the workspace, inputs never clipped, for all time (premise: the
  disturbance bound);
* **tracking** — the error stays in its region and in the tube while a plan is followed.

Every condition the safe tier depends on is also one the tracking tier depends on
(``verify.theorem.tiers.tier_conditions``), so tracking without safety cannot be given:
:class:`Tiers` refuses it. ``verify`` decides the tiers; the loop, the promises and the reports
only read them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from tubekit.exceptions import ConfigError

__all__ = ["Tiers"]


@dataclass(frozen=True)
class Tiers:
    """Which tiers a certificate gives (both False: none, the best-effort or baseline run).

    Attributes
    ----------
    safe : bool
        Safety for all time is certified.
    tracking : bool
        Tracking inside the tube is certified (implies ``safe``).
    """

    safe: bool = False
    tracking: bool = False

    def __post_init__(self) -> None:
        for name in ("safe", "tracking"):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(f"tiers.{name}", "true or false", getattr(self, name))
        if self.tracking and not self.safe:
            raise ConfigError("tiers.tracking", "false when the safe tier is not given (tracking implies safety)",
                              self.tracking)

    @property
    def safe_only(self) -> bool:
        """True when the safe tier is given and tracking is not (then σ = 0: the safe-only design)."""
        return self.safe and not self.tracking

    @property
    def both(self) -> bool:
        """True when both tiers are given (the certificate is fully certified)."""
        return self.tracking

    def label(self) -> str:
        """``"both tiers"``, ``"safe tier only"`` or ``"no tier"``."""
        return "both tiers" if self.tracking else "safe tier only" if self.safe else "no tier"

    def to_dict(self) -> dict[str, bool]:
        """``{"safe": bool, "tracking": bool}``."""
        return {"safe": self.safe, "tracking": self.tracking}

    @classmethod
    def from_dict(cls, d: Any, where: str = "tiers") -> "Tiers":
        """Inverse of :meth:`to_dict` (ConfigError naming ``where.<key>`` when a key is missing or not a bool)."""
        if not isinstance(d, dict):
            raise ConfigError(where, "a table with 'safe' and 'tracking'", d)
        values = {}
        for name in ("safe", "tracking"):
            if not isinstance(d.get(name), bool):
                raise ConfigError(f"{where}.{name}", "true or false", d.get(name, "missing"))
            values[name] = d[name]
        return cls(**values)
