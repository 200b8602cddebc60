"""Tightening: the baseline's sets and a certificate's tightened sets."""

from __future__ import annotations

import numpy as np
import pytest

import verify
from tubekit.scenario import paper_scenario
from tubekit.tightening import Tightening


def test_untightened_is_the_scenario():
    sc = paper_scenario()
    t = Tightening.untightened(sc)
    assert np.array_equal(t.v_max, sc.limits.vector)
    assert t.e_d_min == sc.epsilon and t.e_d_max == sc.region.e_d_max
    assert t.e_o_max == sc.region.e_o_max and t.e_z_max == sc.region.e_z_max
    assert t.obstacle_margin == 0 and t.rho_tilde == 0 and t.sigma == 0


def test_certified_tightening_is_the_pontryagin_difference():
    """V-bar = V - kappa-bar and E-bar = R shrunk by rho-tilde, as Lemma 1 / Section V define them."""
    sc = verify.certifiable_scenario()
    cert = verify.certify(sc, "corrected")
    t = cert.tightening()
    rho = cert.rho["rho_tilde"]
    assert t.rho_tilde == pytest.approx(rho)
    assert t.e_d_min == pytest.approx(sc.epsilon + rho)
    assert t.e_d_max == pytest.approx(sc.region.e_d_max - rho)
    assert t.e_o_max == pytest.approx(sc.region.e_o_max - rho)
    assert np.allclose(t.v_max, sc.limits.vector - np.asarray(cert.kappa_bar), rtol=1e-9)
    # |kappa_i| <= sigma * sup||row_i K|| * rho-tilde
    rows = np.array([cert.bounds[f"K_row_{a}"].bound for a in "uwr"])
    assert np.all(np.asarray(cert.kappa_bar) >= t.sigma * rows * rho * (1 - 1e-9))
