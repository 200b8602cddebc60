"""The paper's J, zeta and xi (eq. 18) encoded exactly as printed.

These are *not* used by the controller or the verifier (they use
:mod:`tubekit.model.derivation`); they exist so :mod:`tubekit.paper.audit` can compare the
print with the derivation term by term.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from tubekit.model.derivation import symbols

__all__ = ["printed_terms", "TERM_NAMES"]

TERM_NAMES: tuple[str, ...] = tuple(
    [f"J[{i},{j}]" for i in range(3) for j in range(3)] + [f"zeta[{i}]" for i in range(3)]
    + [f"xi[{i}]" for i in range(3)]
)


@lru_cache(maxsize=1)
def printed_terms() -> dict[str, sp.Expr]:
    """The 15 printed terms keyed ``J[i,j]``, ``zeta[i]``, ``xi[i]`` (0-based)."""
    s = symbols()
    ex, ey, psi = s["e_x"], s["e_y"], s["psi"]
    w1, w2, w3 = s["omega_1"], s["omega_2"], s["omega_3"]
    xd, yd, zd = s["xdot_d"], s["ydot_d"], s["zdot_d"]
    ed = sp.sqrt(ex**2 + ey**2)
    sn, cs = sp.sin(psi), sp.cos(psi)
    J = sp.Matrix([
        [(ex * cs + ey * sn) / ed, 0, 0],
        [0, 1, 0],
        [(ey * sn * cs**2 - ex * sn**2 * cs) / ed**2, 0, ex * ey / ed**2],
    ])
    zeta = [-(ex * xd + ey * yd) / ed, -zd, (ex * yd - ey * xd) * sn * cs / ed**2]
    xi = [(ex * w1 + ey * w2) / ed, w3, (ey * w1 - ex * w2) / ed**2 * sn * cs]
    terms: dict[str, sp.Expr] = {}
    for i in range(3):
        for j in range(3):
            terms[f"J[{i},{j}]"] = sp.sympify(J[i, j])
    for i in range(3):
        terms[f"zeta[{i}]"] = sp.sympify(zeta[i])
        terms[f"xi[{i}]"] = sp.sympify(xi[i])
    return {name: terms[name] for name in TERM_NAMES}
