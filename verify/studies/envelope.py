"""The certified frontier of a scenario beside the physical-necessity frontier, at one epsilon.

For each target speed s (m/s) the search builds a variant of the scenario whose
trajectory moves at horizontal speed s (a circle's or helix's rate scaled to
s / radius, a line's horizontal velocity scaled to s) and whose horizontal current
amplitude is a (m/s: ``disturbance.amplitude`` x and y both set to a; the vertical
amplitude, the constant current and the sway model are kept as they are), and asks
:func:`verify.certify` for a verdict. Two frontiers, both in

    omega_bar_xy = a + ||c_xy|| + gamma_bar,   gamma_bar = sway gain u_max r_max + sway amplitude

(the certificate's horizontal disturbance bound, :func:`verify.theorem.design.disturbance_bounds`:
current amplitude plus constant current plus the sway the model produces over V):

* **certified**: the largest omega_bar_xy that certifies, found by bisection on the
  amplitude a with a fixed number of steps (a work unit: the result is the same on any
  machine). The certificate is monotone in the disturbance (every bound grows with it),
  so the bracket [certified, refuted] holds the edge;
* **necessary** (any controller, any tube): keep-up needs u_max >= s + omega_bar_xy (a current that holds
  against the target's motion outruns a slower vehicle), so omega_bar_xy <= u_max - s. The bearing rate
  omega_bar_xy / epsilon <= r_max that earlier versions added is not necessary: no plan need go to e_d = epsilon,
  and where step 17 covers the design the vehicle turns with the line of sight at X_f's distance
  (``yaw_budget`` is a screen, ``docs/verify.md`` §3; a counterexample is pinned in
  ``tests/test_verify_theorem_tiers.py``).

On the dynamic plant (``[plant] kind = "dynamic"``) each point is a dynamic certificate: omega_bar_xy is its
tracking design's (current + the sway loop's or the hull's sway + the velocity loop's error under plans alone,
the plans-only bound of ``docs/verify.md`` step 17d, derived from the vehicle), ``gamma`` is the part that is not
current at zero current, and the certified frontier is that omega_bar_xy at the certified amplitude. The
bisection assumes the verdict monotone in the amplitude; on the dynamic plant the backup's design search is
not proved monotone, so there each point is a certificate of its own and the edge between them a bracket of
two verdicts, not a proof that every amplitude below certifies.

A point *certifies* when the safe tier and every condition of the tracking tier hold, except the tracking
theorem's conditions on the geometry of one mission — the start (``initial_terminal``), the obstacles along
the path (``path_*``) and the plans' rate limit (``terminal_rate``), :data:`GEOMETRY_CONDITIONS` — which a
speed and a current do not decide, and, under rate-limited plans once a row face fails (``terminal_rate[...]``),
the terminal law's conditions (``terminal_*``: its row faces are sized by the plans' rates, which the envelope
does not vary; ``docs/verify.md`` step 17c) (:func:`frontier_verdict`).

The ratio certified / necessary per speed (1 = the certificate loses nothing to
physics) and its min and median summarise the conservatism. The scenario's own point
(its target speed and its omega_bar_xy) is certified as it is, at the envelope's epsilon,
and its verdict kept beside the frontiers (``own_*`` fields). The plot is drawn by
the application layer (:func:`tubekit.app.plots.plot_envelope`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.jsonable import to_jsonable
from tubekit.scenario import Scenario
from tubekit.model.trajectory import Circle, Line, Trajectory
from tubekit.validation import finite, positive

from verify.certificate.artefact import Certificate
from verify.certificate.certify import certify, resolve_law
from verify.kernel.intervals import upper
from verify.theorem.design import disturbance_bounds

__all__ = ["EnvelopeResult", "envelope", "necessary_omega", "scenario_at", "frontier_verdict", "GEOMETRY_CONDITIONS", "REFERENCE_POINTS",
           "BISECTION_STEPS"]

#: Bisection steps on the current amplitude (full, quick): the bracket is top / 2**steps wide.
BISECTION_STEPS: dict[bool, int] = {False: 14, True: 9}

#: Operating points marked on the plot: (label, target speed m/s, omega_bar_xy m/s, epsilon m).
REFERENCE_POINTS: tuple[tuple[str, float, float, float], ...] = (
    ("paper Section VI", 0.377, 0.12, 0.1),
    ("paper_currents", 0.19, 0.12, 0.5),
)


@dataclass(frozen=True)
class EnvelopeResult:
    """Outcome of :func:`envelope` (units: m, m/s, rad/s).

    Attributes
    ----------
    scenario_name, law : str
        What was searched.
    epsilon : float
        Lower bound of e_d used for every point (m).
    speeds : array (k,)
        Horizontal target speeds (m/s).
    certified_omega : array (k,)
        Largest certified omega_bar_xy per speed (m/s); NaN when not even a = 0 certifies.
    certified_amplitude, refuted_amplitude : array (k,)
        The bisection bracket on the horizontal current amplitude a (m/s): certify holds at the first,
        fails at the second (NaN: none certifies / the top of the search certified).
    necessary_omega : array (k,)
        u_max - s (m/s): the physical-necessity frontier (keep-up).
    first_failure : list of str
        The first failed condition at the refuted amplitude (or at a = 0 when none certifies).
    sigma_at_edge : array (k,)
        sigma (1/s) of the certified design at the certified amplitude (NaN: none certifies).
    gamma, current_offset : float
        gamma_bar (sway; on the dynamic plant: the sway (the hull's, or its sway loop's error) + loop error at zero current) and ||c_xy|| (constant
        current), both in omega_bar_xy (m/s).
    dynamic : bool
        The scenario's plant is the dynamic one (module doc).
    amplitude_z : float
        The vertical current amplitude kept for every point (m/s).
    limits : (3,)
        u_max, w_max, r_max.
    bisection_steps : int
        Steps per speed (the work unit).
    own_speed, own_omega : float
        The scenario's own horizontal target speed and omega_bar_xy (m/s; NaN: not recorded).
    own_current_xy : float
        Its horizontal current bound (m/s: amplitude and constant current; :attr:`own_current`).
    own_epsilon : float
        The scenario's own epsilon (m); its verdict below is at ``epsilon`` (the same unless ``eps`` was given).
    own_certified, own_safe : bool or None
        The scenario's verdict at ``epsilon``: the envelope's (:func:`frontier_verdict`), the safe tier (None: not
        recorded).
    own_failure : str
        Its first failed condition ("" when certified).
    """

    scenario_name: str
    law: str
    epsilon: float
    speeds: np.ndarray
    certified_omega: np.ndarray
    certified_amplitude: np.ndarray
    refuted_amplitude: np.ndarray
    necessary_omega: np.ndarray
    first_failure: list = field(default_factory=list)
    sigma_at_edge: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gamma: float = 0.0
    current_offset: float = 0.0
    amplitude_z: float = 0.0
    limits: tuple[float, float, float] = (0.4, 0.3, 0.5)
    bisection_steps: int = 14
    own_speed: float = math.nan
    own_omega: float = math.nan
    own_epsilon: float = math.nan
    own_certified: bool | None = None
    own_safe: bool | None = None
    own_failure: str = ""
    dynamic: bool = False
    own_current_xy: float = math.nan

    @property
    def own_current(self) -> float:
        """The scenario's horizontal current bound (m/s): as recorded (``own_current_xy``), else own omega_bar_xy
        minus the sway gamma_bar."""
        return self.own_current_xy if math.isfinite(self.own_current_xy) else self.own_omega - self.gamma

    def own_verdict(self) -> str:
        """The scenario's verdict in words: ``certified``, ``not certified (<first failure>; safe tier certified)``
        (the safe tier named when it holds) or ``not recorded``."""
        if self.own_certified is None:
            return "not recorded"
        if self.own_certified:
            return "certified"
        safe = "; safe tier certified" if self.own_safe else ""
        return f"not certified ({self.own_failure or 'no failure named'}{safe})"

    @property
    def ratio(self) -> np.ndarray:
        """certified / necessary per speed (0 where none certifies, NaN where nothing is necessary-feasible)."""
        cert = np.nan_to_num(self.certified_omega, nan=0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.necessary_omega > 0, cert / self.necessary_omega, np.nan)

    @property
    def ratio_min(self) -> float | None:
        """Smallest ratio over the speeds (None: no speed is physically feasible)."""
        r = self.ratio[np.isfinite(self.ratio)]
        return float(r.min()) if r.size else None

    @property
    def ratio_median(self) -> float | None:
        """Median ratio over the speeds (None: no speed is physically feasible)."""
        r = self.ratio[np.isfinite(self.ratio)]
        return float(np.median(r)) if r.size else None

    def certifies(self, speed: float, omega_xy: float) -> bool:
        """True if (speed, omega_xy) lies under the certified frontier at a searched speed (exact match, 1e-9)."""
        hit = np.flatnonzero(np.abs(self.speeds - speed) <= 1e-9)
        return bool(hit.size) and bool(omega_xy <= np.nan_to_num(self.certified_omega[hit[0]], nan=-1.0))

    def check(self) -> list[str]:
        """Sanity problems (empty list: none): a certified value above the necessity frontier is unsound."""
        problems = []
        for s, c, n in zip(self.speeds, self.certified_omega, self.necessary_omega):
            if math.isfinite(c) and c > n + 1e-9:
                problems.append(f"speed {s:.4g} m/s: certified omega_bar_xy {c:.6g} > necessary {n:.6g} m/s")
        for s, lo, hi in zip(self.speeds, self.certified_amplitude, self.refuted_amplitude):
            if math.isfinite(lo) and math.isfinite(hi) and not lo < hi:
                problems.append(f"speed {s:.4g} m/s: bracket [{lo:.6g}, {hi:.6g}] is empty")
        return problems

    def to_dict(self) -> dict:
        """Strict-JSON-ready dict (NaN as None)."""
        return to_jsonable({
            "scenario": self.scenario_name, "law": self.law, "epsilon": self.epsilon,
            "omega_bar_xy": ("the dynamic certificate's: current + sway + velocity-loop error (gamma: the part "
                             "that is not current, at zero current)" if self.dynamic else
                             "current amplitude a + ||c_xy|| + gamma_bar (sway: gain u_max r_max + amplitude)"),
            "dynamic": self.dynamic,
            "gamma": self.gamma, "current_offset": self.current_offset, "amplitude_z": self.amplitude_z,
            "limits": list(self.limits), "speeds": self.speeds, "certified_omega": self.certified_omega,
            "certified_amplitude": self.certified_amplitude, "refuted_amplitude": self.refuted_amplitude,
            "necessary_omega": self.necessary_omega, "ratio": self.ratio, "ratio_min": self.ratio_min,
            "ratio_median": self.ratio_median, "first_failure": list(self.first_failure),
            "sigma_at_edge": self.sigma_at_edge,
            "bisection_steps": self.bisection_steps, "problems": self.check(),
            "scenario_point": {"speed": self.own_speed, "omega_bar_xy": self.own_omega, "current": self.own_current,
                               "epsilon": self.own_epsilon, "certified": self.own_certified, "safe": self.own_safe,
                               "first_failure": self.own_failure},
        })

    def summary(self) -> str:
        """The frontier table and the ratio."""
        def num(x: float) -> str:
            return f"{x:.4f}" if math.isfinite(x) else "none"

        lines = [f"tubekit envelope: scenario '{self.scenario_name}', law '{self.law}', epsilon = {self.epsilon:g} m",
                 f"  omega_bar_xy = horizontal current amplitude + {self.current_offset:.4g} (constant) + "
                 + (f"sway + loop error (derived per certificate; {self.gamma:.4g} at zero current)"
                    if self.dynamic else f"gamma_bar {self.gamma:.4g} (sway)")
                 + f"; vertical amplitude kept at {self.amplitude_z:.4g} m/s",
                 f"  necessary: omega_bar_xy <= u_max - speed = {self.limits[0]:g} - speed (keep-up)",
                 "  speed [m/s] | certified omega_bar_xy [m/s] | necessary [m/s] | ratio | sigma [1/s] | first failure above",
                 ]
        sigmas = self.sigma_at_edge if len(self.sigma_at_edge) else np.full(len(self.speeds), np.nan)
        for s, c, n, r, sg, f in zip(self.speeds, self.certified_omega, self.necessary_omega, self.ratio, sigmas,
                                     self.first_failure):
            sig = f"{sg:.4g}" if math.isfinite(sg) else "-"
            lines.append(f"  {s:11.4f} | {num(c):>28s} | {num(n):>15s} | {num(r):>5s} | {sig:>11s} | {f or '-'}")
        rmin, rmed = self.ratio_min, self.ratio_median
        lines.append("  ratio certified / necessary: " + ("none (no speed is feasible)" if rmin is None else
                                                          f"min {rmin:.4f}, median {rmed:.4f}"))
        lines.append(f"  bisection: {self.bisection_steps} steps per speed on the amplitude (bracket in the JSON)")
        if self.own_certified is not None:
            lines.append(f"  your scenario: target {self.own_speed:.4g} m/s, current {self.own_current:.4g} m/s "
                         f"(omega_bar_xy {self.own_omega:.4g}) at epsilon {self.epsilon:g} m: {self.own_verdict()}")
        problems = self.check()
        if problems:
            lines.append("  SANITY PROBLEMS: " + "; ".join(problems))
        return "\n".join(lines)


def necessary_omega(speed: float, u_max: float) -> float:
    """Largest omega_bar_xy (m/s) physics admits at target speed ``speed`` (m/s): u_max - speed, keep-up (module
    doc; may be negative)."""
    return u_max - speed


def _trajectory_at_speed(trajectory: Trajectory, speed: float) -> Trajectory:
    """``trajectory`` moving at horizontal speed ``speed`` (m/s): a circle's rate, a line's xy velocity."""
    if isinstance(trajectory, Circle):  # Helix too: only the horizontal rate changes
        sign = -1.0 if trajectory.rate < 0 else 1.0
        return dataclasses.replace(trajectory, rate=sign * speed / trajectory.radius)
    if isinstance(trajectory, Line):
        v = np.asarray(trajectory.direction_velocity, dtype=float)
        norm = math.hypot(v[0], v[1])
        if norm == 0:
            raise ConfigError("trajectory.velocity", "a line with a horizontal velocity (to scale)", list(v))
        k = speed / norm
        return dataclasses.replace(trajectory, direction_velocity=(k * v[0], k * v[1], v[2]))
    raise ConfigError("trajectory.kind", "circle, helix or line (the envelope scales their speed)",
                      getattr(trajectory, "kind", type(trajectory).__name__))


def scenario_at(scenario: Scenario, *, speed: float, amplitude_xy: float, epsilon: float) -> Scenario:
    """The variant at horizontal target speed ``speed``, current amplitude ``amplitude_xy`` on x and y
    (z kept), and ``epsilon`` (m/s, m/s, m)."""
    d = scenario.disturbance
    dist = dataclasses.replace(d, amplitude=(amplitude_xy, amplitude_xy, d.amplitude[2]))
    return scenario.with_changes(trajectory=_trajectory_at_speed(scenario.trajectory, speed), disturbance=dist,
                                 epsilon=epsilon)


def _check_inputs(scenario: Scenario, eps: float | None, speeds) -> tuple[float, np.ndarray]:
    """Validated epsilon (m) and speed grid (m/s); the default grid spans (0, u_max) plus the scenario's speed."""
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.scenario.Scenario", type(scenario).__name__)
    eps = scenario.epsilon if eps is None else positive("eps", eps)
    if eps >= scenario.region.e_d_max:
        raise ConfigError("eps", f"a number < region.e_d_max = {scenario.region.e_d_max}", eps)
    u_max = scenario.limits.u_max
    if speeds is None:
        return eps, np.array([])
    try:
        grid = np.asarray([finite("speeds", s) for s in np.ravel(np.asarray(speeds, dtype=float))])
    except (TypeError, ValueError):
        raise ConfigError("speeds", "a list of numbers in [0, u_max)", speeds) from None
    if grid.size == 0 or np.any(grid < 0) or np.any(grid >= u_max):
        raise ConfigError("speeds", f"a non-empty list of speeds in [0, u_max = {u_max:g}) m/s", list(grid))
    return eps, np.unique(grid)


def _default_speeds(scenario: Scenario, quick: bool) -> np.ndarray:
    """Evenly spaced in [0, u_max) (quick 5, full 16 points) plus the scenario's own speed (m/s)."""
    u_max = scenario.limits.u_max
    n = 5 if quick else 16
    own = scenario.trajectory.horizontal_speed_bound()
    grid = np.linspace(0.0, u_max, n + 1)[:-1]
    return np.unique(np.round(np.append(grid, [own] if own < u_max else []), 12))


def _current_xy(scenario: Scenario) -> float:
    """The horizontal current bound max(a_x, a_y) + ||c_xy|| (m/s), rounded outward: the part of omega_bar_xy
    that is water current on either plant (:func:`verify.theorem.design.disturbance_bounds`)."""
    a, c = scenario.disturbance.amplitude, scenario.disturbance.constant
    return upper(arb(max(a[0], a[1])) + (arb(c[0]) ** 2 + arb(c[1]) ** 2).sqrt())


#: The tracking theorem's conditions on one mission's geometry (prefixes), left out of an envelope's verdict.
GEOMETRY_CONDITIONS = ("initial_terminal", "path_", "terminal_rate")


def frontier_verdict(cert: Certificate) -> tuple[bool, str]:
    """(certifies, first failed condition or "") of a point (module doc)."""
    failed = [c.condition for tier in ("safe", "tracking") for c in cert.tier_conditions[tier] if c.ok is not True]
    left = GEOMETRY_CONDITIONS + (("terminal_",) if any(n.startswith("terminal_rate[") for n in failed) else ())
    failed = [n for n in failed if not n.startswith(left)]
    return (not failed, failed[0] if failed else "")


def _tracking_omega(cert: Certificate) -> float:
    """ω̄_xy (m/s) the tracking design was derived at: the certificate's on the kinematic plant, the plans-only loop
    bound's on the dynamic one (``docs/verify.md`` step 17d): what keep-up and the yaw budget read."""
    return float(cert.design.problem.omega_xy)


def _own_point(scenario: Scenario, law: str, eps: float) -> dict:
    """The scenario's own speed (m/s), omega_bar_xy (m/s) and epsilon (m), and its verdict at ``eps``
    (the ``own_*`` fields of :class:`EnvelopeResult`)."""
    cert = certify(scenario.with_changes(epsilon=eps), law)
    certifies, failure = frontier_verdict(cert)
    if scenario.plant.dynamic:
        omega, current = _tracking_omega(cert), _current_xy(scenario)
    else:
        kinematic = disturbance_bounds(scenario)
        omega, current = kinematic.omega_xy, kinematic.omega_xy - kinematic.gamma
    return {"own_speed": float(scenario.trajectory.horizontal_speed_bound()),
            "own_omega": float(omega), "own_current_xy": float(current),
            "own_epsilon": float(scenario.epsilon),
            "own_certified": certifies, "own_safe": bool(cert.tiers.safe), "own_failure": failure}


def _frontier_at(scenario: Scenario, law: str, speed: float, eps: float, top: float,
                 steps: int, zero: Certificate | None = None) -> tuple[float, float, str, float, float]:
    """Bisection on the amplitude in [0, top] (m/s): certified a (NaN: none), refuted a (NaN: top certifies),
    the first failure at the refuted a, the sigma (1/s) of the certified design and its tracking design's omega_bar_xy
    (m/s) at the certified a (NaN: none). ``zero``: the certificate at a = 0, when the caller has it already."""
    def verdict(a: float) -> tuple[bool, str, float, float]:
        cert = zero if a == 0.0 and zero is not None else certify(
            scenario_at(scenario, speed=speed, amplitude_xy=a, epsilon=eps), law)
        return (*frontier_verdict(cert), cert.design.sigma, _tracking_omega(cert))

    ok, fail, sigma, omega = verdict(0.0)
    if not ok:
        return math.nan, 0.0, fail, math.nan, math.nan
    top = max(top, 0.0)
    ok_top, fail_top, sigma_top, omega_top = verdict(top)
    if ok_top or top == 0.0:
        return (top, math.nan, "", *((sigma_top, omega_top) if ok_top else (sigma, omega)))
    lo, hi, fail = 0.0, top, fail_top
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        ok, why, sig, om = verdict(mid)
        if ok:
            lo, sigma, omega = mid, sig, om
        else:
            hi, fail = mid, why
    return lo, hi, fail, sigma, omega


def envelope(scenario: Scenario, law: str | None = None, *, eps: float | None = None, speeds=None,
             quick: bool = False, steps: int | None = None,
             on_speed: Callable[[int, int], None] | None = None) -> EnvelopeResult:
    """Certified and physical-necessity frontiers of ``scenario`` at one epsilon (module doc).

    Parameters
    ----------
    scenario : Scenario
        Base scenario (circle, helix or line trajectory).
    law : str, optional
        Ancillary law; default the scenario's.
    eps : float, optional
        Lower bound of e_d (m); default the scenario's epsilon.
    speeds : sequence of float, optional
        Horizontal target speeds in [0, u_max) (m/s); default an even grid plus the scenario's speed.
    quick : bool
        Fewer speeds (5 + the scenario's) and bisection steps (9 instead of 14).
    steps : int, optional
        Bisection steps per speed, in place of the ``quick`` choice (>= 1).
    on_speed : callable, optional
        ``on_speed(done, total)`` after each speed's frontier (a progress report; the result does not depend on it).

    Returns
    -------
    EnvelopeResult
    """
    eps, grid = _check_inputs(scenario, eps, speeds)
    law = resolve_law(scenario.controller.law if law is None else law)
    grid = grid if grid.size else _default_speeds(scenario, quick)
    if steps is None:
        steps = BISECTION_STEPS[bool(quick)]
    elif isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
        raise ConfigError("steps", "an integer >= 1", steps)
    lim, dynamic = scenario.limits, scenario.plant.dynamic
    first = scenario_at(scenario, speed=float(grid[0]), amplitude_xy=0.0, epsilon=eps)
    if dynamic:  # gamma: the part of the tracking design's omega_bar_xy that is not current, at zero current
        offset = _current_xy(first)
        zero = certify(first, law)  # also the first speed's verdict at a = 0 (not certified twice)
        omega0 = _tracking_omega(zero)
        gamma = max(omega0 - offset, 0.0) if math.isfinite(omega0) else math.nan
    else:
        dist, zero = disturbance_bounds(first), None
        offset = max(dist.omega_xy - dist.gamma, 0.0)  # ||c_xy|| rounded outward, as the certificate sees it
        gamma = dist.gamma
    rows = []
    for s in grid:
        need = necessary_omega(float(s), lim.u_max)
        top = need - offset - (0.0 if dynamic else gamma)  # dynamic: the non-current part may grow with a
        rows.append((need, *_frontier_at(scenario, law, float(s), eps, top, steps,
                                         zero if s == grid[0] else None)))
        if on_speed is not None:
            on_speed(len(rows), len(grid))
    need, lo, hi, fails, sigmas, omegas = (list(x) for x in zip(*rows))
    lo_arr = np.asarray(lo, dtype=float)
    certified = np.asarray(omegas, dtype=float) if dynamic else lo_arr + offset + gamma
    return EnvelopeResult(
        scenario_name=scenario.name, law=law, epsilon=eps, speeds=grid,
        certified_omega=np.where(np.isfinite(lo_arr), certified, np.nan),
        certified_amplitude=lo_arr, refuted_amplitude=np.asarray(hi, dtype=float),
        necessary_omega=np.asarray(need, dtype=float), first_failure=fails, gamma=gamma,
        sigma_at_edge=np.asarray(sigmas, dtype=float), current_offset=offset, amplitude_z=scenario.disturbance.amplitude[2],
        limits=tuple(lim.vector), bisection_steps=steps, dynamic=dynamic, **_own_point(scenario, law, eps))
