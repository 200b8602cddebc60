"""The paper's printed terms, evaluated against the formulas typed from the paper by hand in numpy."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from tubekit.model.derivation import SYMBOL_NAMES, symbols
from tubekit.paper.equations import TERM_NAMES, printed_terms


def test_fifteen_names_in_order():
    assert len(TERM_NAMES) == 15 and list(printed_terms()) == list(TERM_NAMES)


def test_printed_terms_equal_the_print():
    rng = np.random.default_rng(7)
    vals = dict(zip(SYMBOL_NAMES, rng.uniform(0.2, 1.0, len(SYMBOL_NAMES))))
    ex, ey, psi = vals["e_x"], vals["e_y"], vals["psi"]
    ed = np.hypot(ex, ey)
    s, c = np.sin(psi), np.cos(psi)
    w1, w2, w3 = vals["omega_1"], vals["omega_2"], vals["omega_3"]
    xd, yd, zd = vals["xdot_d"], vals["ydot_d"], vals["zdot_d"]
    by_hand = {  # eq. (18) of the paper, as printed
        "J[0,0]": (ex * c + ey * s) / ed, "J[1,1]": 1.0,
        "J[2,0]": (ey * s * c**2 - ex * s**2 * c) / ed**2, "J[2,2]": ex * ey / ed**2,
        "zeta[0]": -(ex * xd + ey * yd) / ed, "zeta[1]": -zd, "zeta[2]": (ex * yd - ey * xd) * s * c / ed**2,
        "xi[0]": (ex * w1 + ey * w2) / ed, "xi[1]": w3, "xi[2]": (ey * w1 - ex * w2) * s * c / ed**2,
    }
    sub = {symbols()[k]: v for k, v in vals.items()}
    for name, expr in printed_terms().items():
        assert float(sp.sympify(expr).subs(sub)) == pytest.approx(by_hand.get(name, 0.0), abs=1e-12), name
