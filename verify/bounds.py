"""Certified bounds L1, L2, J_lower, xi_bar (and the auxiliary sups) by branch-and-bound.

The dynamics are always the *derived* ones (:func:`tubekit.derivation.derive`).
They are rewritten in polar form (:func:`polar_model`) by substituting

    e_x = e_d cos(theta),  e_y = e_d sin(theta),  psi = theta + phi,
    sin(phi) = e_o,  cos(phi) = c = s sqrt(1 - e_o^2)   (s = -1 toward, +1 away),
    [xdot_d, ydot_d] = a n_theta + b t_theta,  [omega_1, omega_2] = alpha n_theta + beta t_theta,

with n_theta = (cos theta, sin theta), t_theta = (-sin theta, cos theta). sympy
then cancels theta, and derivatives w.r.t. e are taken at fixed theta and fixed
Cartesian velocities (dc/de_o = -e_o / c). Because (a, b) is a rotation of
p_d_dot_xy and the region's velocity set is contained in the disc of radius
``pd_dot_xy_max`` (rotation invariant), a sup over all bearings and velocities
equals a sup over (a, b) in that disc. Each sup of a convex function of the
linear parameters (v_hat, p_d_dot) is taken at extreme points: vertices of
boxes, the circle a = h cos(gamma), b = h sin(gamma) of the disc. omega enters
xi linearly, so sup over the ball is omega_bar * ||d xi / d omega||_2.

Objectives are enclosed in Arb (:mod:`verify.intervals`): a matrix 2-norm as
sqrt(lambda_max(A^T A)) of the symbolically simplified Gram matrix, lambda_min of
a symmetric matrix via :func:`verify.intervals.sym_eig_bounds`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import sympy as sp
from flint import arb

from tubekit.ancillary import LAWS
from tubekit.derivation import derive, symbols
from tubekit.exceptions import ConfigError, TubekitError

from .intervals import Case, MaxResult, compile_arb, compile_numpy, maximise, point, sym_eig_bounds, upper
from .region import Region

__all__ = [
    "PolarModel",
    "polar_model",
    "law_gain",
    "BoundResult",
    "Bounds",
    "compute_bounds",
    "BOUND_NAMES",
]

#: Reported bounds: the four of issue item 2 and the auxiliary sups the certificate uses.
BOUND_NAMES = ("L1", "L2", "J_lower", "xi_bar", "zeta_theta", "K_row_u", "K_row_w", "K_row_r", "JK_norm")

# polar-form symbols
E_D = sp.Symbol("e_d", positive=True)
E_Z = sp.Symbol("e_z", real=True)
E_O = sp.Symbol("e_o", real=True)
_C = sp.Symbol("c", real=True)          # cos(psi - theta), eliminated before evaluation
THETA = sp.Symbol("theta", real=True)
A_V, B_V = sp.symbols("a b", real=True)              # target velocity along n_theta, t_theta
ALPHA, BETA = sp.symbols("alpha beta", real=True)    # disturbance along n_theta, t_theta
GAMMA = sp.Symbol("gamma", real=True)                # angle on the velocity disc
H_XY, P_Z = sp.symbols("h_xy p_z", nonnegative=True)  # velocity-set parameters
U_M, W_M, R_M = sp.symbols("u_max w_max r_max", positive=True)  # input-box parameters
_PHI = sp.Symbol("phi", real=True)


@dataclass(frozen=True)
class PolarModel:
    """The derived error dynamics in polar form for one hemisphere sign ``s``.

    All matrices are sympy expressions in ``e_d, e_z, e_o`` (c already replaced
    by s sqrt(1 - e_o^2)) and the named parameters.

    Attributes
    ----------
    s : int
        Hemisphere sign.
    J : Matrix (3, 3)
        Input matrix J(e).
    zeta : Matrix (3, 1)
        Drift in terms of a, b, zdot_d.
    xi : Matrix (3, 1)
        Disturbance term in terms of alpha, beta, omega_3.
    dh_de : Matrix (3, 3)
        d (J(e) v_hat) / d e in terms of u, w, r.
    dzeta_de : Matrix (3, 3)
        d zeta / d e at fixed bearing and Cartesian velocity.
    dzeta_dtheta : Matrix (3, 1)
        d zeta / d theta at fixed e and Cartesian velocity.
    dxi_domega : Matrix (3, 3)
        d xi / d (alpha, beta, omega_3); xi is linear in omega.
    zeta_rotation_form : bool
        zeta = zeta_0(e, zdot_d) + G(e) [a, b]^T with no other bearing dependence
        (verified symbolically), so zeta(e, theta) - zeta(e, theta_hat) =
        G (R_theta - R_theta_hat)^T p_d_dot_xy and its norm is at most
        sup||d zeta/d theta|| * 2 |sin((theta - theta_hat)/2)|.
    """

    s: int
    J: sp.Matrix
    zeta: sp.Matrix
    xi: sp.Matrix
    dh_de: sp.Matrix
    dzeta_de: sp.Matrix
    dzeta_dtheta: sp.Matrix
    dxi_domega: sp.Matrix
    zeta_rotation_form: bool = False


def _c_expr(s: int) -> sp.Expr:
    return s * sp.sqrt(1 - E_O**2)


def _to_polar(M: sp.Matrix, extra: dict) -> sp.Matrix:
    """Substitute the polar coordinates and the rotated velocities; simplify with c kept symbolic."""
    sy = symbols()
    sub = {sy["e_x"]: E_D * sp.cos(THETA), sy["e_y"]: E_D * sp.sin(THETA), sy["psi"]: THETA + _PHI}
    out = M.subs(sub).subs(extra)
    out = out.applyfunc(lambda x: sp.expand_trig(sp.expand(x)))
    out = out.subs({sp.sin(_PHI): E_O, sp.cos(_PHI): _C})
    out = out.applyfunc(lambda x: sp.simplify(sp.trigsimp(x)))
    if _PHI in out.free_symbols:
        raise TubekitError("polar_model: psi - theta did not reduce to (e_o, c)")
    return out


def _d_de(M: sp.Matrix) -> sp.Matrix:
    """d M / d [e_d, e_z, e_o] at fixed theta with c = c(e_o), dc/de_o = -e_o / c."""
    cols = [M.diff(E_D), M.diff(E_Z), M.diff(E_O) + M.diff(_C) * (-E_O / _C)]
    return sp.Matrix.hstack(*cols)


def _finish(M: sp.Matrix, s: int) -> sp.Matrix:
    return M.subs(_C, _c_expr(s)).applyfunc(sp.simplify)


@lru_cache(maxsize=4)
def polar_model(s: int) -> PolarModel:
    """Derive the polar-form model for hemisphere sign ``s`` (-1 toward, +1 away); cached."""
    if s not in (-1, 1):
        raise ConfigError("hemisphere sign", "-1 or +1", s)
    d = derive()
    sy = symbols()
    vel = {sy["xdot_d"]: A_V * sp.cos(THETA) - B_V * sp.sin(THETA),
           sy["ydot_d"]: A_V * sp.sin(THETA) + B_V * sp.cos(THETA)}
    om = {sy["omega_1"]: ALPHA * sp.cos(THETA) - BETA * sp.sin(THETA),
          sy["omega_2"]: ALPHA * sp.sin(THETA) + BETA * sp.cos(THETA)}
    J = _to_polar(d.J, {})
    zeta = _to_polar(d.zeta, vel)
    xi = _to_polar(d.xi, om)
    # d zeta / d theta at fixed Cartesian velocity: differentiate before rotating the velocity.
    sub = {sy["e_x"]: E_D * sp.cos(THETA), sy["e_y"]: E_D * sp.sin(THETA), sy["psi"]: THETA + _PHI}
    dth = _to_polar(d.zeta.subs(sub).diff(THETA), vel)
    u, w, r = sy["u"], sy["w"], sy["r"]
    dh = _d_de(J * sp.Matrix([u, w, r]))
    dz = _d_de(zeta)
    om_vec = [ALPHA, BETA, sy["omega_3"]]
    dxi = xi.jacobian(om_vec)
    if (xi - dxi * sp.Matrix(om_vec)).applyfunc(sp.simplify) != sp.zeros(3, 1):
        raise TubekitError("polar_model: xi is not linear in omega; the ball formula does not apply")
    G = zeta.jacobian([A_V, B_V])
    rot = (THETA not in zeta.free_symbols and THETA not in G.free_symbols
           and A_V not in G.free_symbols and B_V not in G.free_symbols
           and (dth - G * sp.Matrix([B_V, -A_V])).applyfunc(sp.simplify) == sp.zeros(3, 1))
    return PolarModel(s=s, J=_finish(J, s), zeta=_finish(zeta, s), xi=_finish(xi, s), dh_de=_finish(dh, s),
                      dzeta_de=_finish(dz, s), dzeta_dtheta=_finish(dth, s), dxi_domega=_finish(dxi, s),
                      zeta_rotation_form=bool(rot))



@lru_cache(maxsize=8)
def law_gain(law: str, s: int) -> tuple[sp.Matrix, sp.Matrix]:
    """Symbolic (K(e), J(e) K(e)) of an ancillary law in hemisphere ``s``.

    The symbolic gain is the law's ``symbolic_gain`` in :data:`tubekit.ancillary.LAWS`
    (K = I for ``paper``, K = J^-1 for ``corrected``, or a registered user law); the
    tests cross-check it against the numeric gain.
    """
    if law not in LAWS:
        raise ConfigError("law", f"one of {tuple(LAWS)}", law)
    gain = LAWS[law].symbolic_gain
    if gain is None:
        raise ConfigError("law", "a law with a symbolic gain (AncillaryLaw.symbolic_gain)", law,
                          "a law without one can be simulated and falsified, not certified")
    J = polar_model(s).J
    K = sp.Matrix(gain(J))
    if K.shape != (3, 3):
        raise ConfigError("law.symbolic_gain", "a map returning a 3x3 sympy Matrix", K.shape)
    JK = (J * K).applyfunc(sp.simplify)
    return K, JK


# --------------------------------------------------------------------------- objectives
def _gram(A: sp.Matrix) -> sp.Matrix:
    return (A.T * A).applyfunc(sp.simplify)


def _dims(expr_syms: set, region: Region) -> list[tuple[sp.Symbol, float, float]]:
    dims = []
    for sym, rng in ((E_D, region.e_d), (E_Z, region.e_z), (E_O, region.e_o), (THETA, (0.0, 2 * math.pi)),
                     (GAMMA, (0.0, 2 * math.pi))):
        if sym in expr_syms:
            dims.append((sym, float(rng[0]), float(rng[1])))
    return dims


@lru_cache(maxsize=128)
def _compiled(kind: str, A: sp.Matrix, dim_syms: tuple, par_syms: tuple):
    """Arb and numpy evaluators of an objective on matrix ``A``.

    ``kind``: ``"norm"`` (||A||_2) or ``"lmin"`` (lambda_min of the symmetric part of A).
    """
    args = list(dim_syms) + list(par_syms)
    n_r, n_c = A.shape
    G = _gram(A) if kind == "norm" else ((A + A.T) / 2).applyfunc(sp.simplify)
    m = G.shape[0]
    idx = [(i, j) for i in range(m) for j in range(i, m)]
    f_arb = compile_arb([G[i, j] for i, j in idx], args)
    f_np = compile_numpy(list(A), args)

    def entries(balls: list[arb]) -> list[list[arb]]:
        vals = f_arb(*balls)
        M = [[arb(0)] * m for _ in range(m)]
        for (i, j), v in zip(idx, vals):
            M[i][j] = v
            M[j][i] = v
        return M

    def matrices(X: np.ndarray, pars: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A at the rows of X (non-finite ones zeroed) and the mask of those rows."""
        cols = [X[:, k] for k in range(X.shape[1])] + [np.full(len(X), p) for p in pars]
        M = f_np(*cols).reshape(len(X), n_r, n_c)
        bad = ~np.all(np.isfinite(M), axis=(1, 2))
        M[bad] = 0.0
        return M, bad

    if kind == "norm":
        def interval(balls: list[arb]) -> arb:
            _, hi = sym_eig_bounds(entries(balls))
            return arb(max(hi, 0.0)).sqrt() if math.isfinite(hi) else arb("nan")

        def value(M: np.ndarray) -> np.ndarray:
            return np.linalg.svd(M, compute_uv=False)[:, 0]
    else:
        def interval(balls: list[arb]) -> arb:
            lo, _ = sym_eig_bounds(entries(balls))
            return arb(-lo) if math.isfinite(lo) else arb("nan")

        def value(M: np.ndarray) -> np.ndarray:
            return -np.linalg.eigvalsh(0.5 * (M + np.swapaxes(M, 1, 2)))[:, 0]

    def pointwise(X: np.ndarray, pars: np.ndarray) -> np.ndarray:
        M, bad = matrices(X, pars)
        out = value(M)
        out[bad] = np.nan
        return out
    return interval, pointwise


def _case(kind: str, A: sp.Matrix, region: Region, params: dict[sp.Symbol, float], label: str) -> Case:
    A = sp.ImmutableMatrix(A)
    free = A.free_symbols
    dims = _dims(free, region)
    dim_syms = tuple(d[0] for d in dims)
    par_syms = tuple(sorted((p for p in params if p in free), key=str))
    missing = free - set(dim_syms) - set(par_syms)
    if missing:
        raise TubekitError(f"bounds: unexpected free symbols {sorted(map(str, missing))} in {label}")
    interval, pointwise = _compiled(kind, A, dim_syms, par_syms)
    pars = np.array([params[p] for p in par_syms], dtype=float)
    par_balls = [point(p) for p in pars]
    return Case(
        label=label,
        names=tuple(str(s) for s in dim_syms),
        lo=np.array([d[1] for d in dims], dtype=float),
        hi=np.array([d[2] for d in dims], dtype=float),
        interval=lambda balls, _f=interval, _p=par_balls: _f(list(balls) + _p),
        point=lambda X, _f=pointwise, _p=pars: _f(np.asarray(X, dtype=float).reshape(len(X), -1), _p),
    )


def _vertex_cases(A: sp.Matrix, box: dict[sp.Symbol, float]) -> list[tuple[sp.Matrix, str]]:
    """Substitute the vertices of a symmetric box {|x_k| <= box[x_k]} for the symbols A depends on.

    A is linear in these symbols (checked); ||A(-x)|| = ||A(x)||, so vertices
    are taken up to a global sign.
    """
    syms = [x for x in box if x in A.free_symbols]
    if not syms:
        return [(A, "")]
    zero = A.subs({x: 0 for x in syms})
    lin = A - zero
    if zero != sp.zeros(*A.shape) or any(lin.diff(x).diff(y) != sp.zeros(*A.shape) for x in syms for y in syms):
        raise TubekitError("bounds: the vertex rule needs an objective linear and homogeneous in the box variables")
    out = []
    for signs in itertools.product((1, -1), repeat=len(syms) - 1):
        signs = (1,) + signs
        sub = {x: sg * box[x] for x, sg in zip(syms, signs)}
        label = ",".join(f"{x}={'+' if sg > 0 else '-'}" for x, sg in zip(syms, signs))
        out.append((A.subs(sub), label))
    return out


def _velocity_cases(A: sp.Matrix) -> list[tuple[sp.Matrix, str]]:
    """Extreme points of the velocity set: circle of radius h_xy in (a, b), vertices +-p_z in zdot_d."""
    zd = symbols()["zdot_d"]
    has_a, has_b = A_V in A.free_symbols, B_V in A.free_symbols
    if has_a and has_b:
        A = A.subs({A_V: H_XY * sp.cos(GAMMA), B_V: H_XY * sp.sin(GAMMA)})
        box = {zd: P_Z}
    else:
        box = {A_V: H_XY, B_V: H_XY, zd: P_Z}
    if zd in A.free_symbols and (has_a and has_b):
        # circle x {+-p_z}: both signs of zdot_d are needed (the circle is already symmetric)
        return [(A.subs(zd, P_Z), "zdot_d=+"), (A.subs(zd, -P_Z), "zdot_d=-")]
    return _vertex_cases(A, box)


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class BoundResult:
    """A certified bound with its sampled counterpart.

    Attributes
    ----------
    name : str
        ``L1``, ``L2``, ``J_lower``, ``xi_bar``, ...
    sampled : float
        Best value attained at a sampled point (for a sup: <= the true sup; for
        J_lower, an inf: >= the true inf).
    bound : float
        Certified bound (sup: >= true sup; inf: <= true inf).
    gap : float
        |bound - sampled| / |sampled|.
    converged : bool
        Whether the target gap was reached within the time budget.
    holds_over : str
        The set the bound holds over.
    quantity : str
        What is bounded.
    boxes : int
        Boxes the branch-and-bound evaluated.
    elapsed_s : float
        Wall time (s) (0 when served from the cache).
    argmax : dict
        Where the sampled value was attained.
    """

    name: str
    sampled: float
    bound: float
    gap: float
    converged: bool
    holds_over: str
    quantity: str
    boxes: int
    elapsed_s: float
    argmax: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """``{sampled, bound, gap, converged, holds_over, quantity, ...}``."""
        return {"sampled": self.sampled, "bound": self.bound, "gap": self.gap, "converged": self.converged,
                "holds_over": self.holds_over, "quantity": self.quantity, "boxes": self.boxes,
                "elapsed_s": round(self.elapsed_s, 4), "argmax": self.argmax}


@dataclass(frozen=True)
class Bounds:
    """All certified bounds of one (region, law)."""

    law: str
    items: dict[str, BoundResult]

    def __getitem__(self, name: str) -> BoundResult:
        return self.items[name]

    @property
    def elapsed_s(self) -> float:
        """Total branch-and-bound wall time (s)."""
        return sum(b.elapsed_s for b in self.items.values())

    def to_dict(self) -> dict:
        return {k: v.to_dict() for k, v in self.items.items()}


_QUANTITY = {
    "L1": "sup ||d(J(e) v_hat)/de||_2  (Lipschitz constant of h(e, v_hat) = J(e) v_hat in e, eq. lip_1)",
    "L2": "sup ||d zeta/de||_2 at fixed bearing  (Lipschitz constant of zeta in e, eq. lip_2)",
    "J_lower": "inf lambda_min((J K + (J K)^T)/2)  (Remark 1; J K is the law's closed-loop gain)",
    "xi_bar": "sup ||xi(e, theta, omega)||_2  (Remark 2, eq. Wset)",
    "zeta_theta": "sup ||d zeta/d theta||_2  (bearing sensitivity, used for the bearing-mismatch fold)",
    "K_row_u": "sup ||row_u(K(e))||_2  (|kappa_u| <= sigma * this * ||rho||)",
    "K_row_w": "sup ||row_w(K(e))||_2  (|kappa_w| <= sigma * this * ||rho||)",
    "K_row_r": "sup ||row_r(K(e))||_2  (|kappa_r| <= sigma * this * ||rho||)",
    "JK_norm": "sup ||J(e) K(e)||_2  (sampled-data gain limit of the ancillary loop)",
}


def _holds_over(name: str, region: Region) -> str:
    e = (f"e in R (e_d in [{region.e_d[0]:.6g}, {region.e_d[1]:.6g}], e_z in [{region.e_z[0]:.6g}, "
         f"{region.e_z[1]:.6g}], e_o in [{region.e_o[0]:.6g}, {region.e_o[1]:.6g}], heading {region.heading})")
    th = "any bearing theta"
    pd = (f"p_d_dot in P (|p_d_dot| <= {list(region.pd_dot_max)}, horizontal speed <= "
          f"{region.pd_dot_xy_max:.6g} m/s)")
    v = f"v_hat in V (|v_hat| <= {list(region.v_max)})"
    om = f"||omega|| <= {region.omega_bar:.6g} m/s"
    return {"L1": f"{e}, {v}", "L2": f"{e}, {th}, {pd}", "xi_bar": f"{e}, {th}, {om}",
            "zeta_theta": f"{e}, {th}, {pd}"}.get(name, e)


@lru_cache(maxsize=512)
def _solve(name: str, law: str, signs: tuple, e_d: tuple, e_z: tuple, e_o: tuple, params: tuple,
           gap: float, budget: float) -> MaxResult:
    region = Region(e_d=e_d, e_z=e_z, e_o=e_o, heading="both" if len(signs) == 2 else
                    ("toward" if signs[0] < 0 else "away"), pd_dot_max=(0.0, 0.0, 0.0), pd_dot_xy_max=0.0,
                    omega_bar=0.0, v_max=(1.0, 1.0, 1.0))
    par = dict(params)
    sy = symbols()
    cases: list[Case] = []
    for s in signs:
        pm = polar_model(s)
        hem = "toward" if s < 0 else "away"
        if name == "L1":
            box = {sy["u"]: U_M, sy["w"]: W_M, sy["r"]: R_M}
            vals = {U_M: par["u"], W_M: par["w"], R_M: par["r"]}
            for A, lab in _vertex_cases(pm.dh_de, box):
                cases.append(_case("norm", A, region, vals, f"{hem} {lab}".strip()))
        elif name in ("L2", "zeta_theta"):
            M = pm.dzeta_de if name == "L2" else pm.dzeta_dtheta
            for A, lab in _velocity_cases(M):
                cases.append(_case("norm", A, region, {H_XY: par["h_xy"], P_Z: par["p_z"]}, f"{hem} {lab}".strip()))
        elif name == "xi_bar":
            cases.append(_case("norm", pm.dxi_domega, region, {}, hem))
        elif name == "J_lower":
            _, JK = law_gain(law, s)
            cases.append(_case("lmin", JK, region, {}, hem))
        elif name == "JK_norm":
            _, JK = law_gain(law, s)
            cases.append(_case("norm", JK, region, {}, hem))
        elif name.startswith("K_row_"):
            K, _ = law_gain(law, s)
            i = "uwr".index(name[-1])
            cases.append(_case("norm", K[i, :].T, region, {}, hem))
        else:
            raise ConfigError("bound", f"one of {BOUND_NAMES}", name)
    return maximise(cases, gap=gap, time_budget_s=budget)


@lru_cache(maxsize=8)
def _linear_in_speed(name: str, s: int) -> bool:
    """True if the L2 / zeta_theta objective is ||M|| with M linear in (a, b) and free of zdot_d.

    Then its sup over the disc of radius h is h times the sup over the unit disc.
    """
    pm = polar_model(s)
    M = pm.dzeta_de if name == "L2" else pm.dzeta_dtheta
    if symbols()["zdot_d"] in M.free_symbols:
        return False
    zero = M.subs({A_V: 0, B_V: 0})
    second = [M.diff(x).diff(y) for x in (A_V, B_V) for y in (A_V, B_V)]
    return zero == sp.zeros(*M.shape) and all(d == sp.zeros(*M.shape) for d in second)


def compute_bounds(region: Region, law: str, *, gap: float = 0.05, time_budget_s: float = 3.0) -> Bounds:
    """Certify every bound of :data:`BOUND_NAMES` over ``region`` for ``law``.

    Parameters
    ----------
    region : Region
        The set the bounds hold over.
    law : str
        Ancillary law name (``paper`` or ``corrected``).
    gap : float
        Target relative gap between sampled and certified value (default 5 %).
    time_budget_s : float
        Branch-and-bound budget per bound (s); the gap reached is reported either way.

    Returns
    -------
    Bounds
        ``xi_bar`` is omega_bar times the certified sup of ||d xi / d omega||_2.
    """
    if law not in LAWS:
        raise ConfigError("law", f"one of {tuple(LAWS)}", law)
    if not (0 < gap < 1):
        raise ConfigError("gap", "a number in (0, 1)", gap)
    if not (time_budget_s > 0 and math.isfinite(time_budget_s)):
        raise ConfigError("time_budget_s", "a finite number > 0", time_budget_s)
    signs = region.hemisphere_signs
    common = (signs, region.e_d, region.e_z, region.e_o)
    params = {
        "L1": (("r", region.v_max[2]), ("u", region.v_max[0]), ("w", region.v_max[1])),
        "L2": (("h_xy", region.pd_dot_xy_max), ("p_z", region.pd_dot_max[2])),
        "zeta_theta": (("h_xy", region.pd_dot_xy_max), ("p_z", region.pd_dot_max[2])),
    }
    # sups that are homogeneous of degree 1 in a scalar parameter are solved at parameter 1 and scaled
    scale = {"xi_bar": region.omega_bar}
    for name in ("L2", "zeta_theta"):
        if all(_linear_in_speed(name, s) for s in signs):
            params[name] = (("h_xy", 1.0), ("p_z", 0.0))
            scale[name] = region.pd_dot_xy_max
    items: dict[str, BoundResult] = {}
    for name in BOUND_NAMES:
        key_law = law if name in ("J_lower", "JK_norm") or name.startswith("K_row_") else ""
        info0 = _solve.cache_info().hits
        res = _solve(name, key_law or "paper", *common, params.get(name, ()), float(gap), float(time_budget_s))
        cached = _solve.cache_info().hits > info0
        sampled, bound = res.sampled, res.bound
        if name == "J_lower":
            sampled, bound = -sampled, -res.bound
        if name in scale:
            k = scale[name]
            sampled = sampled * k
            bound = upper(arb(res.bound) * arb(k)) if math.isfinite(res.bound) else math.inf
        items[name] = BoundResult(name=name, sampled=float(sampled), bound=float(bound), gap=float(res.gap),
                                  converged=res.converged, holds_over=_holds_over(name, region),
                                  quantity=_QUANTITY[name], boxes=res.boxes,
                                  elapsed_s=0.0 if cached else res.elapsed_s, argmax=dict(res.argmax[1],
                                                                                          case=res.argmax[0]))
    return Bounds(law=law, items=items)
