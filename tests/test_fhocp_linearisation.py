"""The SCP subproblem's linearisations (tubekit.fhocp.linearisation): the exact step's and e_o's, against finite
differences of the exact step and of the error coordinates."""

from __future__ import annotations

import numpy as np

from tubekit.fhocp.linearisation import eo_linearisation, step_linearisation
from tubekit.fhocp.nlp import FhocpNlp, discrete_step
from tubekit.scenario import paper_scenario

from .fhocp_cases import tightening

SC = paper_scenario()


def test_step_and_eo_linearisations_match_finite_differences():
    rng = np.random.default_rng(2)
    s = rng.normal(size=(9, 4))
    v = rng.uniform(-1, 1, (8, 3)) * np.array([0.4, 0.3, 2.0])
    lin = step_linearisation(s, v, 0.1)
    f0 = discrete_step(s[:8], v, 0.1)
    h = 1e-7
    for row, (kind, col, out) in {0: ("s", 3, 0), 1: ("v", 0, 0), 2: ("v", 2, 0),
                                  4: ("s", 3, 1), 5: ("v", 0, 1), 6: ("v", 2, 1)}.items():
        s2, v2 = s.copy(), v.copy()
        (s2 if kind == "s" else v2)[:, col] += h
        fd = (discrete_step(s2[:8], v2, 0.1) - f0)[:, out] / h
        assert np.allclose(fd, lin[row], atol=1e-6)
    # the affine model reproduces F at the linearisation point
    x_lin = s[:8, 0] + lin[0] * s[:8, 3] + lin[1] * v[:, 0] + lin[2] * v[:, 2] + lin[3]
    assert np.allclose(x_lin, f0[:, 0], atol=1e-14)
    ref = rng.normal(size=(9, 3))
    g = eo_linearisation(s, ref)
    nlp = FhocpNlp.from_scenario(SC, tightening())
    e0 = nlp.errors(s, ref)[:, 2]
    assert np.allclose(g[4], e0)
    for row, col in ((0, 0), (1, 1), (2, 3)):
        s2 = s.copy()
        s2[:, col] += h
        assert np.allclose((nlp.errors(s2, ref)[:, 2] - e0) / h, g[row], atol=1e-5)



def test_nested_lists_are_taken_as_the_arrays_they_spell():
    """The compiled routines type their arguments; the public functions hand them float arrays."""
    states, inputs, ref = [[0.0, 0.0, 0.0, 0.1]] * 3, [[0.3, 0.0, 0.1]] * 2, [[1, 1, 0]] * 3
    np.testing.assert_array_equal(step_linearisation(states, inputs, 0.1),
                                  step_linearisation(np.array(states), np.array(inputs), 0.1))
    np.testing.assert_array_equal(eo_linearisation(states, ref), eo_linearisation(np.array(states), np.array(ref, float)))
