"""Symbolic derivation of the error dynamics (eqs. 12-18) with sympy.

The error e = [e_d, e_z, e_o] is differentiated along the kinematics of eq. (11);
nothing is typed in from the paper. The result is decomposed as
``e_dot = J v + zeta + xi`` (eq. 18) with

* ``J = d e_dot / d v``                      (input matrix),
* ``zeta = e_dot |_(v=0, omega=0)``          (drift from the moving target),
* ``xi = e_dot |_(v=0, p_d_dot=0)``          (disturbance term).

All expressions use the symbols of :data:`SYMBOL_NAMES`; ``e_x = x - x_d`` etc.
The numeric versions (:mod:`tubekit.model.errors`, numpy only) are *generated
once* from this derivation (sympy printing with common-subexpression elimination)
into the shipped module :mod:`tubekit.model._generated_dynamics`, so that no sympy work
runs at import or at run time; ``python -m tubekit.model.derivation`` regenerates it and
``tests/test_model_derivation.py`` checks that the shipped code equals the derivation
(source hash, text and values).
"""

from __future__ import annotations

import hashlib
import inspect
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import sympy as sp

__all__ = [
    "SYMBOL_NAMES",
    "symbols",
    "DerivedDynamics",
    "derive",
    "derivation_hash",
    "generated_source",
    "GENERATED_PATH",
]

#: The shipped module holding the generated closed-form code.
GENERATED_PATH = Path(__file__).with_name("_generated_dynamics.py")

SYMBOL_NAMES: tuple[str, ...] = (
    "e_x", "e_y", "e_z", "psi", "u", "w", "r",
    "omega_1", "omega_2", "omega_3", "xdot_d", "ydot_d", "zdot_d",
)


@lru_cache(maxsize=1)
def symbols() -> dict[str, sp.Symbol]:
    """The real sympy symbols used throughout, keyed by name."""
    return {name: sp.Symbol(name, real=True) for name in SYMBOL_NAMES}


@dataclass(frozen=True)
class DerivedDynamics:
    """The derived error dynamics.

    Attributes
    ----------
    e : sympy.Matrix (3, 1)
        [e_d, e_z, e_o] in terms of e_x, e_y, e_z, psi.
    e_dot : sympy.Matrix (3, 1)
        Time derivative along eq. (11).
    J, zeta, xi : sympy.Matrix
        Decomposition e_dot = J v + zeta + xi (eq. 18), (3,3), (3,1), (3,1).
    residual : sympy.Matrix (3, 1)
        e_dot - (J v + zeta + xi), simplified; zero when the split is exact.
    """

    e: sp.Matrix
    e_dot: sp.Matrix
    J: sp.Matrix
    zeta: sp.Matrix
    xi: sp.Matrix
    residual: sp.Matrix


@lru_cache(maxsize=1)
def derive() -> DerivedDynamics:
    """Differentiate e = [e_d, e_z, e_o] along the kinematics and split it (eq. 18)."""
    s = symbols()
    ex, ey, ez, psi = s["e_x"], s["e_y"], s["e_z"], s["psi"]
    u, w, r = s["u"], s["w"], s["r"]
    om = sp.Matrix([s["omega_1"], s["omega_2"], s["omega_3"]])
    pdd = sp.Matrix([s["xdot_d"], s["ydot_d"], s["zdot_d"]])
    v = sp.Matrix([u, w, r])

    # Kinematics eq. (11) written for the error state (e_x, e_y, e_z, psi):
    # d/dt (x - x_d) = u cos psi + omega_1 - xdot_d, etc.  f(x) v + omega - [p_d_dot, 0]
    f = sp.Matrix([[sp.cos(psi), 0, 0], [sp.sin(psi), 0, 0], [0, 1, 0], [0, 0, 1]])
    state_dot = f * v + sp.Matrix([om[0], om[1], om[2], 0]) - sp.Matrix([pdd[0], pdd[1], pdd[2], 0])

    e_d = sp.sqrt(ex**2 + ey**2)
    e_o = ex / e_d * sp.sin(psi) - ey / e_d * sp.cos(psi)
    e = sp.Matrix([e_d, ez, e_o])
    state = sp.Matrix([ex, ey, ez, psi])
    e_dot = (e.jacobian(state) * state_dot).applyfunc(sp.expand)

    J = e_dot.jacobian(v).applyfunc(sp.simplify)
    zero_v = {u: 0, w: 0, r: 0}
    zeta = e_dot.subs(zero_v).subs({om[0]: 0, om[1]: 0, om[2]: 0}).applyfunc(sp.simplify)
    xi = e_dot.subs(zero_v).subs({pdd[0]: 0, pdd[1]: 0, pdd[2]: 0}).applyfunc(sp.simplify)
    residual = (e_dot - (J * v + zeta + xi)).applyfunc(sp.simplify)
    return DerivedDynamics(e=e, e_dot=e_dot, J=J, zeta=zeta, xi=xi, residual=residual)


def derivation_hash() -> str:
    """sha256 (hex) of the source of :func:`derive` and of the code generator: the cache key of the
    generated module, together with the sympy version."""
    parts = [inspect.getsource(f) for f in (derive, generated_source, _emit_function)]
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def _emit_function(name: str, exprs: list[sp.Expr], args: list[sp.Symbol], scalar: bool, doc: str) -> str:
    """Python source of ``name(*args)`` returning ``exprs`` (a list, or a tuple if ``scalar``) with CSE.

    ``scalar`` prints with :mod:`math` (plain floats; a zero division raises), otherwise with numpy.
    """
    from sympy.printing.numpy import NumPyPrinter
    from sympy.printing.pycode import PythonCodePrinter

    printer = PythonCodePrinter({"fully_qualified_modules": True}) if scalar else NumPyPrinter()
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_x"))
    lines = [f"def {name}({', '.join(a.name for a in args)}):", f'    """{doc}"""']
    lines += [f"    {lhs} = {printer.doprint(rhs)}" for lhs, rhs in replacements]
    items = ", ".join(printer.doprint(e) for e in reduced)
    lines.append(f"    return ({items})" if scalar else f"    return [{items}]")
    return "\n".join(lines) + "\n"


def generated_source() -> str:
    """The text of :mod:`tubekit.model._generated_dynamics`, printed from :func:`derive`."""
    d, s = derive(), symbols()
    ex, ey, ez, psi = s["e_x"], s["e_y"], s["e_z"], s["psi"]
    om = [s["omega_1"], s["omega_2"], s["omega_3"]]
    pdd = [s["xdot_d"], s["ydot_d"], s["zdot_d"]]
    v = [s["u"], s["w"], s["r"]]
    rho = list(sp.symbols("rho_d rho_z rho_o", real=True))
    sigma = sp.Symbol("sigma", positive=True)
    K = d.J.inv(method="ADJ").applyfunc(sp.simplify)
    kappa = -sigma * K * sp.Matrix(rho)
    blocks = [
        _emit_function("J", list(d.J), [ex, ey, psi], False, "J (9 entries, row-major), numpy."),
        _emit_function("zeta", list(d.zeta), [ex, ey, psi, *pdd], False, "zeta (3 entries), numpy."),
        _emit_function("xi", list(d.xi), [ex, ey, psi, *om], False, "xi (3 entries), numpy."),
        _emit_function("e_dot", list(d.e_dot), [ex, ey, psi, *v, *om, *pdd], False, "e_dot (3 entries), numpy."),
        _emit_function("error_scalar", list(d.e), [ex, ey, ez, psi], True, "e = (e_d, e_z, e_o), floats."),
        _emit_function("jacobian_scalar", list(d.J), [ex, ey, psi], True, "J (9 entries, row-major), floats."),
        _emit_function("corrected_kappa", list(kappa), [ex, ey, psi, *rho, sigma], True,
                       "kappa = -sigma J^-1 rho (3 entries), floats; ZeroDivisionError where J is singular."),
    ]
    header = (f'"""Generated by tubekit.model.derivation.generated_source(): do not edit; run\n'
              f'``python -m tubekit.model.derivation`` after changing the derivation.\n"""\n'
              f"# ruff: noqa\nimport math\n\nimport numpy\n\n"
              f"__all__ = ['J', 'zeta', 'xi', 'e_dot', 'error_scalar', 'jacobian_scalar', 'corrected_kappa']\n\n"
              f"SYMPY_VERSION = {sp.__version__!r}\nDERIVATION_HASH = {derivation_hash()!r}\n")
    return header + "\n\n" + "\n\n".join(blocks)


if __name__ == "__main__":
    GENERATED_PATH.write_text(generated_source())
    print(f"wrote {GENERATED_PATH}")
