"""Hypothesis strategies for property-testing tube controllers.

Every strategy *builds* valid values (no filtering): regions, error states in a
region, (real, nominal) pairs on the tube boundary ||e - e_hat|| = rho-tilde,
disturbances in Omega = {||omega|| <= omega_bar} (constant or time-varying),
target velocities, desired trajectories and obstacle sets that satisfy the
spherical-world separation (eq. obstacle_dis).

Example
-------
>>> from hypothesis import given
>>> from verify.falsify import strategies as vs
>>> @given(vs.tube_configurations(region, rho_tilde=0.05, v_bar=[0.3, 0.2, 0.4]))
... def test_my_law(cfg):
...     assert rho_dot_inner(cfg, my_law, sigma) <= 0

Most strategies are thin maps from unit cubes (``[0, 1]^n``) to the sets; the
same maps are public (``*_from_unit``) so local optimisers (see
:mod:`verify.falsify.one_period`) search exactly the set the strategies sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.scenario import Obstacle, Scenario
from tubekit.model.trajectory import Circle, Helix, Line, Trajectory, Waypoints

from verify.falsify import scenarios as families
from verify.falsify.invariance import TubeConfiguration
from verify.kernel.region import Region

__all__ = [
    "regions",
    "error_states",
    "tube_pairs",
    "nominal_inputs",
    "disturbances",
    "disturbance_signals",
    "DisturbanceSignal",
    "target_velocities",
    "tube_configurations",
    "trajectories",
    "obstacle_sets",
    "state_from_error",
    "configuration_from_unit",
    "CONFIGURATION_DIM",
    "period_configuration_from_unit",
    "period_configurations",
    "PERIOD_DIM",
    "obstacles_beyond_sensing",
    "obstacles_on_path",
    "obstacle_clusters",
    "obstacles_between_end_and_target",
    "blocked_starts",
    "backup_attack_scenarios",
]

_unit = st.floats(0.0, 1.0, allow_nan=False, allow_infinity=False)


def _units(n: int) -> st.SearchStrategy[np.ndarray]:
    return st.lists(_unit, min_size=n, max_size=n).map(np.array)


def _lerp(lo: float, hi: float, u: float) -> float:
    return lo + (hi - lo) * float(u)


def _unit_vector(u_azimuth: float, u_z: float) -> np.ndarray:
    z = 2.0 * u_z - 1.0
    a = 2.0 * math.pi * u_azimuth
    s = math.sqrt(max(0.0, 1.0 - z * z))
    return np.array([s * math.cos(a), s * math.sin(a), z])


def state_from_error(e_d: float, e_z: float, e_o: float, bearing: float, sign: int) -> np.ndarray:
    """[e_x, e_y, e_z, psi] relative to the target for error (e_d, e_z, e_o), bearing and hemisphere sign.

    ``sign`` = -1: "toward" (cos(psi - bearing) < 0), +1: "away".
    """
    phi = math.atan2(e_o, sign * math.sqrt(max(0.0, 1.0 - e_o * e_o)))
    return np.array([e_d * math.cos(bearing), e_d * math.sin(bearing), e_z, bearing + phi])


# ------------------------------------------------------------------ regions and states
@st.composite
def regions(draw, heading: str | None = None, max_e_o: float = 0.95) -> Region:
    """Valid :class:`verify.kernel.region.Region` values (optionally with a fixed heading)."""
    lo = draw(st.floats(0.05, 2.0))
    hi = lo + draw(st.floats(0.2, 5.0))
    ez = draw(st.floats(0.1, 2.0))
    eo = draw(st.floats(0.1, max_e_o))
    head = heading if heading is not None else draw(st.sampled_from(("toward", "away", "both")))
    pd = (draw(st.floats(0.0, 0.5)), draw(st.floats(0.0, 0.5)), draw(st.floats(0.0, 0.1)))
    xy = draw(st.floats(0.0, 1.0)) * math.hypot(pd[0], pd[1])
    return Region(e_d=(lo, hi), e_z=(-ez, ez), e_o=(-eo, eo), heading=head, pd_dot_max=pd, pd_dot_xy_max=xy,
                  omega_bar=draw(st.floats(0.0, 0.3)),
                  v_max=(draw(st.floats(0.1, 1.0)), draw(st.floats(0.1, 1.0)), draw(st.floats(0.1, 1.0))))


def _sign_from_unit(region: Region, u: float) -> int:
    signs = region.hemisphere_signs
    return signs[0] if len(signs) == 1 or u < 0.5 else signs[1]


def error_states(region: Region) -> st.SearchStrategy[np.ndarray]:
    """Real states [e_x, e_y, e_z, psi] (relative to the target) whose error lies in ``region``."""
    def build(u: np.ndarray) -> np.ndarray:
        return state_from_error(_lerp(*region.e_d, u[0]), _lerp(*region.e_z, u[1]), _lerp(*region.e_o, u[2]),
                                _lerp(-math.pi, math.pi, u[3]), _sign_from_unit(region, u[4]))
    return _units(5).map(build)


def _shrunk(region: Region, rho: float) -> tuple[tuple[float, float], ...]:
    boxes = tuple((lo + rho, hi - rho) for lo, hi in (region.e_d, region.e_z, region.e_o))
    if any(lo > hi for lo, hi in boxes):
        raise ConfigError("rho_tilde", "a tube radius smaller than half the narrowest region width", rho,
                          "the region shrunk by the tube is empty")
    return boxes


def _pair_from_unit(region: Region, rho: float, delta_theta: float, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    (dl, dh), (zl, zh), (ol, oh) = _shrunk(region, rho)
    e_hat = np.array([_lerp(dl, dh, u[0]), _lerp(zl, zh, u[1]), _lerp(ol, oh, u[2])])
    e = e_hat + rho * _unit_vector(u[4], u[5])
    sign = _sign_from_unit(region, u[3])
    theta_hat = _lerp(-math.pi, math.pi, u[6])
    theta = theta_hat + _lerp(-delta_theta, delta_theta, u[7])
    return state_from_error(*e, theta, sign), state_from_error(*e_hat, theta_hat, sign)


def tube_pairs(region: Region, rho_tilde: float, delta_theta: float = 0.0) -> st.SearchStrategy[tuple]:
    """(real, nominal) states with ||e - e_hat|| = rho_tilde exactly, both errors in ``region``.

    The nominal lies in the region shrunk by rho_tilde (E-bar), the real one on the
    sphere of radius rho_tilde around it; the same hemisphere; bearings differ by at
    most ``delta_theta`` (rad) — the certificate's bearing-mismatch bound.
    """
    _shrunk(region, rho_tilde)
    return _units(8).map(lambda u: _pair_from_unit(region, rho_tilde, delta_theta, u))


# ------------------------------------------------------------------ inputs and disturbances
def _input_from_unit(v_bar: Sequence[float], u: np.ndarray) -> np.ndarray:
    return np.array([_lerp(-b, b, x) for b, x in zip(v_bar, u)])


def nominal_inputs(v_bar: Sequence[float]) -> st.SearchStrategy[np.ndarray]:
    """Nominal inputs in the box |v_i| <= v_bar_i."""
    return _units(3).map(lambda u: _input_from_unit(v_bar, u))


def _omega_from_unit(omega_bar: float, u: np.ndarray) -> np.ndarray:
    mag = omega_bar if u[2] > 0.8 else omega_bar * u[2] / 0.8  # a fifth of the draws on the sphere
    return mag * _unit_vector(u[0], u[1])


def disturbances(omega_bar: float) -> st.SearchStrategy[np.ndarray]:
    """Constant disturbances omega with ||omega||_2 <= omega_bar (m/s), often on the boundary."""
    return _units(3).map(lambda u: _omega_from_unit(omega_bar, u))


@dataclass(frozen=True)
class DisturbanceSignal:
    """omega(t) = omega_bar * sum_k w_k d_k sin(f_k t + phi_k), sum w_k <= 1, ||d_k|| = 1.

    So ||omega(t)|| <= omega_bar for every t. Callable: ``signal(t) -> (3,)``.
    """

    omega_bar: float
    weights: tuple[float, ...]
    directions: tuple[tuple[float, float, float], ...]
    frequencies: tuple[float, ...]
    phases: tuple[float, ...]

    def __call__(self, t: float) -> np.ndarray:
        out = np.zeros(3)
        for w, d, f, p in zip(self.weights, self.directions, self.frequencies, self.phases):
            out += w * math.sin(f * t + p) * np.asarray(d)
        return self.omega_bar * out


@st.composite
def disturbance_signals(draw, omega_bar: float, max_terms: int = 3,
                        max_frequency: float = 2.0) -> DisturbanceSignal:
    """Bounded time-varying disturbances (sums of sinusoids, rad/s frequencies <= max_frequency)."""
    k = draw(st.integers(1, max_terms))
    raw = [draw(st.floats(0.0, 1.0)) for _ in range(k)]
    total = sum(raw) or 1.0
    weights = tuple(r / total for r in raw)
    dirs = tuple(tuple(_unit_vector(draw(_unit), draw(_unit))) for _ in range(k))
    freqs = tuple(draw(st.floats(0.0, max_frequency)) for _ in range(k))
    phases = tuple(draw(st.floats(0.0, 2 * math.pi)) for _ in range(k))
    return DisturbanceSignal(omega_bar, weights, dirs, freqs, phases)


def _pd_dot_from_unit(region: Region, u: np.ndarray) -> np.ndarray:
    a = 2.0 * math.pi * u[0]
    ca, sa = abs(math.cos(a)), abs(math.sin(a))
    reach = region.pd_dot_xy_max
    if ca > 0:
        reach = min(reach, region.pd_dot_max[0] / ca)
    if sa > 0:
        reach = min(reach, region.pd_dot_max[1] / sa)
    speed = reach * u[1]
    return np.array([speed * math.cos(a), speed * math.sin(a), _lerp(-region.pd_dot_max[2], region.pd_dot_max[2], u[2])])


def target_velocities(region: Region) -> st.SearchStrategy[np.ndarray]:
    """Target velocities in P (componentwise bounds and the horizontal speed bound)."""
    return _units(3).map(lambda u: _pd_dot_from_unit(region, u))


#: Length of the unit vector :func:`configuration_from_unit` reads.
CONFIGURATION_DIM = 8 + 3 + 3 + 3


def configuration_from_unit(region: Region, rho_tilde: float, v_bar: Sequence[float], delta_theta: float,
                            u: np.ndarray) -> TubeConfiguration:
    """Map u in [0, 1]^CONFIGURATION_DIM to a tube-boundary :class:`TubeConfiguration`."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    real, nominal = _pair_from_unit(region, rho_tilde, delta_theta, u[:8])
    return TubeConfiguration(real=real, nominal=nominal, v_hat=_input_from_unit(v_bar, u[8:11]),
                             omega=_omega_from_unit(region.omega_bar, u[11:14]),
                             pd_dot=_pd_dot_from_unit(region, u[14:17]))


def tube_configurations(region: Region, rho_tilde: float, v_bar: Sequence[float],
                        delta_theta: float = 0.0) -> st.SearchStrategy[TubeConfiguration]:
    """Everything rho^T rho_dot depends on, with ||rho|| = rho_tilde, v_hat in V-bar, omega in Omega, p_d_dot in P."""
    _shrunk(region, rho_tilde)
    return _units(CONFIGURATION_DIM).map(
        lambda u: configuration_from_unit(region, rho_tilde, v_bar, delta_theta, u))


#: Length of the unit vector :func:`period_configuration_from_unit` reads.
PERIOD_DIM = 5 + 3 + 3 + 3


def _omega_box_from_unit(omega_xy: float, omega_z: float, u: np.ndarray) -> np.ndarray:
    """ω with ‖ω_xy‖ <= ω̄_xy and |ω_z| <= ω̄_z (a fifth of the draws on the circle)."""
    mag = omega_xy if u[1] > 0.8 else omega_xy * u[1] / 0.8
    a = 2.0 * math.pi * u[0]
    return np.array([mag * math.cos(a), mag * math.sin(a), _lerp(-omega_z, omega_z, u[2])])


def period_configuration_from_unit(region: Region, start: Sequence[Sequence[float]], v_bar: Sequence[float],
                                   omega_bar: Sequence[float], u: np.ndarray) -> TubeConfiguration:
    """Map u in [0, 1]^PERIOD_DIM to the start of one period under the reset (``real`` = ``nominal``).

    ``start`` = ((e_d lo, hi), (e_z lo, hi), (e_o lo, hi)) is Ē; ``omega_bar`` = (ω̄_xy, ω̄_z);
    v̂ in the V̄ box, p_d_dot in P of ``region``.
    """
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    e = [_lerp(lo, hi, x) for (lo, hi), x in zip(start, u[:3])]
    state = state_from_error(*e, _lerp(-math.pi, math.pi, u[3]), _sign_from_unit(region, u[4]))
    return TubeConfiguration(real=state, nominal=state.copy(), v_hat=_input_from_unit(v_bar, u[5:8]),
                             omega=_omega_box_from_unit(omega_bar[0], omega_bar[1], u[8:11]),
                             pd_dot=_pd_dot_from_unit(region, u[11:14]))


def period_configurations(region: Region, start: Sequence[Sequence[float]], v_bar: Sequence[float],
                          omega_bar: Sequence[float]) -> st.SearchStrategy[TubeConfiguration]:
    """Starts of one sampled-data period: e in Ē (``start``), ρ = 0, v̂ in V̄, ω in the box-disk, p_d_dot in P."""
    if any(lo > hi for lo, hi in start):
        raise ConfigError("start", "non-empty intervals (lo <= hi) for e_d, e_z, e_o", [list(b) for b in start])
    return _units(PERIOD_DIM).map(lambda u: period_configuration_from_unit(region, start, v_bar, omega_bar, u))


# ------------------------------------------------------------------ trajectories and obstacles
@st.composite
def trajectories(draw, max_speed: float = 0.4) -> Trajectory:
    """Circles, helices, lines and waypoint paths whose horizontal speed is <= max_speed (m/s)."""
    kind = draw(st.sampled_from(("circle", "helix", "line", "waypoints")))
    speed = draw(st.floats(0.01, max_speed))
    if kind in ("circle", "helix"):
        radius = draw(st.floats(0.5, 10.0))
        rate = speed / radius * draw(st.sampled_from((-1.0, 1.0)))
        center = tuple(draw(st.floats(-5, 5)) for _ in range(3))
        if kind == "circle":
            return Circle(radius=radius, rate=rate, center=center, phase=draw(st.floats(0, 2 * math.pi)))
        return Helix(radius=radius, rate=rate, center=center, climb=draw(st.floats(-0.1, 0.1)))
    if kind == "line":
        d = _unit_vector(draw(_unit), 0.5)
        return Line(start=tuple(draw(st.floats(-5, 5)) for _ in range(3)), direction_velocity=tuple(speed * d))
    n = draw(st.integers(2, 5))
    pts = [np.zeros(3)]
    for _ in range(n - 1):
        step = draw(st.floats(0.5, 5.0)) * _unit_vector(draw(_unit), draw(st.floats(0.3, 0.7)))
        pts.append(pts[-1] + step)
    return Waypoints(points=tuple(tuple(p) for p in pts), speed=speed)


@st.composite
def obstacle_sets(draw, vehicle_radius: float = 0.2, max_obstacles: int = 4, max_radius: float = 1.0,
                  spread: float = 10.0) -> tuple[Obstacle, ...]:
    """Obstacles satisfying eq. (obstacle_dis): ||c_i - c_j|| > 2 r-bar + r_i + r_j, by construction.

    Centres are placed on a line of slots spaced 2 r-bar + 2 max_radius + gap apart
    (so any pair is separated), then jittered within each slot's slack.
    """
    n = draw(st.integers(0, max_obstacles))
    gap = 0.1
    slot = 2 * vehicle_radius + 2 * max_radius + gap
    out = []
    direction = _unit_vector(draw(_unit), draw(_unit))
    origin = np.array([draw(st.floats(-spread, spread)) for _ in range(3)])
    for k in range(n):
        radius = draw(st.floats(0.05, max_radius))
        center = origin + k * slot * direction
        jitter = (gap / 2 - 1e-6) * _unit_vector(draw(_unit), draw(_unit)) * draw(_unit) * 0.99
        out.append(Obstacle(tuple(center + jitter), radius))
    return tuple(out)


# ------------------------------------------------------------------ scenario families (issue 21)
def _family(name: str, scenario: Scenario) -> st.SearchStrategy[Scenario]:
    build = families.FAMILIES[name]
    return _units(families.FAMILY_DIMS[name]).map(lambda u: build(scenario, u))


def obstacles_beyond_sensing(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """``scenario`` with one obstacle whose surface lies just beyond the start's sensing range, on the way."""
    return _family("beyond_sensing", scenario)


def obstacles_on_path(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """``scenario`` with up to three obstacles centred on the desired path."""
    return _family("on_path", scenario)


def obstacle_clusters(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """``scenario`` with a tight hexagonal cluster of 3-7 obstacles near the path."""
    return _family("cluster", scenario)


def obstacles_between_end_and_target(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """``scenario`` with an obstacle between a plan's end and the target."""
    return _family("between_end_and_target", scenario)


def blocked_starts(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """``scenario`` started just behind an obstacle between it and the target (no FHOCP plan may exist)."""
    return _family("blocked_start", scenario)


def backup_attack_scenarios(scenario: Scenario) -> st.SearchStrategy[Scenario]:
    """Any of the five families above (:mod:`verify.falsify.scenarios`)."""
    return st.one_of(*(_family(name, scenario) for name in families.FAMILIES))
