"""Tests of verify.certificate.handoff: from a certificate to the Tightening the FHOCP and the loop use.

The node constraints are recomputed here from the module's documented rule (largest per-arc margin plus
the inter-node allowance rate * dt / 2, each keeping at least a quarter of R's half-width) with the arc
rates derived by hand: |e_d'| <= u + P, |e_z'| <= w + |zdot_d|, |e_o'| <= r + (u + P) / eps, ||p'|| <= ||(u, w)||.
"""

from __future__ import annotations

from tubekit.tiers import Tiers

import math

import numpy as np
import pytest

from tubekit.model.backup import BackupPlan
from tubekit.scenario import paper_scenario
from tubekit.tightening import DisturbanceBound, RegionBounds, Tightening
from verify import NotCertifiedError, certify

P = 3.0 * math.pi / 50     # horizontal target speed of paper_currents (m/s)


def test_certified_tightening_is_the_certificate(pc_cert):
    c = pc_cert
    t = c.tightening
    assert isinstance(t, Tightening) and t.certified
    np.testing.assert_allclose(t.v_max, np.array([0.4, 0.3, 0.5]) - c.kappa_bar, rtol=1e-12)
    np.testing.assert_array_equal(t.tube, np.asarray(c.tube.rho))
    assert t.rho_tilde == pytest.approx(math.sqrt(sum(r * r for r in c.tube.rho)))
    assert t.sigma == c.sigma.value and t.horizon_arcs == 8
    m = c.margins
    np.testing.assert_array_equal(t.margins, np.column_stack([m.e_d, m.e_z, m.e_o, m.position]))
    np.testing.assert_allclose(t.rates, [0.4 + P, 0.3, 0.5 + (0.4 + P) / 0.5, 0.5], rtol=1e-12)
    assert t.region == RegionBounds(epsilon=0.5, e_d_max=3.0, e_z_max=1.0, e_o_max=0.5)
    d = c.disturbance
    assert t.disturbance == DisturbanceBound(omega_xy=d.omega_xy, omega_z=d.omega_z, sway=d.gamma)
    assert t.law == c.law == "corrected" and t.design_key == c.design_key and len(t.design_key) == 64
    assert t.design == c.inputs and t.design.law == "corrected"
    assert t.tiers == Tiers(True, True)
    b = c.backup
    assert b.anchor_reach > 0.0                                               # the anchor may move: the loop reads it
    assert t.backup == BackupPlan(law=b.law, safe_set=b.safe_set, handover=(m.position[-1] + b.anchor_reach, m.e_z[-1]),
                                  anchor_reach=b.anchor_reach)


@pytest.fixture(scope="module")
def blind_cert():
    """The paper's scenario with a sensing range of 0.6 m: T ||V|| + M_pos + r_bar > 0.6, so neither tier certifies."""
    return certify(paper_scenario().with_changes(sensing_range=0.6))


def test_safe_only_tightening(paper_cert):
    """Tracking fails, safety holds: sigma = 0, inputs up to V, zero e-columns (not enforced), the certified
    position margins, obstacle margin = last position margin + ||(u, w)|| dt / 2; the FHOCP's e-node bounds
    are R's (the paper's: e_d <= 3, |e_z| <= 1, |e_o| <= 0.9: nothing about e is promised there) but for e_d_min,
    the best-effort tracking design's (largest e_d margin + rate dt / 2, keeping a quarter of R): plans stay off ε."""
    c = paper_cert
    t = c.tightening
    assert t.certified and t.tiers == Tiers(True, False)
    assert t.sigma == 0.0 and np.all(t.tube == 0) and t.rho_tilde == 0.0
    np.testing.assert_array_equal(t.v_max, [0.4, 0.3, 0.5])
    m = c.safe_design.margins
    np.testing.assert_array_equal(t.margins[:, :3], np.zeros((8, 3)))
    np.testing.assert_array_equal(t.margins[:, 3], m.position)
    assert (t.e_d_max, t.e_z_max, t.e_o_max) == (3.0, 1.0, 0.9)
    dm, half = c.design.margins, 0.05  # dt / 2 (s)
    target = 3.0 * np.pi / 25  # the paper's target speed (m/s)
    assert t.e_d_min == pytest.approx(0.1 + min(max(dm.e_d) + half * (0.4 + target), 0.75 * (3.0 - 0.1) / 2))
    assert t.obstacle_margin == pytest.approx(m.position[-1] + 0.05 * 0.5)
    reach = c.backup.anchor_reach
    assert t.backup.handover == (m.position[-1] + reach, m.e_z[-1]) and t.backup.safe_set == c.backup.safe_set
    assert t.backup.anchor_reach == reach > 0.0
    best = c.best_effort_tightening()
    assert best.tiers == t.tiers and np.array_equal(best.margins, t.margins) and best.sigma == 0.0


def test_node_constraints_are_the_last_margin_plus_the_allowance(pc_cert):
    t = pc_cert.tightening
    m = pc_cert.margins
    half = 0.05     # dt / 2 (s)
    worst = [m.e_d[-1] + half * (0.4 + P), m.e_z[-1] + half * 0.3,
             m.e_o[-1] + half * (0.5 + (0.4 + P) / 0.5), m.position[-1] + half * 0.5]
    assert t.e_d_min == pytest.approx(0.5 + min(worst[0], 0.75 * 1.25))
    assert t.e_d_max == pytest.approx(3.0 - min(worst[0], 0.75 * 1.25))
    assert t.e_z_max == pytest.approx(1.0 - min(worst[1], 0.75 * 1.0))
    assert t.e_o_max == pytest.approx(0.5 - min(worst[2], 0.75 * 0.5))
    assert t.obstacle_margin == pytest.approx(worst[3])
    assert t.e_o_max >= 0.25 * 0.5 - 1e-15     # at least a quarter of R's half-width is kept


def test_uncertified_tightening_needs_consent(blind_cert):
    assert blind_cert.tiers == Tiers(False, False)
    with pytest.raises(NotCertifiedError, match="is not certified .*best_effort_tightening"):
        blind_cert.tightening


@pytest.mark.parametrize("fraction", [0.5, 0.9, 1.0])
def test_best_effort_tightening(blind_cert, fraction):
    """Best effort: each input limit >= max(fraction V_i, keep-up need), <= V_i; nodes keep a quarter of R."""
    paper_cert = blind_cert
    t = paper_cert.best_effort_tightening(min_input_fraction=fraction)
    v = np.array([0.4, 0.3, 0.5])
    need = np.array([min(3 * math.pi / 25 + 0.12, 0.4), min(0.1, 0.3), 0.0])
    assert not t.certified and t.design_key == paper_cert.design_key and t.law == paper_cert.law
    assert t.tiers == Tiers(False, False) and t.backup is not None   # never the zero input
    assert np.all(t.v_max <= v + 1e-15) and np.all(t.v_max >= np.maximum(fraction * v, need) - 1e-15)
    assert t.v_max[0] == pytest.approx(0.4)    # the keep-up need (0.497 m/s) is above u_max
    reg = paper_scenario().region
    assert 0.1 < t.e_d_min <= 0.1 + 0.75 * (reg.e_d_max - 0.1) / 2 + 1e-12
    assert t.e_o_max >= 0.25 * reg.e_o_max - 1e-12 and t.e_z_max >= 0.25 * reg.e_z_max - 1e-12
    assert np.all(np.isfinite(t.v_max)) and math.isfinite(t.rho_tilde)


def test_best_effort_without_a_tube():
    """A design whose tube diverges hands over no margins and a zero tube, flagged uncertified."""
    sc = paper_scenario()
    huge = sc.with_changes(disturbance=type(sc.disturbance)(amplitude=(2.0, 2.0, 2.0)))
    c = certify(huge)
    assert not c.design.tube.certified
    t = c.best_effort_tightening()
    assert t.horizon_arcs == 0 and np.all(t.tube == 0) and t.rho_tilde == 0.0 and not t.certified


# --------------------------------------------------------------------------- misuse, refused before anything runs
class _MustNotSolve:
    """A solver factory that fails the test if the loop gets as far as building a solver."""

    def __init__(self, *args, **kwargs) -> None:
        raise AssertionError("the loop started: the certificate should have been refused first")


def _pc():
    from tubekit.scenario import load_scenario
    import verify
    return load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


def _misuses(pc_cert):
    from dataclasses import replace
    sc = _pc()
    paper_law = replace(sc, controller=replace(sc.controller, law="paper"))
    third = certify(replace(sc, disturbance=replace(sc.disturbance, amplitude=tuple(a / 3 for a in
                                                                                     sc.disturbance.amplitude))))
    assert third.certified
    return [(paper_law, pc_cert, r"design_key\.law: expected the certificate's value 'corrected'.*'paper'"),
            (sc, third, r"design_key\.disturbance\.amplitude: expected the certificate's value \[0\.0333")]


def test_a_certificate_of_another_design_is_refused_by_simulate(pc_cert):
    import tubekit
    from tubekit.exceptions import ConfigError
    from tubekit.loop.closed_loop import run_closed_loop
    for scenario, cert, match in _misuses(pc_cert):
        with pytest.raises(ConfigError, match=match):
            tubekit.simulate(scenario, cert, duration=0.2, progress=False)
        with pytest.raises(ConfigError, match=match):
            run_closed_loop(scenario, tightening=cert.tightening, progress=False, solver_factory=_MustNotSolve)


def test_the_matching_certificate_runs(pc_cert):
    """Control: the same call with the scenario the certificate was issued for gets past the check."""
    from tubekit.loop.closed_loop import run_closed_loop
    with pytest.raises(AssertionError, match="the loop started"):
        run_closed_loop(_pc(), tightening=pc_cert.tightening, progress=False, solver_factory=_MustNotSolve)


def test_the_safe_only_tightening_matches_its_scenario(paper_cert):
    """The safe-only tightening (sigma = 0) is bound to the paper's scenario and gets past the key check;
    a run longer than the certified 100 s is refused by the duration the target was checked over."""
    from tubekit.exceptions import ConfigError
    from tubekit.loop.closed_loop import run_closed_loop
    sc = paper_scenario()
    assert paper_cert.inputs.sigma == 0.0 and paper_cert.tightening.sigma == 0.0
    with pytest.raises(AssertionError, match="the loop started"):
        run_closed_loop(sc, tightening=paper_cert.tightening, progress=False, solver_factory=_MustNotSolve)
    with pytest.raises(ConfigError, match=r"design_key\.duration"):
        paper_cert.tightening.require(sc.with_changes(duration=120.0))


def test_a_certificate_over_another_region_is_bound_to_it(pc_cert):
    """certify(region=R') records R' (region_override): a run of the scenario's own region refuses it."""
    from tubekit.exceptions import ConfigError
    from verify import Region
    sc = _pc()
    narrow = certify(sc, region=Region.from_scenario(sc, e_o=(-0.3, 0.3)))
    assert narrow.inputs.fields()["region_override"] == {"e_o": [-0.3, 0.3]}
    assert "region_override" not in pc_cert.inputs.fields()
    with pytest.raises(ConfigError, match=r"design_key\.region_override: .*\[-0\.3, 0\.3\].*'absent'"):
        narrow.tightening.require(sc)
