"""Rigorous interval enclosures (python-flint ``arb``) and branch-and-bound maximisation.

Everything that ends up in a certificate as a *bound* is computed here with
Arb ball arithmetic, which rounds outward: an ``arb`` result always contains
the exact value for every point of its input balls. Floats leave this module
only through :func:`upper` / :func:`lower`, which round in the safe direction.

* :func:`enclose` turns a float box edge pair into a ball containing it.
* :func:`compile_arb` turns sympy expressions into a Python function over
  ``arb`` (exact rationals, ``sqrt``/``sin``/``cos``/``Abs``; no floats allowed),
  :func:`compile_numpy` into a vectorised numpy function (for sampling).
* :func:`sym_eig_bounds` bounds the eigenvalues of a symmetric interval matrix
  (Gershgorin discs in the eigenbasis of the midpoint matrix, with the basis
  change inverted rigorously in Arb).
* :func:`maximise` is a best-first branch-and-bound over a union of boxes that
  reports the best sampled value and a certified upper bound.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np
from flint import arb, arb_mat

if TYPE_CHECKING:  # sympy is imported on first compilation: the precompiled objectives need none
    import sympy as sp

__all__ = [
    "bisect_sup",
    "raise_upper",
    "float_top",
    "enclose",
    "point",
    "upper",
    "lower",
    "arb_source",
    "compile_arb",
    "compile_numpy",
    "vectorised",
    "sym_eig_bounds",
    "Case",
    "MaxResult",
    "maximise",
    "relative_gap",
]


# --------------------------------------------------------------------------- conversions
def enclose(lo: float, hi: float) -> arb:
    """A ball containing the closed float interval [lo, hi]."""
    lo, hi = float(lo), float(hi)
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
        raise ValueError(f"enclose: need finite lo <= hi, got [{lo}, {hi}]")
    if lo == hi:
        return arb(lo)
    return arb.union(arb(lo), arb(hi))


def point(x: float) -> arb:
    """The exact ball {x} of a finite float."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"point: need a finite float, got {x}")
    return arb(x)


def upper(x: arb) -> float:
    """A float >= every point of ``x`` (``inf`` if ``x`` is not finite)."""
    if not x.is_finite():
        return math.inf
    u = x.upper()  # an exact ball: its float is its midpoint's
    f = float(u)
    while not (arb(f) >= u):
        f = math.nextafter(f, math.inf)
    return f


def float_top(x: arb) -> float:
    """mid + rad of ``x`` in floats: within a few ulps of :func:`upper` of it (nan or inf where it is not finite)."""
    return float(x.mid()) + float(x.rad())


def raise_upper(best: float, x: arb) -> float:
    """max(``best``, :func:`upper` of ``x``) for a ball ``x`` >= 0 (an absolute value, a norm): the exact upper bound
    is taken only where the ball's float top, mid + rad, comes within a relative 1e-12 of ``best`` or is not finite;
    below that its upper bound, at most a few ulps above mid + rad, cannot reach ``best``. A running maximum over
    many balls then costs about one float conversion a ball."""
    top = float_top(x)
    if top < best * (1.0 - 1e-12):
        return best
    return max(best, upper(x))


def lower(x: arb) -> float:
    """A float <= every point of ``x`` (``-inf`` if ``x`` is not finite)."""
    if not x.is_finite():
        return -math.inf
    lo = x.lower()
    f = float(lo)
    while not (arb(f) <= lo):
        f = math.nextafter(f, -math.inf)
    return f


# --------------------------------------------------------------------------- sympy -> arb
def _abs(x: arb) -> arb:
    """|x| as a ball inside [0, sup|x|] (arb's own abs keeps the ball's midpoint-radius form)."""
    return arb.union(x.abs_lower(), x.abs_upper())


def _pow_int(x: arb, n: int) -> arb:
    """x**n (n >= 1) from the endpoints: t -> t**n is monotone on [0, inf) and, for odd n, on R."""
    if n == 1:
        return x
    if n % 2 == 0:
        return arb.union(x.abs_lower() ** n, x.abs_upper() ** n)
    return arb.union(x.lower() ** n, x.upper() ** n)


class _ArbPrinter:
    """Prints a sympy expression as Python source over arb values.

    Rationals become exact arb constants, even powers go through ``abs`` (so
    ``x**2`` of a ball straddling 0 stays >= 0), ``sqrt`` maps to ``arb.sqrt``.
    Floats are rejected: a decimal float inside an expression would not be exact.
    """

    def __init__(self, names: dict[sp.Symbol, str], prefix: str = "_k") -> None:
        self.names = names
        self.prefix = prefix
        self.consts: dict[str, tuple[int, int]] = {}

    def _const(self, value: sp.Rational) -> str:
        key = f"{self.prefix}{len(self.consts)}"
        self.consts[key] = (int(value.p), int(value.q))
        return key

    def code(self, e: sp.Expr) -> str:
        import sympy as sp

        if isinstance(e, sp.Symbol):
            if e not in self.names:
                raise ValueError(f"compile_arb: free symbol {e} is not an argument")
            return self.names[e]
        if isinstance(e, sp.Integer):
            return f"_arb({int(e)})"
        if isinstance(e, sp.Rational):
            return self._const(e)
        if isinstance(e, sp.Float):
            raise ValueError(f"compile_arb: float constant {e} is not exact; use a Rational or a parameter")
        if e is sp.pi:
            return "_arb.pi()"
        if isinstance(e, sp.Add):
            return "(" + " + ".join(self.code(a) for a in e.args) + ")"
        if isinstance(e, sp.Mul):
            return "(" + " * ".join(self.code(a) for a in e.args) + ")"
        if isinstance(e, sp.Pow):
            base, ex = e.args
            b = self.code(base)
            if isinstance(ex, sp.Integer):
                n = int(ex)
                if n == 0:
                    return "_arb(1)"
                pw = f"_pw({b}, {abs(n)})"
                return pw if n > 0 else f"(_arb(1) / {pw})"
            if ex == sp.Rational(1, 2):
                return f"(({b}).sqrt())"
            if ex == sp.Rational(-1, 2):
                return f"(({b}).rsqrt())"
            if isinstance(ex, sp.Rational) and ex.q == 2:
                return f"((({b}).sqrt())**{int(ex.p)})" if ex.p > 0 else f"(_arb(1) / (({b}).sqrt())**{-int(ex.p)})"
            raise ValueError(f"compile_arb: unsupported power {e}")
        if isinstance(e, sp.sin):
            return f"(({self.code(e.args[0])}).sin())"
        if isinstance(e, sp.cos):
            return f"(({self.code(e.args[0])}).cos())"
        if isinstance(e, sp.Abs):
            return f"_abs({self.code(e.args[0])})"
        raise ValueError(f"compile_arb: unsupported expression {sp.srepr(e)[:80]}")


def arb_source(exprs: Sequence[sp.Expr], args: Sequence[sp.Symbol], name: str = "_f",
               prefix: str = "_k") -> tuple[str, dict[str, tuple[int, int]]]:
    """Python source of ``name(a0, a1, ...) -> list[arb]`` enclosing ``exprs``, and its rational constants.

    The source refers to ``_arb`` (:class:`flint.arb`), ``_pw`` (:func:`_pow_int`), ``_abs`` (:func:`_abs`)
    and to the constants, named ``prefix`` + number and given as exact (numerator, denominator) pairs
    (each bound to ``arb(p) / q``). Common subexpressions are evaluated once (``sympy.cse``).
    """
    import sympy as sp

    exprs = [sp.sympify(e) for e in exprs]
    names = {s: f"a{i}" for i, s in enumerate(args)}
    repl, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_t"))
    printer = _ArbPrinter(names, prefix)
    lines = [f"def {name}({', '.join(names[s] for s in args)}):"]
    for sym, sub in repl:
        names[sym] = str(sym)
        lines.append(f"    {sym} = {printer.code(sub)}")
    lines.append("    return [" + ", ".join(printer.code(e) for e in reduced) + "]")
    return "\n".join(lines), printer.consts


def compile_arb(exprs: Sequence[sp.Expr], args: Sequence[sp.Symbol]) -> Callable[..., list[arb]]:
    """Compile sympy expressions into ``f(*arb_args) -> list[arb]`` (rigorous enclosures).

    Common subexpressions are evaluated once (``sympy.cse``). Every operation
    is an Arb ball operation, so the result encloses the exact values of the
    expressions for every point of the argument balls (where defined; a ball
    touching a singularity returns a non-finite result).
    """
    source, consts = arb_source(exprs, args)
    namespace: dict = {"_arb": arb, "_pw": _pow_int, "_abs": _abs,
                       **{k: arb(p) / q for k, (p, q) in consts.items()}}
    exec(source, namespace)  # noqa: S102 - generated from sympy, no user text
    return namespace["_f"]


def vectorised(fn: Callable[..., Sequence]) -> Callable[..., np.ndarray]:
    """``fn(*arrays) -> sequence of arrays`` as ``f(*arrays)`` returning shape ``broadcast + (len,)`` (floats)."""

    def call(*values: np.ndarray) -> np.ndarray:
        arrays = [np.asarray(v, dtype=float) for v in values]
        shape = np.broadcast_shapes(*(a.shape for a in arrays)) if arrays else ()
        with np.errstate(all="ignore"):
            out = fn(*arrays)
            res = np.empty(shape + (len(out),))
            for i, o in enumerate(out):
                res[..., i] = o  # each entry broadcast and cast to float, as np.stack of broadcast_to would
        return res

    return call


def compile_numpy(exprs: Sequence[sp.Expr], args: Sequence[sp.Symbol]) -> Callable[..., np.ndarray]:
    """Compile sympy expressions into a vectorised numpy function (:func:`vectorised` of ``sympy.lambdify``).

    ``f(*arrays)`` returns an array of shape ``broadcast(arrays).shape + (len(exprs),)``.
    Used only for sampling (the *sampled* side of a bound pair), never for bounds.
    """
    import sympy as sp

    return vectorised(sp.lambdify(list(args), [sp.sympify(e) for e in exprs], modules="numpy", cse=True))


# --------------------------------------------------------------------------- eigenvalues
def sym_eig_bounds(entries: Sequence[Sequence[arb]]) -> tuple[float, float]:
    """Rigorous (lower bound of lambda_min, upper bound of lambda_max) of a symmetric interval matrix.

    Every real symmetric matrix contained entrywise in ``entries`` has all its
    eigenvalues in the returned interval. Method: with Q the (float) eigenvectors
    of the midpoint, B = Q^-1 A Q is enclosed in Arb (Q^-1 enclosed by Arb's
    rigorous inverse); A and B are similar, so Gershgorin's discs of B contain
    the (real) eigenvalues of A. The plain Gershgorin bound of A is also taken
    and the tighter of the two returned.
    """
    n = len(entries)
    A = [[entries[i][j] for j in range(n)] for i in range(n)]
    if not all(x.is_finite() for row in A for x in row):
        return -math.inf, math.inf

    def gersh(M) -> tuple[float, float]:
        lo_b, hi_b = math.inf, -math.inf
        for i in range(n):
            rad = arb(0)
            for j in range(n):
                if j != i:
                    rad += abs(M[i, j]) if isinstance(M, arb_mat) else abs(M[i][j])
            d = M[i, i] if isinstance(M, arb_mat) else M[i][i]
            lo_b = min(lo_b, lower(d - rad))
            hi_b = max(hi_b, upper(d + rad))
        return lo_b, hi_b

    lo0, hi0 = gersh(A)
    mid = np.array([[float(A[i][j].mid()) for j in range(n)] for i in range(n)])
    mid = 0.5 * (mid + mid.T)
    try:
        _, Q = np.linalg.eigh(mid)
        Qa = arb_mat([[float(q) for q in row] for row in Q])
        B = Qa.inv() * arb_mat(A) * Qa
    except (ZeroDivisionError, ValueError, np.linalg.LinAlgError):
        return lo0, hi0
    lo1, hi1 = gersh(B)
    return max(lo0, lo1), min(hi0, hi1)


# --------------------------------------------------------------------------- branch and bound
@dataclass(frozen=True)
class Case:
    """One box of a maximisation problem (the problem is the union of its cases).

    Attributes
    ----------
    label : str
        Names the discrete choice (hemisphere, vertex of V, ...).
    names : tuple of str
        Names of the box dimensions.
    lo, hi : array (d,)
        Box edges.
    interval : callable
        ``interval(list_of_arb_balls) -> arb`` enclosing the objective over the ball product.
    point : callable
        ``point(X (n, d)) -> (n,)`` float objective at points (NaN allowed).
    """

    label: str
    names: tuple[str, ...]
    lo: np.ndarray
    hi: np.ndarray
    interval: Callable[[list[arb]], arb]
    point: Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class MaxResult:
    """Outcome of :func:`maximise`.

    Attributes
    ----------
    sampled : float
        Best objective value found at an actual point (a lower bound of the sup).
    bound : float
        Certified upper bound of the sup (rigorous).
    gap : float
        (bound - sampled) / |sampled| (``inf`` when sampled is 0 and bound > 0).
    converged : bool
        True when ``gap <= target`` was reached within the box budget.
    boxes : int
        Boxes evaluated.
    elapsed_s : float
        Wall time (s).
    argmax : tuple
        (case label, point as dict) where ``sampled`` was attained.
    """

    sampled: float
    bound: float
    gap: float
    converged: bool
    boxes: int
    elapsed_s: float
    argmax: tuple = field(default=("", {}))


def relative_gap(sampled: float, bound: float) -> float:
    """(bound - sampled) / |sampled|, 0 when equal, inf when sampled = 0 < bound."""
    if bound <= sampled:
        return 0.0
    if sampled == 0.0:
        return math.inf
    return (bound - sampled) / abs(sampled)


def _box_balls(lo: np.ndarray, hi: np.ndarray) -> list[arb]:
    return [enclose(a, b) for a, b in zip(lo, hi)]


#: Iterations of the compass search that refines the sampled lower bound (a work unit, not seconds).
REFINE_STEPS = 60


def _sample(case: Case, n: int, rng: np.random.Generator) -> tuple[float, np.ndarray]:
    """Best point value of a case: random + corner sampling, then local refinement (:func:`_refine`)."""
    d = len(case.lo)
    if d == 0:
        v = float(np.asarray(case.point(np.zeros((1, 0))))[0])
        return (v if math.isfinite(v) else -math.inf), np.zeros(0)
    width = case.hi - case.lo
    X = case.lo + width * rng.random((n, d))
    corners = np.array(list(itertools.product(*zip(case.lo, case.hi))), dtype=float)
    X = np.vstack([X, corners, 0.5 * (case.lo + case.hi)])
    vals = np.asarray(case.point(X), dtype=float)
    vals = np.where(np.isfinite(vals), vals, -np.inf)
    order = np.argsort(vals)[::-1][:4]
    best_v, best_x = float(vals[order[0]]), X[order[0]].copy()
    for k in order:
        v, x = _refine(case, X[k].copy(), float(vals[k]))
        if v > best_v:
            best_v, best_x = v, x
    return best_v, best_x


def _refine(case: Case, x: np.ndarray, v: float, steps: int = REFINE_STEPS) -> tuple[float, np.ndarray]:
    """Compass search inside the box from ``x`` (value ``v``): the best of x ± s e_j, evaluated in one batch;
    the step s halves when none improves. Only the sampled lower bound uses it (numpy, no import cost)."""
    step = 0.25 * (case.hi - case.lo)
    eye = np.eye(len(x))
    for _ in range(steps):
        cand = np.clip(np.vstack([x + eye * step, x - eye * step]), case.lo, case.hi)
        vals = np.asarray(case.point(cand), dtype=float)
        vals = np.where(np.isfinite(vals), vals, -np.inf)
        k = int(np.argmax(vals))
        if vals[k] > v:
            x, v = cand[k], float(vals[k])
        else:
            step = 0.5 * step
    return v, x


def maximise(cases: Sequence[Case], *, gap: float = 0.05, max_boxes: int = 20000,
             n_samples: int = 1500, seed: int = 0) -> MaxResult:
    """Certified sup of an objective over a union of boxes (best-first branch-and-bound).

    The sampled value comes from dense random sampling, the box corners and a
    few L-BFGS-B refinements (plus the centre of every box the search visits).
    The bound is the largest Arb enclosure upper end among the boxes still
    open; the box with the largest upper end is split along its widest
    (relative to the initial box) dimension. Stops when the relative gap is
    <= ``gap`` or after ``max_boxes`` boxes (a work unit, never the clock, so the
    result is the same on an idle or a loaded machine); the gap reached is reported
    either way.
    """
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    best, arg = -math.inf, ("", {})
    for case in cases:
        v, x = _sample(case, n_samples, rng)
        if v > best:
            best, arg = v, (case.label, dict(zip(case.names, map(float, x))))
    heap: list = []
    counter = itertools.count()
    boxes = 0
    scales = [np.where(c.hi > c.lo, c.hi - c.lo, 1.0) for c in cases]

    def push(ci: int, lo: np.ndarray, hi: np.ndarray) -> None:
        nonlocal boxes
        boxes += 1
        enc = cases[ci].interval(_box_balls(lo, hi))
        ub = upper(enc)
        if math.isnan(ub):
            ub = math.inf
        heapq.heappush(heap, (-ub, next(counter), ci, lo, hi))

    for ci, c in enumerate(cases):
        push(ci, c.lo.astype(float), c.hi.astype(float))
    while True:
        ub = -heap[0][0]
        g = relative_gap(best, ub)
        if g <= gap or boxes >= max_boxes:
            break
        _, _, ci, lo, hi = heapq.heappop(heap)
        case = cases[ci]
        if len(lo) == 0 or np.all(hi - lo <= 1e-15 * np.maximum(1.0, np.abs(lo))):
            heapq.heappush(heap, (-ub, next(counter), ci, lo, hi))
            break
        k = int(np.argmax((hi - lo) / scales[ci]))
        m = 0.5 * (lo[k] + hi[k])
        h1, l2 = hi.copy(), lo.copy()
        h1[k], l2[k] = m, m
        for a, b in ((lo, h1), (l2, hi)):
            centre = 0.5 * (a + b)
            v = float(np.asarray(case.point(centre[None, :]))[0])
            if math.isfinite(v) and v > best:
                best, arg = v, (case.label, dict(zip(case.names, map(float, centre))))
            push(ci, a, b)
    ub = -heap[0][0]
    g = relative_gap(best, ub)
    return MaxResult(sampled=best, bound=ub, gap=g, converged=g <= gap, boxes=boxes,
                     elapsed_s=time.perf_counter() - t0, argmax=arg)


def bisect_sup(upper_bound: Callable[[float, float], float], lo: float, hi: float,
               max_boxes: int) -> tuple[float, int]:
    """(bound, intervals): the largest of ``upper_bound(a, b)`` over a cover of [lo, hi] by bisection.

    An interval is split until its bound is negative, the intervals used and pending reach ``max_boxes``
    (so at most ``max_boxes + 1`` evaluations), or it is narrower than 1e-9; the bound returned holds over [lo, hi] whenever each ``upper_bound(a, b)`` is an
    upper bound over [a, b]. The proof of a negative supremum (e.g. V̇ on a level set) is a negative result.
    """
    pending, done, used = [(lo, hi)], [], 0
    while pending:
        a, b = pending.pop()
        bound = upper_bound(a, b)
        used += 1
        if bound < 0.0 or used + len(pending) >= max_boxes or b - a < 1e-9:
            done.append(bound)
            continue
        mid = 0.5 * (a + b)
        pending += [(mid, b), (a, mid)]
    return max(done), used
