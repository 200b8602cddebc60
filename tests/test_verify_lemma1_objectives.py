"""verify.lemma1.objectives: the branch-and-bound cases of each Lemma-1 bound, built from the polar model.

Hand derivation (J = [[c, 0, 0], [0, 1, 0], [-o c / d, 0, c]], c = s sqrt(1 - o^2), v = (u, w, r)):
J v = (c u, w, c (r - o u / d)), so d(J v)/de depends on u and r but not on w; L1's cases are the
vertices of the (u, r) box up to a global sign: two per hemisphere, in the parameters r_max, u_max.
zeta = (-a, -zdot_d, c b / d) is linear in (a, b) and its e-derivative is free of zdot_d.
"""

from __future__ import annotations

import pytest
import sympy as sp

from tubekit.exceptions import ConfigError
from verify.lemma1.objectives import arb_entries, case_matrices, derived_objectives, linear_in_speed
from verify.lemma1.polar import E_D, E_O, polar_model


@pytest.mark.parametrize("s, hem", [(-1, "toward"), (1, "away")])
def test_l1_has_the_two_vertices_of_the_u_r_box(s, hem):
    cases = case_matrices("L1", "paper", s)
    assert [c[0] for c in cases] == [f"{hem} u=+,r=+", f"{hem} u=+,r=-"]
    for label, kind, A, dims, pars in cases:
        assert kind == "norm" and A.shape == (3, 3)
        assert [str(d) for d in dims] == ["e_d", "e_o"] and [str(p) for p in pars] == ["r_max", "u_max"]


def test_j_lower_is_the_lmin_of_the_law_gain_and_xi_bar_one_norm():
    (label, kind, A, dims, pars), = case_matrices("J_lower", "corrected", 1)
    assert (label, kind, pars) == ("away", "lmin", ()) and A == sp.eye(3)  # J J^-1 = I
    (label, kind, A, dims, pars), = case_matrices("xi_bar", "paper", -1)
    assert (label, kind) == ("toward", "norm") and A == sp.ImmutableMatrix(polar_model(-1).dxi_domega)


@pytest.mark.parametrize("name", ["L3", "K_row_x", ""])
def test_an_unknown_bound_is_refused(name):
    with pytest.raises(ConfigError, match="bound"):
        case_matrices(name, "paper", 1)


def test_arb_entries_are_the_upper_triangle_of_the_gram_or_symmetric_part():
    A = sp.Matrix([[E_D, 0], [0, 1]])
    assert arb_entries("norm", A) == [E_D**2, 0, 1]
    B = sp.Matrix([[0, 2 * E_D], [0, E_O]])
    assert arb_entries("lmin", B) == [0, E_D, E_O]


@pytest.mark.parametrize("s", [-1, 1])
def test_the_velocity_bounds_are_linear_in_speed(s):
    assert linear_in_speed("L2", s) and linear_in_speed("zeta_theta", s)


def test_derived_objectives_name_their_arguments_as_the_cases_do():
    for obj, (label, kind, A, dims, pars) in zip(derived_objectives("L1", "paper", -1),
                                                 case_matrices("L1", "paper", -1)):
        assert (obj.label, obj.kind, obj.shape) == (label, kind, (3, 3))
        assert obj.dims == tuple(map(str, dims)) and obj.pars == tuple(map(str, pars))
