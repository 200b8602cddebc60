"""Certified bounds L1, L2, J_lower, xi_bar (and the auxiliary sups) by branch-and-bound.

The objectives are matrices of the polar-form model (:mod:`verify.lemma1.polar`).
Because (a, b) is a rotation of p_d_dot_xy and the region's velocity set is
contained in the disc of radius ``pd_dot_xy_max`` (rotation invariant), a sup
over all bearings and velocities equals a sup over (a, b) in that disc. Each sup
of a convex function of the linear parameters (v_hat, p_d_dot) is taken at
extreme points: vertices of boxes, the circle a = h cos(gamma), b = h sin(gamma)
of the disc. omega enters xi linearly, so sup over the ball is
omega_bar * ||d xi / d omega||_2.

Objectives are enclosed in Arb (:mod:`verify.kernel.intervals`): a matrix 2-norm as
sqrt(lambda_max(A^T A)) of the symbolically simplified Gram matrix, lambda_min of
a symmetric matrix via :func:`verify.kernel.intervals.sym_eig_bounds`. The objectives (one matrix per case)
are built and compiled by :mod:`verify.lemma1.objectives` (sympy); for the built-in laws they ship
compiled (:mod:`verify.kernel.compiled`), so a certificate's route needs no sympy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Callable

import numpy as np
from flint import arb

from tubekit.model.ancillary import LAWS
from tubekit.exceptions import ConfigError

from verify.kernel.compiled import LAW_BOUNDS, Objective, route_objectives
from verify.kernel.compiled import linear_in_speed as shipped_linear_in_speed
from verify.kernel.intervals import Case, MaxResult, maximise, point, sym_eig_bounds, upper
from verify.kernel.region import Region

__all__ = [
    "BoundResult",
    "Bounds",
    "compute_bounds",
    "BOUND_NAMES",
]

#: Reported bounds: the four of issue item 2 and the auxiliary sups the certificate uses.
BOUND_NAMES = ("L1", "L2", "J_lower", "xi_bar", "zeta_theta", "K_row_u", "K_row_w", "K_row_r", "JK_norm")


# --------------------------------------------------------------------------- objectives
def _dims(names: tuple[str, ...], region: Region) -> list[tuple[float, float]]:
    """(lo, hi) of each branch-and-bound dimension (m, -, rad)."""
    ranges = {"e_d": region.e_d, "e_z": region.e_z, "e_o": region.e_o, "theta": (0.0, 2 * math.pi),
              "gamma": (0.0, 2 * math.pi)}
    return [(float(ranges[n][0]), float(ranges[n][1])) for n in names]


@lru_cache(maxsize=128)
def _evaluators(obj: Objective) -> tuple[Callable[[list[arb]], arb], Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """(interval, pointwise) of an objective: ``kind`` ``norm`` (||A||_2) or ``lmin`` (-lambda_min of the
    symmetric part of A, so that every bound is a sup)."""
    kind, f_arb, f_np = obj.kind, obj.arb, obj.numpy
    n_r, n_c = obj.shape
    m = n_c
    idx = [(i, j) for i in range(m) for j in range(i, m)]

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


def _case(obj: Objective, region: Region, params: dict[str, float]) -> Case:
    """The branch-and-bound case of ``obj`` over ``region`` with its parameters (by name) fixed."""
    dims = _dims(obj.dims, region)
    interval, pointwise = _evaluators(obj)
    pars = np.array([params[p] for p in obj.pars], dtype=float)
    par_balls = [point(p) for p in pars]
    return Case(
        label=obj.label,
        names=obj.dims,
        lo=np.array([d[0] for d in dims], dtype=float),
        hi=np.array([d[1] for d in dims], dtype=float),
        interval=lambda balls, _f=interval, _p=par_balls: _f(list(balls) + _p),
        point=lambda X, _f=pointwise, _p=pars: _f(np.asarray(X, dtype=float).reshape(len(X), -1), _p),
    )


def _objectives(name: str, law: str, s: int) -> tuple[Objective, ...]:
    """The cases of bound ``name`` in hemisphere ``s``: shipped compiled, or derived now (another law, stale code)."""
    shipped = route_objectives(name, law, s)
    if shipped is not None:
        return shipped
    from verify.lemma1.objectives import derived_objectives

    return derived_objectives(name, law or "paper", s)


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
        Whether the target gap was reached within the box budget.
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
        """``{name: BoundResult.to_dict()}``."""
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
    """Printable description of the set bound ``name`` holds over."""
    e = (f"e in R (e_d in [{region.e_d[0]:.6g}, {region.e_d[1]:.6g}], e_z in [{region.e_z[0]:.6g}, "
         f"{region.e_z[1]:.6g}], e_o in [{region.e_o[0]:.6g}, {region.e_o[1]:.6g}], heading {region.heading})")
    th = "any bearing theta"
    pd = (f"p_d_dot in P (|p_d_dot| <= {list(region.pd_dot_max)}, horizontal speed <= "
          f"{region.pd_dot_xy_max:.6g} m/s)")
    v = f"v_hat in V (|v_hat| <= {list(region.v_max)})"
    om = f"||omega|| <= {region.omega_bar:.6g} m/s"
    return {"L1": f"{e}, {v}", "L2": f"{e}, {th}, {pd}", "xi_bar": f"{e}, {th}, {om}",
            "zeta_theta": f"{e}, {th}, {pd}"}.get(name, e)


def _hemisphere_cases(name: str, law: str, s: int, region: Region, par: dict[str, float]) -> list[Case]:
    """The branch-and-bound cases of bound ``name`` in hemisphere ``s`` (extreme points of its parameters)."""
    if name not in BOUND_NAMES:
        raise ConfigError("bound", f"one of {BOUND_NAMES}", name)
    if name == "L1":
        values = {"u_max": par["u"], "w_max": par["w"], "r_max": par["r"]}
    elif name in ("L2", "zeta_theta"):
        values = {"h_xy": par["h_xy"], "p_z": par["p_z"]}
    else:
        values = {}
    return [_case(obj, region, values) for obj in _objectives(name, law, s)]


@lru_cache(maxsize=512)
def _solve(name: str, law: str, signs: tuple, e_d: tuple, e_z: tuple, e_o: tuple, params: tuple,
           gap: float, budget: int) -> MaxResult:
    """Branch-and-bound maximum of bound ``name`` over the error box (hashable arguments: cached; ``law`` is ""
    for a bound that does not depend on the law)."""
    region = Region(e_d=e_d, e_z=e_z, e_o=e_o, heading="both" if len(signs) == 2 else
                    ("toward" if signs[0] < 0 else "away"), pd_dot_max=(0.0, 0.0, 0.0), pd_dot_xy_max=0.0,
                    omega_bar=0.0, v_max=(1.0, 1.0, 1.0))
    par = dict(params)
    cases: list[Case] = []
    for s in signs:
        cases.extend(_hemisphere_cases(name, law, s, region, par))
    return maximise(cases, gap=gap, max_boxes=budget)


def _linear_in_speed(name: str, s: int) -> bool:
    """True if the L2 / zeta_theta objective is ||M|| with M linear in (a, b) and free of zdot_d
    (:func:`verify.lemma1.objectives.linear_in_speed`; shipped with the compiled objectives).

    Then its sup over the disc of radius h is h times the sup over the unit disc.
    """
    shipped = shipped_linear_in_speed(name, s)
    if shipped is not None:
        return shipped
    from verify.lemma1.objectives import linear_in_speed

    return linear_in_speed(name, s)


def compute_bounds(region: Region, law: str, *, gap: float = 0.05, max_boxes: int = 20000,
                   names: tuple[str, ...] = BOUND_NAMES) -> Bounds:
    """Certify the bounds ``names`` (default every one of :data:`BOUND_NAMES`) over ``region`` for ``law``.

    Parameters
    ----------
    region : Region
        The set the bounds hold over.
    law : str
        Ancillary law name (``paper`` or ``corrected``).
    gap : float
        Target relative gap between sampled and certified value (default 5 %).
    max_boxes : int
        Branch-and-bound budget per bound (boxes: a work unit, so the result does not depend on
        machine load); the gap reached is reported either way.
    names : tuple of str
        Which bounds to certify (a subset of :data:`BOUND_NAMES`).

    Returns
    -------
    Bounds
        ``xi_bar`` is omega_bar times the certified sup of ||d xi / d omega||_2.
    """
    if law not in LAWS:
        raise ConfigError("law", f"one of {tuple(LAWS)}", law)
    if not (0 < gap < 1):
        raise ConfigError("gap", "a number in (0, 1)", gap)
    if not isinstance(max_boxes, int) or isinstance(max_boxes, bool) or max_boxes < 1:
        raise ConfigError("max_boxes", "an integer >= 1", max_boxes)
    unknown = [n for n in names if n not in BOUND_NAMES] if isinstance(names, tuple) else [names]
    if unknown or not names:
        raise ConfigError("names", f"a non-empty tuple of names in {BOUND_NAMES}", unknown[0] if unknown else names)
    signs = region.hemisphere_signs
    common = (signs, region.e_d, region.e_z, region.e_o)
    params, scale = _solver_parameters(region)
    items: dict[str, BoundResult] = {}
    for name in names:
        key_law = law if name in LAW_BOUNDS else ""
        info0 = _solve.cache_info().hits
        res = _solve(name, key_law, *common, params.get(name, ()), float(gap), int(max_boxes))
        cached = _solve.cache_info().hits > info0
        items[name] = _bound_result(name, res, scale.get(name), region, cached)
    return Bounds(law=law, items=items)


def _solver_parameters(region: Region) -> tuple[dict[str, tuple], dict[str, float]]:
    """Per-bound solver parameters (hashable) and the factors the solved sups are scaled by.

    Sups that are homogeneous of degree 1 in a scalar parameter are solved at
    parameter 1 and scaled: ``xi_bar`` by omega_bar (m/s), and ``L2`` /
    ``zeta_theta`` by the horizontal target speed (m/s) when linear in it.
    """
    params = {
        "L1": (("r", region.v_max[2]), ("u", region.v_max[0]), ("w", region.v_max[1])),
        "L2": (("h_xy", region.pd_dot_xy_max), ("p_z", region.pd_dot_max[2])),
        "zeta_theta": (("h_xy", region.pd_dot_xy_max), ("p_z", region.pd_dot_max[2])),
    }
    scale = {"xi_bar": region.omega_bar}
    for name in ("L2", "zeta_theta"):
        if all(_linear_in_speed(name, s) for s in region.hemisphere_signs):
            params[name] = (("h_xy", 1.0), ("p_z", 0.0))
            scale[name] = region.pd_dot_xy_max
    return params, scale


def _bound_result(name: str, res: MaxResult, scale: float | None, region: Region, cached: bool) -> BoundResult:
    """The reported :class:`BoundResult` of a solved sup: sign-flipped for ``J_lower``, scaled by ``scale``."""
    sampled, bound = res.sampled, res.bound
    if name == "J_lower":
        sampled, bound = -sampled, -res.bound
    if scale is not None:
        sampled = sampled * scale
        bound = upper(arb(res.bound) * arb(scale)) if math.isfinite(res.bound) else math.inf
    return BoundResult(name=name, sampled=float(sampled), bound=float(bound), gap=float(res.gap),
                       converged=res.converged, holds_over=_holds_over(name, region), quantity=_QUANTITY[name],
                       boxes=res.boxes, elapsed_s=0.0 if cached else res.elapsed_s,
                       argmax=dict(res.argmax[1], case=res.argmax[0]))
