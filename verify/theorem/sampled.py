"""The sampled-data tube of one FHOCP period under the nominal reset.

This is the tube of the loop that runs (:mod:`tubekit.loop.closed_loop`): at every
sample t_k the nominal is reset to the measured state (ê(t_k) = e(t_k),
eq. diff_mpc), the nominal input v̂ is held for one period δ = ``dt``, and the
ancillary law κ_i = -σ K(e_i) ρ_i is applied with a zero-order hold at the
ticks t_i = t_k + i h, h = 1 / f. The deviation therefore starts at zero every
period, and a finite-time bound over [t_k, t_k + δ] is all the tube needs.

The bound is a box: per-axis bounds ρ̄ = (ρ̄_d, ρ̄_z, ρ̄_o) on |e - ê|, a bound
Θ̄ on the bearing difference |θ - θ̂| (θ = atan2(e_y, e_x), which e does not
contain), and Cartesian bounds (‖p_xy - p̂_xy‖, |z - ẑ|, |ψ - ψ̂|). It is the
least post-fixed point of a monotone map F (:func:`tube_map`):

* per tick, ρ(t_i + s) = (I - σ s G_i) ρ_i + ∫ rest, with G = J K held over
  the tick, so |ρ_j| obeys the recursion of :func:`_tick_recursion`;
* ``rest`` = (J(e) - J(e_i)) κ_i + (J(e) - J(ê)) v̂ + ζ(e) - ζ(ê) + ξ is bounded
  per axis by :func:`_rest_rates`;
* the Cartesian deviation obeys |ψ̇ - ψ̂̇| <= κ̄_r,
  ‖ṗ_xy - ṗ̂_xy‖ <= κ̄_u + ū |ψ - ψ̂| + ω̄_xy, |ż - ẑ̇| <= κ̄_w + ω̄_z
  (:func:`_cartesian`), which bounds ρ too; the smaller bound is kept.

A point x with F(x) < x componentwise (checked in Arb) is a certified tube:
if the trajectory left the box x at a first time T, every bound would hold up
to T and give |ρ_j(T)| <= F_j(x) < x_j, a contradiction (first-exit argument).
``docs/verify.md`` states each step and names the function computing it.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import lru_cache

from flint import arb

from tubekit.exceptions import ConfigError

from verify.kernel.intervals import upper
from verify.kernel.parts import bound, flag, integer, matrix, number, numbers, text

__all__ = ["TubeProblem", "PeriodTube", "tube_map", "one_period_tube", "horizon_margins", "HorizonMargins"]

#: Relative inflation of the float fixed point before the Arb check.
_INFLATE = 1e-6
#: Fixed-point iterations (work units, not seconds).
_MAX_ITER = 400


@dataclass(frozen=True)
class TubeProblem:
    """Everything the one-period theorem takes (plain floats; stored in the certificate).

    Units: m, m/s, rad/s, s, 1/s. ``yaw_rate_error`` bounds |ψ̇ - r_cmd| (rad/s): 0 on the kinematic
    plant, the velocity loop's yaw error on the dynamic one (its surge and heave errors enter ω).
    ``k_abs[j][l]`` >= sup |K_jl| over R;
    ``g_lo[j] <= (J K)_jj <= g_hi[j]`` and ``g_off[j][l]`` >= sup |(J K)_jl| (l != j) over R.
    """

    eps: float
    e_o_max: float
    u_max: float
    w_max: float
    r_max: float
    omega_xy: float
    omega_z: float
    pd_xy: float
    pd_z: float
    sigma: float
    tick: float
    ticks: int
    k_abs: tuple[tuple[float, float, float], ...]
    g_lo: tuple[float, float, float]
    g_hi: tuple[float, float, float]
    g_off: tuple[tuple[float, float, float], ...]
    yaw_rate_error: float = 0.0

    @property
    def period(self) -> float:
        """δ = ticks * tick (s)."""
        return self.ticks * self.tick

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return {k: (list(map(list, v)) if isinstance(v, tuple) and v and isinstance(v[0], tuple)
                    else list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.problem") -> "TubeProblem":
        """Inverse of :meth:`to_dict` (ConfigError naming the key on a missing or mistyped entry)."""
        scalars = ("eps", "e_o_max", "u_max", "w_max", "r_max", "omega_xy", "omega_z", "pd_xy", "pd_z", "sigma",
                   "tick", "yaw_rate_error")
        kw = {k: number(d, k, where) for k in scalars}
        return cls(**kw, ticks=integer(d, "ticks", where), k_abs=matrix(d, "k_abs", where),
                   g_lo=numbers(d, "g_lo", where, 3, none=None), g_hi=numbers(d, "g_hi", where, 3, none=None),
                   g_off=matrix(d, "g_off", where))


@dataclass(frozen=True)
class PeriodTube:
    """A certified one-period tube (every number an upper bound over [t_k, t_k + δ]).

    Attributes
    ----------
    rho : tuple (3,)
        sup |e_d - ê_d| (m), |e_z - ê_z| (m), |e_o - ê_o| (-).
    theta : float
        sup |θ - θ̂| (rad).
    p_xy, p_z, psi : float
        sup ‖p_xy - p̂_xy‖ (m), |z - ẑ| (m), |ψ - ψ̂| (rad).
    kappa : tuple (3,)
        sup |κ_u| (m/s), |κ_w| (m/s), |κ_r| (rad/s).
    certified : bool
        True when F(x) < x was verified in Arb.
    iterations : int
        Fixed-point iterations used.
    reason : str
        Why not certified ('' when certified).
    contraction : float
        max_j F_j(x) / x_j at the certified x (< 1 is the theorem's condition).
    """

    rho: tuple[float, float, float]
    theta: float
    p_xy: float
    p_z: float
    psi: float
    kappa: tuple[float, float, float]
    certified: bool
    iterations: int
    reason: str = ""
    contraction: float = math.inf

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        d = asdict(self)
        d["rho"], d["kappa"] = list(self.rho), list(self.kappa)
        return d

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.tube") -> "PeriodTube":
        """Inverse of :meth:`to_dict`; ``null`` bounds read as +inf (no finite bound). Extra keys are ignored."""
        return cls(rho=numbers(d, "rho", where, 3), theta=bound(d, "theta", where), p_xy=bound(d, "p_xy", where),
                   p_z=bound(d, "p_z", where), psi=bound(d, "psi", where), kappa=numbers(d, "kappa", where, 3),
                   certified=bool(flag(d, "certified", where)), iterations=integer(d, "iterations", where),
                   reason=text(d, "reason", where), contraction=bound(d, "contraction", where))


# --------------------------------------------------------------------------- the map F
@lru_cache(maxsize=64)
def _lipschitz(p: TubeProblem) -> dict[str, arb]:
    """Constants of the derived J over R: c = s sqrt(1 - e_o²), a = e_o c / e_d (J_od = -a).

    Computed once per problem (the fixed-point iteration calls :func:`tube_map` up to 400 times);
    callers only read the returned dict.
    """
    o, eps = arb(p.e_o_max), arb(p.eps)
    c_min = (1 - o * o).sqrt()
    q = o * c_min if p.e_o_max <= math.sqrt(0.5) else arb(0.5)    # sup |e_o c|
    ed_rate = arb(p.u_max) + arb(p.omega_xy) + arb(p.pd_xy)
    eo_rate = arb(p.r_max) + arb(p.yaw_rate_error) + (arb(p.u_max) * o + arb(p.omega_xy) + arb(p.pd_xy)) / eps
    return {"Lc": o / c_min,                  # |dc/de_o|
            "La_o": 1 / (c_min * eps),        # |da/de_o| = |1 - 2 e_o²| / (|c| e_d)
            "La_d": q / (eps * eps),          # |da/de_d| = |e_o c| / e_d²
            "ed_rate": ed_rate, "eo_rate": eo_rate}


def _kappa(p: TubeProblem, rho: list[arb]) -> list[arb]:
    """κ̄_j = σ Σ_l sup|K_jl| ρ̄_l."""
    s = arb(p.sigma)
    return [s * sum((arb(p.k_abs[j][l]) * rho[l] for l in range(3)), arb(0)) for j in range(3)]


def _rest_rates(p: TubeProblem, rho: list[arb], theta: arb, kap: list[arb], L: dict[str, arb]) -> list[arb]:
    """Per-axis bound B_j on |rest_j| = |(J(e)-J(e_i))κ_i + (J(e)-J(ê))v̂ + Δζ + ξ|_j."""
    eps, h = arb(p.eps), arb(p.tick)
    u, r, P = arb(p.u_max), arb(p.r_max), arb(p.pd_xy)
    wxy = arb(p.omega_xy)
    rd, _rz, ro = rho
    b_d = (wxy + P * theta + u * L["Lc"] * ro            # ξ_d, Δζ_d, (c - ĉ) û
           + L["Lc"] * h * L["eo_rate"] * kap[0])         # ZOH: (c - c_i) κ_u
    b_z = arb(p.omega_z)                                  # ξ_z (J row z is constant)
    b_o = (wxy / eps                                                      # ξ_o
           + P * (L["Lc"] * ro / eps + theta / eps + rd / (eps * eps))   # Δζ_o
           + u * (L["La_o"] * ro + L["La_d"] * rd) + r * L["Lc"] * ro     # (J(e) - J(ê)) v̂, row o
           + h * (L["La_o"] * L["eo_rate"] + L["La_d"] * L["ed_rate"]) * kap[0]  # ZOH, a(e) - a(e_i)
           + L["Lc"] * h * L["eo_rate"] * kap[2]                           # ZOH, (c - c_i) κ_r
           + arb(p.yaw_rate_error))                                        # c (ψ̇ - r_cmd), |c| <= 1
    return [b_d, b_z, b_o]


def _bearing_rate(p: TubeProblem, rho: list[arb], theta: arb, kap: list[arb]) -> arb:
    """Bound on |θ̇ - θ̂̇|, θ̇ = (u e_o + (ω - ṗ_d)·n_t) / e_d."""
    eps, o = arb(p.eps), arb(p.e_o_max)
    rd, _, ro = rho
    return (kap[0] * o / eps + arb(p.u_max) * (ro / eps + o * rd / (eps * eps))
            + arb(p.omega_xy) / eps + arb(p.pd_xy) * (theta / eps + rd / (eps * eps)))


def _tick_recursion(p: TubeProblem, b: list[arb]) -> list[arb]:
    """sup over the period of the per-tick bounds r_i (r_0 = 0, reset).

    r_{i+1,j} = max_g |1 - σ h g| r_{i,j} + σ h Σ_{l≠j} sup|G_jl| r_{i,l} + h B_j,
    and within a tick |ρ_j| <= max(r_i, r_{i+1}) (the bound is convex in s).
    """
    sh = arb(p.sigma) * arb(p.tick)
    h = arb(p.tick)
    diag = [_max(abs(1 - sh * arb(p.g_lo[j])), abs(1 - sh * arb(p.g_hi[j]))) for j in range(3)]
    r = [arb(0)] * 3
    top = [arb(0)] * 3
    for _ in range(p.ticks):
        r = [diag[j] * r[j] + sh * sum((arb(p.g_off[j][l]) * r[l] for l in range(3) if l != j), arb(0))
             + h * b[j] for j in range(3)]
        top = [_max(top[j], r[j]) for j in range(3)]
    return top


def _cartesian(p: TubeProblem, kap: list[arb]) -> tuple[arb, arb, arb]:
    """(sup ‖Δp_xy‖, sup |Δz|, sup |Δψ|) over the period with |κ| <= κ̄."""
    d = arb(p.period)
    psi = (kap[2] + arb(p.yaw_rate_error)) * d
    pxy = (kap[0] + arb(p.omega_xy)) * d + arb(p.u_max) * psi * d / 2
    pz = (kap[1] + arb(p.omega_z)) * d
    return pxy, pz, psi


def _asin_ratio(num: arb, den: arb) -> arb:
    """asin(num / den), or +inf when num >= den (no bound on the angle)."""
    ratio = num / den
    if not ratio < 1:
        return arb("inf")
    return ratio.asin()


def tube_map(p: TubeProblem, x: list[arb]) -> tuple[list[arb], dict[str, arb]]:
    """F(x) for x = [ρ̄_d, ρ̄_z, ρ̄_o, Θ̄]; also the Cartesian bounds and κ̄ at x."""
    L = _lipschitz(p)
    rho, theta = x[:3], x[3]
    kap = _kappa(p, rho)
    b = _rest_rates(p, rho, theta, kap, L)
    tick_rho = _tick_recursion(p, b)
    theta_rate = arb(p.period) * _bearing_rate(p, rho, theta, kap)
    pxy, pz, psi = _cartesian(p, kap)
    theta_geo = _asin_ratio(pxy, arb(p.eps))
    new_theta = _min(theta_rate, theta_geo)
    new = [_min(tick_rho[0], pxy), _min(tick_rho[1], pz), _min(tick_rho[2], psi + new_theta), new_theta]
    return new, {"p_xy": pxy, "p_z": pz, "psi": psi, "kappa": kap}


def _min(a: arb, b: arb) -> arb:
    """The smaller of two upper bounds (both are valid; an Arb ball is kept whole)."""
    return a if upper(a) <= upper(b) else b


def _max(a: arb, b: arb) -> arb:
    """The ball with the larger upper end: an upper bound of both."""
    return a if upper(a) >= upper(b) else b


# --------------------------------------------------------------------------- fixed point
def _caps(p: TubeProblem) -> list[float]:
    """Beyond these the tube is useless (and the bounds' premises fail): divergence."""
    return [10.0 * p.eps, 10.0, 2.0 * p.e_o_max, math.pi / 2]


def one_period_tube(p: TubeProblem) -> PeriodTube:
    """The least certified one-period tube, or a not-certified result with the reason."""
    x = [0.0] * 4
    caps = _caps(p)
    it = 0
    for it in range(1, _MAX_ITER + 1):
        fx, _ = tube_map(p, [arb(v) for v in x])
        new = [upper(v) for v in fx]
        if any(not math.isfinite(v) or v > c for v, c in zip(new, caps)):
            return _failed(p, new, it, "the fixed-point iteration diverges (σ δ sup|K| too large, or the "
                                       "disturbance too large for ε): no finite one-period tube")
        if all(n <= v * (1 + 1e-12) + 1e-15 for n, v in zip(new, x)):
            x = new
            break
        x = new
    found = _post_fixed_point(p, x)
    if found is None:
        fx, _ = tube_map(p, [arb(v) for v in x])
        return _failed(p, [upper(v) for v in fx], it, "no post-fixed point F(x) < x found within the work budget")
    cand, fx, cart = found
    ratio = max(upper(f / arb(c)) for f, c in zip(fx, cand))
    return PeriodTube(rho=(cand[0], cand[1], cand[2]), theta=cand[3], p_xy=upper(cart["p_xy"]),
                      p_z=upper(cart["p_z"]), psi=upper(cart["psi"]),
                      kappa=tuple(upper(k) for k in cart["kappa"]), certified=True, iterations=it,
                      contraction=ratio)


def _post_fixed_point(p: TubeProblem, x: list[float], attempts: int = 200):
    """A point c with F(c) < c in Arb near the float fixed point x (attempts: a work unit).

    Iterates c <- F(c) + s with the slack s = η x + floor > 0 from c = x + s. Its limit solves
    c = F(c) + s, so F(c) = c - s < c; the iteration stops at the first c that passes in Arb.
    (A uniform inflation of x can fail where the map couples axes, e.g. ρ̄ into the bearing.)
    """
    slack = [v * _INFLATE + 1e-12 for v in x]
    cand = [v + e for v, e in zip(x, slack)]
    for _ in range(attempts):
        fx, cart = tube_map(p, [arb(v) for v in cand])
        if all(fv < arb(c) for fv, c in zip(fx, cand)):
            return cand, fx, cart
        cand = [max(c, upper(f) + e) for c, f, e in zip(cand, fx, slack)]
    return None


def _failed(p: TubeProblem, x: list[float], it: int, reason: str) -> PeriodTube:
    inf = math.inf
    return PeriodTube(rho=(x[0], x[1], x[2]), theta=x[3], p_xy=inf, p_z=inf, psi=inf, kappa=(inf, inf, inf),
                      certified=False, iterations=it, reason=reason)


# --------------------------------------------------------------------------- along the horizon
@dataclass(frozen=True)
class HorizonMargins:
    """Tightening of arc j (node j to j+1) of a plan, j = 0..N-1, relative to the state it starts from.

    ``e_d[j]``, ``e_z[j]``, ``e_o[j]`` (error units) and ``position[j]`` (m) grow with j so that the
    previous accepted plan, shifted by one period and replayed from the new measured state, still meets
    the margins of one arc less (the certified fallback candidate).
    """

    e_d: tuple[float, ...]
    e_z: tuple[float, ...]
    e_o: tuple[float, ...]
    position: tuple[float, ...]

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return {k: list(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, d: dict, where: str = "certificate.margins") -> "HorizonMargins":
        """Inverse of :meth:`to_dict`: four lists of one length (``null`` read as +inf)."""
        cols = {k: numbers(d, k, where) for k in ("e_d", "e_z", "e_o", "position")}
        if len({len(v) for v in cols.values()}) != 1:
            raise ConfigError(where, "four lists of one length (one entry per arc)",
                              {k: len(v) for k, v in cols.items()})
        return cls(**cols)


def horizon_margins(p: TubeProblem, tube: PeriodTube, arcs: int) -> HorizonMargins:
    """M_0 = the one-period tube; M_j = M_{j-1} + Δ(j δ) (Cartesian offset of the replayed candidate).

    A replayed plan starts off by at most (p_xy, p_z, psi) and, under the same inputs, keeps
    |Δψ| = psi and drifts ‖Δp_xy‖ <= p_xy + ū psi τ, |Δz| <= p_z after τ.
    """
    eps, d = arb(p.eps), arb(p.period)
    pxy, pz, psi = arb(tube.p_xy), arb(tube.p_z), arb(tube.psi)
    md, mz, mo = arb(tube.rho[0]), arb(tube.rho[1]), arb(tube.rho[2])
    mp = (pxy * pxy + pz * pz).sqrt()
    out: dict[str, list[float]] = {"e_d": [upper(md)], "e_z": [upper(mz)], "e_o": [upper(mo)], "position": [upper(mp)]}
    for j in range(1, arcs):
        dxy = pxy + arb(p.u_max) * psi * d * j
        md, mz = md + dxy, mz + pz
        mo = mo + psi + _asin_ratio(dxy, eps)
        mp = mp + (dxy * dxy + pz * pz).sqrt()
        for k, v in (("e_d", md), ("e_z", mz), ("e_o", mo), ("position", mp)):
            out[k].append(upper(v))
    return HorizonMargins(**{k: tuple(v) for k, v in out.items()})
