"""Audit of the paper's printed error dynamics against the sympy derivation.

For each of the 15 terms of eq. (18) (``J[i,j]``, ``zeta[i]``, ``xi[i]``) the
audit tries a symbolic proof that print - derivation == 0 (in polar form
e_x = d cos(theta), e_y = d sin(theta), psi = theta + phi, d > 0) and evaluates
both at random points (both heading hemispheres, e_d down to 1e-6 m). A term
matches when the numeric difference is within rounding everywhere.

It also checks Remark 1 as numbers: where the derived J is singular, and the
range and sign of lambda_min((J + J^T)/2) in each heading hemisphere
("toward": cos(psi - atan2(e_y, e_x)) < 0, the vehicle points at the target).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from functools import lru_cache
from typing import Mapping

import numpy as np
import sympy as sp

from tubekit.model.derivation import SYMBOL_NAMES, derive, symbols
from tubekit.paper.equations import TERM_NAMES, printed_terms

__all__ = [
    "TermAudit",
    "HemisphereCheck",
    "AuditReport",
    "derived_terms",
    "audit",
]


@dataclass(frozen=True)
class TermAudit:
    """One term of eq. (18): the print, the derivation and whether they agree."""

    name: str
    paper: str
    derived: str
    match: bool
    symbolic_zero: bool | None
    max_abs_diff: float
    max_rel_diff: float


@dataclass(frozen=True)
class HemisphereCheck:
    """lambda_min of the symmetric part of a J over one heading hemisphere (sampled)."""

    heading: str
    source: str
    samples: int
    lambda_min_min: float
    lambda_min_max: float
    negative_fraction: float
    e_d_range: tuple[float, float]


@dataclass(frozen=True)
class AuditReport:
    """Result of :func:`audit`; ``mismatches`` lists the flagged term names."""

    terms: list[TermAudit]
    det_J: str
    singular_set: str
    sym_eigenvalues: list[str]
    hemispheres: list[HemisphereCheck]
    samples: int
    seed: int
    mismatches: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready dict with the ``terms`` list first."""
        return {
            "terms": [asdict(t) for t in self.terms],
            "mismatches": list(self.mismatches),
            "jacobian": {
                "det_J": self.det_J,
                "singular_set": self.singular_set,
                "sym_part_eigenvalues": self.sym_eigenvalues,
                "remark_1": [asdict(h) for h in self.hemispheres],
            },
            "samples": self.samples,
            "seed": self.seed,
        }

    def table(self) -> str:
        """A readable plain-text table."""
        lines = [f"{'term':<9} {'match':<6} {'max|diff|':>10}  paper  |  derived"]
        for t in self.terms:
            flag = "yes" if t.match else "NO"
            lines.append(f"{t.name:<9} {flag:<6} {t.max_abs_diff:10.2e}  {t.paper}  |  {t.derived}")
        lines.append("")
        lines.append(f"det(J_derived) = {self.det_J}")
        lines.append(f"J_derived is singular where {self.singular_set}")
        lines.append("eigenvalues of (J+J^T)/2 (derived; c = cos(psi - bearing), s = e_o = sin(psi - bearing), "
                     f"d = e_d): {', '.join(self.sym_eigenvalues)}")
        lines.append("Remark 1 (lambda_min((J+J^T)/2) > 0 on E), sampled:")
        for h in self.hemispheres:
            lines.append(
                f"  {h.source:<8} {h.heading:<7} lambda_min in [{h.lambda_min_min:.3g}, {h.lambda_min_max:.3g}], "
                f"negative at {100 * h.negative_fraction:.1f}% of {h.samples} points "
                f"(e_d in [{h.e_d_range[0]:g}, {h.e_d_range[1]:g}] m)")
        lines.append("")
        if self.mismatches:
            lines.append(f"{len(self.mismatches)} of {len(self.terms)} printed terms differ from the derivation: "
                         + ", ".join(self.mismatches))
        else:
            lines.append("All printed terms agree with the derivation.")
        return "\n".join(lines)


@lru_cache(maxsize=1)
def derived_terms() -> dict[str, sp.Expr]:
    """The 15 derived terms keyed like :data:`tubekit.paper.equations.TERM_NAMES`."""
    d = derive()
    out: dict[str, sp.Expr] = {}
    for i in range(3):
        for j in range(3):
            out[f"J[{i},{j}]"] = d.J[i, j]
    for i in range(3):
        out[f"zeta[{i}]"] = d.zeta[i]
        out[f"xi[{i}]"] = d.xi[i]
    return {name: out[name] for name in TERM_NAMES}


def _polar(expr: sp.Expr) -> sp.Expr:
    s = symbols()
    dist, theta, phi = sp.symbols("d theta phi", positive=True)
    return sp.simplify(expr.subs({s["e_x"]: dist * sp.cos(theta), s["e_y"]: dist * sp.sin(theta)})
                       .subs(s["psi"], theta + phi))


def _symbolic_zero(diff: sp.Expr) -> bool | None:
    try:
        z = sp.simplify(sp.expand_trig(_polar(diff)))
    except Exception:  # sympy may fail on odd user input: the numeric check decides
        return None
    if z == 0:
        return True
    return None if z.free_symbols else bool(z == 0)


def _sample_points(n: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
    e_d = np.concatenate([10 ** rng.uniform(-3, 1, n - n // 10), 10 ** rng.uniform(-6, -3, n // 10)])
    theta = rng.uniform(-np.pi, np.pi, n)
    pts = {name: rng.uniform(-1.0, 1.0, n) for name in SYMBOL_NAMES}
    pts["e_x"], pts["e_y"] = e_d * np.cos(theta), e_d * np.sin(theta)
    pts["psi"] = rng.uniform(-np.pi, np.pi, n)  # covers both heading hemispheres
    pts["e_z"] = rng.uniform(-2.0, 2.0, n)
    return pts


def _evaluate(expr: sp.Expr, pts: dict[str, np.ndarray]) -> np.ndarray:
    syms = symbols()
    args = [syms[name] for name in SYMBOL_NAMES]
    fn = sp.lambdify(args, expr, modules="numpy")
    n = len(pts["e_x"])
    with np.errstate(all="ignore"):
        return np.broadcast_to(np.asarray(fn(*[pts[name] for name in SYMBOL_NAMES]), dtype=float), (n,))


def _hemisphere_checks(n: int, rng: np.random.Generator, e_d_range=(0.05, 5.0)) -> list[HemisphereCheck]:
    syms = symbols()
    jac = {"derived": sp.Matrix(3, 3, [derived_terms()[f"J[{i},{j}]"] for i in range(3) for j in range(3)]),
           "paper": sp.Matrix(3, 3, [printed_terms()[f"J[{i},{j}]"] for i in range(3) for j in range(3)])}
    out = []
    for source, J in jac.items():
        fn = sp.lambdify([syms["e_x"], syms["e_y"], syms["psi"]], J, modules="numpy")
        for heading in ("toward", "away"):
            d = np.exp(rng.uniform(np.log(e_d_range[0]), np.log(e_d_range[1]), n))
            theta = rng.uniform(-np.pi, np.pi, n)
            phi = rng.uniform(-np.pi / 2, np.pi / 2, n)  # cos(phi) > 0: away
            if heading == "toward":
                phi = phi + np.pi
            lam = np.empty(n)
            for k in range(n):
                M = np.asarray(fn(d[k] * np.cos(theta[k]), d[k] * np.sin(theta[k]), theta[k] + phi[k]), dtype=float)
                lam[k] = np.linalg.eigvalsh(0.5 * (M + M.T))[0]
            out.append(HemisphereCheck(heading=heading, source=source, samples=n,
                                       lambda_min_min=float(lam.min()), lambda_min_max=float(lam.max()),
                                       negative_fraction=float(np.mean(lam < 0)), e_d_range=e_d_range))
    return out


def audit(paper_terms: Mapping[str, sp.Expr] | None = None, *, samples: int = 2000, seed: int = 0,
          hemisphere_samples: int = 2000) -> AuditReport:
    """Compare printed terms (default: the paper's) with the derivation.

    Parameters
    ----------
    paper_terms : mapping name -> sympy expression, optional
        Terms to audit (missing names fall back to the paper's print); pass a
        deliberately wrong expression to see it flagged.
    samples : int
        Random points for the numeric comparison.
    seed : int
        RNG seed (the audit is deterministic for a seed).
    hemisphere_samples : int
        Points per hemisphere for the Remark 1 check.
    """
    printed = dict(printed_terms())
    if paper_terms:
        unknown = set(paper_terms) - set(TERM_NAMES)
        if unknown:
            from tubekit.exceptions import ConfigError
            raise ConfigError("paper_terms", f"names among {TERM_NAMES}", sorted(unknown))
        printed.update({k: sp.sympify(v) for k, v in paper_terms.items()})
    derived = derived_terms()
    rng = np.random.default_rng(seed)
    pts = _sample_points(samples, rng)
    rows = []
    for name in TERM_NAMES:
        p, d = printed[name], derived[name]
        pv, dv = _evaluate(p, pts), _evaluate(d, pts)
        ok = np.isfinite(dv)
        diff = np.abs(pv[ok] - dv[ok])
        scale = 1.0 + np.abs(dv[ok])
        max_abs = float(np.max(diff)) if diff.size else 0.0
        max_rel = float(np.max(diff / scale)) if diff.size else 0.0
        numeric_match = bool(np.all(np.isfinite(pv[ok]))) and max_rel <= 1e-9
        symbolic = _symbolic_zero(p - d) if numeric_match else False
        rows.append(TermAudit(name=name, paper=sp.sstr(p), derived=sp.sstr(d), match=numeric_match,
                              symbolic_zero=symbolic, max_abs_diff=max_abs, max_rel_diff=max_rel))
    J = sp.Matrix(3, 3, [derived[f"J[{i},{j}]"] for i in range(3) for j in range(3)])
    det = sp.simplify(J.det())
    c, s_, dd = sp.symbols("c s d", real=True)
    sym = sp.Matrix([[c, 0, -s_ * c / (2 * dd)], [0, 1, 0], [-s_ * c / (2 * dd), 0, c]])
    # check the polar form of J really is [[c,0,0],[0,1,0],[-s c/d,0,c]] before quoting its eigenvalues
    dist, theta, phi = sp.symbols("d theta phi", positive=True)
    polar = sp.Matrix([[sp.cos(phi), 0, 0], [0, 1, 0], [-sp.sin(phi) * sp.cos(phi) / dist, 0, sp.cos(phi)]])
    polar_ok = (J.applyfunc(_polar) - polar).applyfunc(sp.simplify) == sp.zeros(3, 3)
    eig = [sp.sstr(sp.simplify(ev)) for ev in sym.eigenvals()] if polar_ok else ["(polar form not verified)"]
    hemis = _hemisphere_checks(hemisphere_samples, rng)
    return AuditReport(
        terms=rows, det_J=sp.sstr(det),
        singular_set="e_x*cos(psi) + e_y*sin(psi) = 0, i.e. cos(psi - atan2(e_y, e_x)) = 0 <=> |e_o| = 1 "
                     "(and e_d = 0, where e_o is undefined)",
        sym_eigenvalues=eig, hemispheres=hemis, samples=samples, seed=seed,
        mismatches=[t.name for t in rows if not t.match])
