"""Search the verification region: which (e_o_max, e_d_max) certify a scenario.

:func:`search_region` certifies the scenario with ``region.e_o_max`` and ``region.e_d_max``
replaced by every point of a fixed grid (default e_o_max in 0.3 .. 0.9, e_d_max in
1.5 .. 6 m; points with e_d_max <= epsilon are skipped and reported as such) and keeps
every verdict with its first failed condition; when the scenario's own certificate fails a condition no
region can remove (:func:`region_independent_failures`) it says so at once and searches nothing. The best
certified point is the one
with the largest e_o_max, then the largest e_d_max (the widest region that certifies).
The grid is fixed, so the search is deterministic and its cost is a number of
certificates, never seconds.
"""

from __future__ import annotations

import collections
import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.jsonable import to_jsonable
from tubekit.scenario import Scenario

from verify.certificate.certify import certify, resolve_law

__all__ = ["RegionTrial", "RegionSearchResult", "search_region", "region_independent_failures", "E_O_MAX_GRID",
           "E_D_MAX_GRID"]

#: Conditions whose need (rhs) no region changes, by the command limit that must meet it: the necessary keep-ups
#: and, where step 17 does not cover the design, the yaw screen; they read V-bar <= V, so V below the need fails
#: them for every region.
_NEED_OF_LIMIT = {"keep_up[u]": "u_max", "keep_up[w]": "w_max", "yaw_budget": "r_max"}

#: Default grid of region.e_o_max (dimensionless, |e_o| = |sin(psi - theta)|).
E_O_MAX_GRID: tuple[float, ...] = (0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)
#: Default grid of region.e_d_max (m).
E_D_MAX_GRID: tuple[float, ...] = (1.5, 2.0, 3.0, 4.0, 5.0, 6.0)


@dataclass(frozen=True)
class RegionTrial:
    """One grid point: its verdict and the first failed condition ('' when certified)."""

    e_o_max: float
    e_d_max: float
    certified: bool
    first_failure: str

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class RegionSearchResult:
    """Outcome of :func:`search_region`: every trial, in grid order (e_o_max outer, e_d_max inner)."""

    scenario_name: str
    law: str
    epsilon: float
    tried: tuple[RegionTrial, ...]
    blocked_by: tuple[str, ...] = ()

    @property
    def certified(self) -> list[RegionTrial]:
        """The trials that certify."""
        return [t for t in self.tried if t.certified]

    @property
    def best(self) -> RegionTrial | None:
        """Largest e_o_max, then largest e_d_max, among the certified (None: none certifies)."""
        return max(self.certified, key=lambda t: (t.e_o_max, t.e_d_max), default=None)

    def to_dict(self) -> dict:
        """Strict-JSON-ready dict."""
        best = self.best
        return to_jsonable({"scenario": self.scenario_name, "law": self.law, "epsilon": self.epsilon,
                            "any_certified": best is not None, "best": None if best is None else best.to_dict(),
                            "certified": [t.to_dict() for t in self.certified],
                            "tried": [t.to_dict() for t in self.tried], "blocked_by": list(self.blocked_by)})

    def summary(self) -> str:
        """A table of verdicts (e_o_max rows, e_d_max columns) with the first failures, then the best point."""
        head = (f"tubekit certify --search-region: scenario '{self.scenario_name}', law '{self.law}', "
                f"epsilon = {self.epsilon:g} m")
        if self.blocked_by:
            return "\n".join([head, "  no region can help, nothing searched (none certifies):",
                              *(f"    {b}" for b in self.blocked_by)])
        eds = sorted({t.e_d_max for t in self.tried})
        rows = {eo: {t.e_d_max: _verdict(t) for t in self.tried if t.e_o_max == eo}
                for eo in sorted({t.e_o_max for t in self.tried})}
        width = max(14, *(len(v) for row in rows.values() for v in row.values()))
        lines = [head, "  e_o_max \\ e_d_max [m] | " + " | ".join(f"{e:>{width}g}" for e in eds)]
        for eo, row in rows.items():
            lines.append(f"  {eo:21g} | " + " | ".join(f"{row.get(e, '-'):>{width}s}" for e in eds))
        counts = collections.Counter(t.first_failure for t in self.tried if not t.certified)
        if counts:
            lines.append("  first failures: " + ", ".join(f"{name} ({n})" for name, n in counts.most_common()))
        best = self.best
        lines.append(f"  tried {len(self.tried)}, certified {len(self.certified)}")
        lines.append("  best: " + ("none certifies" if best is None else
                                   f"e_o_max = {best.e_o_max:g}, e_d_max = {best.e_d_max:g} m"))
        return "\n".join(lines)


def _verdict(trial: RegionTrial) -> str:
    """A grid cell's text: ``certified``, the first failed condition, or ``skipped`` (its reason: the failures'
    line)."""
    if trial.certified:
        return "certified"
    return "skipped" if trial.first_failure.startswith("skipped") else trial.first_failure


def _grid(field: str, values, upper: float | None) -> tuple[float, ...]:
    """Validated grid: finite numbers > 0 (and < ``upper`` when given)."""
    try:
        grid = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ConfigError(field, "a list of numbers", values) from None
    bad = [v for v in grid if not math.isfinite(v) or v <= 0 or (upper is not None and v >= upper)]
    if not grid or bad:
        limit = f" and < {upper:g}" if upper is not None else ""
        raise ConfigError(field, f"a non-empty list of numbers > 0{limit}", list(values))
    return tuple(np.unique(grid))


def region_independent_failures(scenario: Scenario, law: str) -> tuple[str, ...]:
    """The failures of ``scenario``'s own certificate that no region can remove, one line each (empty: searching
    may help).

    ``keep_up[u]``, ``keep_up[w]`` and ``yaw_budget`` compare V-bar = V - kappa-bar <= V with a need (target speed +
    omega-bar, omega-bar_xy / epsilon) that the region does not enter; where the command limit V itself is below
    the need, every region fails the condition.
    """
    cert = certify(scenario, law)
    out = []
    for c in cert.failures:
        limit = _NEED_OF_LIMIT.get(c.condition)
        if limit is None or c.rhs is None:
            continue
        value = float(getattr(scenario.limits, limit))
        if value < float(c.rhs):
            out.append(f"{c.condition}: limits.{limit} = {value:g} < {float(c.rhs):.6g} needed "
                       f"({c.inequality.split('>=', 1)[-1].split(' (')[0].strip()}), whatever the region")
    return tuple(out)


def search_region(scenario: Scenario, law: str | None = None, *, e_o_max=E_O_MAX_GRID,
                  e_d_max=E_D_MAX_GRID) -> RegionSearchResult:
    """Certify ``scenario`` on every (e_o_max, e_d_max) of the grid (module doc).

    Parameters
    ----------
    scenario : Scenario
        Base scenario; every other field is kept.
    law : str, optional
        Ancillary law; default the scenario's.
    e_o_max : sequence of float
        Values of region.e_o_max, each in (0, 1).
    e_d_max : sequence of float
        Values of region.e_d_max (m), each > 0; those <= epsilon are skipped.

    Returns
    -------
    RegionSearchResult
    """
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.scenario.Scenario", type(scenario).__name__)
    law = resolve_law(scenario.controller.law if law is None else law)
    eo_grid = _grid("e_o_max", e_o_max, 1.0)
    ed_grid = _grid("e_d_max", e_d_max, None)
    blocked = region_independent_failures(scenario, law)
    if blocked:
        return RegionSearchResult(scenario_name=scenario.name, law=law, epsilon=scenario.epsilon, tried=(),
                                  blocked_by=blocked)
    tried = []
    for eo in eo_grid:
        for ed in ed_grid:
            if ed <= scenario.epsilon:
                tried.append(RegionTrial(eo, ed, False, f"skipped: e_d_max <= epsilon = {scenario.epsilon:g}"))
                continue
            region = dataclasses.replace(scenario.region, e_o_max=eo, e_d_max=ed)
            cert = certify(scenario.with_changes(region=region), law)
            first = cert.failures[0].condition if cert.failures else ""
            tried.append(RegionTrial(eo, ed, cert.certified, first))
    return RegionSearchResult(scenario_name=scenario.name, law=law, epsilon=scenario.epsilon, tried=tuple(tried))
