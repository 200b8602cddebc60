"""Design search: the certifiable envelope of a scenario for one ancillary law.

For a grid of epsilon values (the lower end of e_d) the search finds, by
bisection on certified/not-certified,

* ``omega_max(epsilon)``: the largest disturbance bound omega-bar that certifies
  (everything else as in the scenario);
* ``speed_max(epsilon)``: the largest horizontal target speed that certifies at the
  scenario's omega-bar (the trajectory's velocity bounds scaled together);

and, at the scenario's epsilon, for a grid of target speeds,

* ``omega_max_by_speed``: the largest certifiable omega-bar (the speed/disturbance
  trade-off: what would certify the scenario at its own epsilon and region);

and from these the headline numbers: the largest omega-bar at the scenario's
epsilon, the smallest epsilon at the scenario's omega-bar (refined by bisection
between grid points), and the largest target speed at the scenario's epsilon and
omega-bar. A 2-D grid (epsilon x omega-bar) of certificate outcomes is kept
for the plot. Every point is a full :func:`verify.certify` call on a copy of the
region; bounds that do not depend on the varied quantity are reused from a cache,
so a bisection step in omega-bar costs only the certificate algebra.

Bisection assumes certification is monotone in the bisected quantity between
the bracketing points (it is in omega-bar and speed: every bound and condition
worsens as they grow); it is reported as such.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario

from .certificate import certify
from .region import Region

__all__ = ["EnvelopeResult", "envelope", "plot_envelope"]


@dataclass(frozen=True)
class EnvelopeResult:
    """Outcome of :func:`envelope` (units: m, m/s).

    Attributes
    ----------
    scenario_name, law : str
        What was searched.
    epsilon, omega_bar, speed : float
        The scenario's own epsilon, disturbance bound and horizontal target speed.
    certified_at_scenario : bool
        Whether the scenario itself certifies.
    max_omega_bar : float or None
        Largest certifiable omega-bar at the scenario's epsilon (None: none, not even 0).
    min_epsilon : float or None
        Smallest certifiable epsilon at the scenario's omega-bar over the searched range.
    max_speed : float or None
        Largest certifiable target speed at the scenario's epsilon and omega-bar.
    eps_grid : array (n,)
        Epsilon grid.
    omega_max : array (n,)
        Largest certifiable omega-bar per grid epsilon (NaN: none).
    speed_max : array (n,)
        Largest certifiable target speed per grid epsilon at the scenario's omega-bar (NaN: none).
    omega_grid : array (m,)
        omega-bar values of the 2-D grid.
    certified_grid : bool array (n, m)
        Certificate outcome at (eps_grid[i], omega_grid[j]).
    speed_grid : array (k,)
        Target speeds of the trade-off curve (m/s).
    omega_max_by_speed : array (k,)
        Largest certifiable omega-bar per target speed at the scenario's epsilon (NaN: none).
    failures_at_scenario : list of str
        Failed condition names of the scenario itself.
    failures_by_eps : list of list of str
        Failed conditions per grid epsilon at the scenario's omega-bar and speed.
    tolerance : float
        Relative bisection tolerance.
    elapsed_s : float
        Wall time (s).
    """

    scenario_name: str
    law: str
    epsilon: float
    omega_bar: float
    speed: float
    certified_at_scenario: bool
    max_omega_bar: float | None
    min_epsilon: float | None
    max_speed: float | None
    eps_grid: np.ndarray
    omega_max: np.ndarray
    speed_max: np.ndarray
    omega_grid: np.ndarray
    certified_grid: np.ndarray
    speed_grid: np.ndarray = field(default_factory=lambda: np.zeros(0))
    omega_max_by_speed: np.ndarray = field(default_factory=lambda: np.zeros(0))
    failures_at_scenario: list = field(default_factory=list)
    failures_by_eps: list = field(default_factory=list)
    tolerance: float = 1e-3
    elapsed_s: float = 0.0

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN as None)."""
        def arr(a: np.ndarray) -> list:
            return [None if not math.isfinite(float(x)) else float(x) for x in np.ravel(a)]

        return {
            "scenario": self.scenario_name, "law": self.law, "epsilon": self.epsilon, "omega_bar": self.omega_bar,
            "speed": self.speed, "certified_at_scenario": self.certified_at_scenario,
            "max_omega_bar": self.max_omega_bar, "min_epsilon": self.min_epsilon, "max_speed": self.max_speed,
            "eps_grid": arr(self.eps_grid), "omega_max": arr(self.omega_max), "speed_max": arr(self.speed_max),
            "omega_grid": arr(self.omega_grid),
            "certified_grid": [[bool(x) for x in row] for row in self.certified_grid],
            "speed_grid": arr(self.speed_grid), "omega_max_by_speed": arr(self.omega_max_by_speed),
            "failures_at_scenario": list(self.failures_at_scenario),
            "failures_by_eps": [list(x) for x in self.failures_by_eps], "tolerance": self.tolerance,
            "elapsed_s": round(self.elapsed_s, 3),
        }

    def summary(self) -> str:
        """Human-readable envelope."""
        def f(x: float | None, unit: str) -> str:
            return "none certifies" if x is None else f"{x:.4g} {unit}"

        lines = [f"tubekit envelope: scenario '{self.scenario_name}', law '{self.law}'",
                 f"  scenario: epsilon = {self.epsilon:.4g} m, omega_bar = {self.omega_bar:.4g} m/s, "
                 f"target speed = {self.speed:.4g} m/s: "
                 + ("certified" if self.certified_at_scenario else
                    "not certified (" + ", ".join(self.failures_at_scenario) + ")"),
                 f"  largest omega_bar at epsilon = {self.epsilon:.4g} m: {f(self.max_omega_bar, 'm/s')}",
                 f"  smallest epsilon at omega_bar = {self.omega_bar:.4g} m/s: {f(self.min_epsilon, 'm')}"
                 f" (searched [{self.eps_grid[0]:.4g}, {self.eps_grid[-1]:.4g}] m)",
                 f"  largest target speed at the scenario's epsilon and omega_bar: {f(self.max_speed, 'm/s')}",
                 "  per epsilon: epsilon [m] | largest omega_bar [m/s] | largest target speed [m/s] "
                 "(at the scenario's omega_bar) | failed at the scenario's omega_bar and speed"]
        fb = self.failures_by_eps or [[] for _ in self.eps_grid]
        for e, w, s, fl in zip(self.eps_grid, self.omega_max, self.speed_max, fb):
            ws = "-" if not math.isfinite(w) else f"{w:.4g}"
            ss = "-" if not math.isfinite(s) else f"{s:.4g}"
            lines.append(f"    {e:9.4g} | {ws:>9s} | {ss:>9s} | {', '.join(fl) if fl else 'certified'}")
        lines.append(f"  at epsilon = {self.epsilon:.4g} m: target speed [m/s] -> largest omega_bar [m/s]")
        for s, w in zip(self.speed_grid, self.omega_max_by_speed):
            lines.append(f"    {s:9.4g} -> {'-' if not math.isfinite(w) else f'{w:.4g}'}")
        lines.append(f"  bisection tolerance {self.tolerance:.0e} (relative); elapsed {self.elapsed_s:.1f} s")
        return "\n".join(lines)


class _Oracle:
    """certified(region) with the scenario, law and branch-and-bound settings fixed."""

    def __init__(self, scenario: Scenario, law: str, gap: float, budget: float) -> None:
        self.scenario, self.law, self.gap, self.budget = scenario, law, gap, budget
        self.calls = 0

    def __call__(self, region: Region) -> bool:
        self.calls += 1
        return certify(self.scenario, self.law, region=region, time_budget_s=self.budget, gap=self.gap).certified


def _bisect_max(ok, lo: float, hi: float, tol: float) -> float | None:
    """Largest x in [lo, hi] with ok(x), assuming ok is monotone decreasing; None if not ok(lo)."""
    if not ok(lo):
        return None
    if ok(hi):
        return hi
    while hi - lo > tol * max(abs(hi), 1e-12):
        mid = 0.5 * (lo + hi)
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return lo


def _with_speed(region: Region, speed: float, base_speed: float) -> Region:
    k = speed / base_speed if base_speed > 0 else 0.0
    return region.replace(pd_dot_max=tuple(k * x for x in region.pd_dot_max), pd_dot_xy_max=speed)


def envelope(scenario: Scenario, law: str | None = None, *, quick: bool = False, n_eps: int | None = None,
             n_omega: int | None = None, eps_range: tuple[float, float] | None = None,
             time_budget_s: float | None = None, gap: float | None = None, tol: float = 1e-3) -> EnvelopeResult:
    """The certifiable envelope of ``scenario`` for ``law`` (see module doc).

    Parameters
    ----------
    scenario : Scenario
        Base scenario.
    law : str, optional
        Ancillary law; default ``scenario.controller.law``.
    quick : bool
        Coarser grids, looser gap (10 %) and shorter budgets.
    n_eps, n_omega : int, optional
        Grid sizes (default 10 x 24, quick 6 x 12).
    eps_range : (lo, hi), optional
        Epsilon search range (m); default [0.02, 0.6] * e_d_max (plus the scenario's epsilon).
    time_budget_s : float, optional
        Branch-and-bound budget per bound (s); default 1.0 (quick 0.5).
    gap : float, optional
        Target relative gap of the bounds; default 0.05 (quick 0.10). Looser gaps
        give smaller (still rigorous) envelopes.
    tol : float
        Relative bisection tolerance.
    """
    t0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.scenario.Scenario", type(scenario).__name__)
    law = scenario.controller.law if law is None else law
    n_eps = n_eps if n_eps is not None else (6 if quick else 10)
    n_omega = n_omega if n_omega is not None else (12 if quick else 24)
    if n_eps < 2 or n_omega < 2:
        raise ConfigError("n_eps/n_omega", "grid sizes >= 2", (n_eps, n_omega))
    gap = gap if gap is not None else (0.10 if quick else 0.05)
    budget = time_budget_s if time_budget_s is not None else (0.5 if quick else 1.0)
    if not (0 < tol < 0.5):
        raise ConfigError("tol", "a number in (0, 0.5)", tol)
    oracle = _Oracle(scenario, law, gap, budget)
    base = Region.from_scenario(scenario)
    eps0, om0, sp0 = base.e_d[0], base.omega_bar, base.pd_dot_xy_max
    ed_max = base.e_d[1]
    lo_e, hi_e = eps_range if eps_range is not None else (0.02 * ed_max, 0.6 * ed_max)
    if not (0 < lo_e < hi_e < ed_max):
        raise ConfigError("eps_range", f"0 < lo < hi < e_d_max = {ed_max}", eps_range)
    eps_grid = np.unique(np.concatenate([np.geomspace(lo_e, hi_e, n_eps), [eps0]]))
    v = base.v_max
    om_hi = max(v[0], v[1])             # beyond this the real vehicle cannot beat the current
    sp_hi = v[0]                        # nor can it keep up with the target

    base_cert = certify(scenario, law, region=base, time_budget_s=budget, gap=gap)
    fails = [fl["condition"] for fl in base_cert.failures] + [f"{n} (not evaluated)" for n in base_cert.not_evaluated]

    omega_max = np.full(len(eps_grid), np.nan)
    speed_max = np.full(len(eps_grid), np.nan)
    fails_by_eps = []
    for i, e in enumerate(eps_grid):
        reg_e = base.replace(e_d=(float(e), ed_max))
        ce = certify(scenario, law, region=reg_e, time_budget_s=budget, gap=gap)
        fails_by_eps.append([fl["condition"] for fl in ce.failures])
        w = _bisect_max(lambda x: oracle(reg_e.replace(omega_bar=x)), 0.0, om_hi, tol)
        omega_max[i] = np.nan if w is None else w
        s = _bisect_max(lambda x: oracle(_with_speed(reg_e, x, sp0)), 0.0, sp_hi, tol) if sp0 > 0 else None
        speed_max[i] = np.nan if s is None else s
    top = max(om0, float(np.nanmax(omega_max)) if np.any(np.isfinite(omega_max)) else 0.0)
    omega_grid = np.linspace(0.0, min(om_hi, 1.5 * top) if top > 0 else om_hi, n_omega)
    cert_grid = np.zeros((len(eps_grid), n_omega), dtype=bool)
    for i, e in enumerate(eps_grid):
        reg_e = base.replace(e_d=(float(e), ed_max))
        for j, x in enumerate(omega_grid):
            cert_grid[i, j] = oracle(reg_e.replace(omega_bar=float(x)))

    # speed grid up to the largest speed that certifies without disturbance (if any)
    reg0 = base.replace(omega_bar=0.0)
    s_top = _bisect_max(lambda x: oracle(_with_speed(reg0, x, sp0)), 0.0, sp_hi, tol) if sp0 > 0 else None
    speed_grid = np.linspace(0.0, s_top if s_top else sp_hi, n_omega // 2 + 1)
    om_by_speed = np.full(len(speed_grid), np.nan)
    for i, sp_ in enumerate(speed_grid):
        reg_s = _with_speed(base, float(sp_), sp0) if sp0 > 0 else base
        w = _bisect_max(lambda x: oracle(reg_s.replace(omega_bar=x)), 0.0, om_hi, tol)
        om_by_speed[i] = np.nan if w is None else w
        if sp0 <= 0:
            break

    k0 = int(np.argmin(np.abs(eps_grid - eps0)))
    max_omega = None if not math.isfinite(omega_max[k0]) else float(omega_max[k0])
    max_speed = None if not math.isfinite(speed_max[k0]) else float(speed_max[k0])

    # smallest epsilon certifying at the scenario's omega-bar: first certified grid point, then bisect down
    ok_e = [oracle(base.replace(e_d=(float(e), ed_max))) for e in eps_grid]
    min_eps = None
    if any(ok_e):
        i = ok_e.index(True)
        min_eps = float(eps_grid[i])
        if i > 0:
            lo, hi = float(eps_grid[i - 1]), float(eps_grid[i])
            while hi - lo > tol * hi:
                mid = 0.5 * (lo + hi)
                if oracle(base.replace(e_d=(mid, ed_max))):
                    hi = mid
                else:
                    lo = mid
            min_eps = hi
    return EnvelopeResult(
        scenario_name=scenario.name, law=law, epsilon=eps0, omega_bar=om0, speed=sp0,
        certified_at_scenario=base_cert.certified, max_omega_bar=max_omega, min_epsilon=min_eps,
        max_speed=max_speed, eps_grid=eps_grid, omega_max=omega_max, speed_max=speed_max, omega_grid=omega_grid,
        certified_grid=cert_grid, speed_grid=speed_grid, omega_max_by_speed=om_by_speed,
        failures_at_scenario=fails, failures_by_eps=fails_by_eps, tolerance=tol,
        elapsed_s=time.perf_counter() - t0)


def plot_envelope(result: EnvelopeResult, path: str | Path) -> Path:
    """Plot the envelope to ``path`` (PNG/PDF/SVG by extension); Agg backend, never shown.

    Left: certified (epsilon, omega-bar) grid points and the omega_max(epsilon) curve,
    with the scenario marked. Middle: largest target speed per epsilon at the
    scenario's omega-bar. Right: largest omega-bar per target speed at the
    scenario's epsilon.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    if not path.parent.exists():
        raise ConfigError("--plot", "a file in an existing directory", str(path))
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(15, 4.2))
    E, W = np.meshgrid(result.eps_grid, result.omega_grid, indexing="ij")
    ax1.scatter(E[result.certified_grid], W[result.certified_grid], s=10, c="tab:green", label="certified")
    ax1.scatter(E[~result.certified_grid], W[~result.certified_grid], s=6, c="lightgray", label="not certified")
    ax1.plot(result.eps_grid, result.omega_max, "-", c="tab:green", label="largest certifiable omega_bar")
    ax1.plot([result.epsilon], [result.omega_bar], "r*", ms=12, label="scenario")
    ax1.set_xscale("log")
    ax1.set_xlim(result.eps_grid[0] * 0.9, result.eps_grid[-1] * 1.1)
    ax1.set_xlabel("epsilon = min e_d [m]")
    ax1.set_ylabel("omega_bar [m/s]")
    ax1.set_title(f"certifiable envelope, law '{result.law}'")
    ax1.legend(fontsize=7)
    ax2.plot(result.eps_grid, result.speed_max, "o-", c="tab:blue", ms=3,
             label=f"largest target speed at omega_bar = {result.omega_bar:.3g}")
    ax2.axhline(result.speed, c="r", ls="--", lw=1, label=f"scenario speed {result.speed:.3g} m/s")
    ax2.set_xscale("log")
    ax2.set_xlim(result.eps_grid[0] * 0.9, result.eps_grid[-1] * 1.1)
    ax2.set_xlabel("epsilon = min e_d [m]")
    ax2.set_ylabel("horizontal target speed [m/s]")
    ax2.set_title(result.scenario_name)
    ax2.legend(fontsize=7)
    ax3.fill_between(result.speed_grid, 0.0, np.nan_to_num(result.omega_max_by_speed, nan=0.0),
                     color="tab:green", alpha=0.3, step=None, label="certifiable")
    ax3.plot(result.speed_grid, result.omega_max_by_speed, "o-", c="tab:green", ms=3)
    ax3.plot([result.speed], [result.omega_bar], "r*", ms=12, label="scenario")
    ax3.set_xlabel("horizontal target speed [m/s]")
    ax3.set_ylabel("largest certifiable omega_bar [m/s]")
    ax3.set_title(f"at epsilon = {result.epsilon:.3g} m")
    ax3.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
