"""The paper's route (verify.lemma1.route): Lemma 1's σ and ρ̃ from the certified L1, L2, J_lower, ξ̄.

References are independent of the code under test: the paper's formulas
σ > (L1 + L2) / J_lower and ρ̃ = ξ̄ / (σ J_lower − L1 − L2) evaluated here in exact rational
arithmetic (fractions.Fraction) on the reported bounds, and the closed forms
J K = I for the corrected law (so J_lower = 1) and sup ‖ξ‖ = ω̄ max(1, 1/ε) (tests of
verify.lemma1.bounds).
"""

from __future__ import annotations

import dataclasses
import json
import math
from fractions import Fraction
from functools import lru_cache

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, paper_scenario
from verify import SCENARIOS_DIR
from verify.lemma1 import ROUTE_BUDGET, PaperRoute, paper_route
from verify.kernel.region import Region

from .json_edits import with_value as _with, without as _without

CURRENTS = load_scenario(SCENARIOS_DIR / "paper_currents.toml")
SCENARIOS = {"paper_currents": CURRENTS, "paper": paper_scenario(),
             "certifiable": load_scenario(SCENARIOS_DIR / "certifiable.toml")}


@lru_cache(maxsize=None)
def route(name: str, law: str, budget: int = ROUTE_BUDGET) -> PaperRoute:
    return paper_route(SCENARIOS[name], law, budget=budget)


def _exact_sigma_min(r: PaperRoute) -> Fraction:
    return (Fraction(r["L1"].bound) + Fraction(r["L2"].bound)) / Fraction(r["J_lower"].bound)


def _exact_radius(r: PaperRoute, sigma: float) -> Fraction:
    den = Fraction(sigma) * Fraction(r["J_lower"].bound) - Fraction(r["L1"].bound) - Fraction(r["L2"].bound)
    return Fraction(r["xi_bar"].bound) / den


@pytest.mark.parametrize("name", ["paper_currents", "paper"])
def test_paper_law_gives_no_sigma_and_names_j_lower(name):
    r = route(name, "paper")
    assert r["J_lower"].sampled < 0  # attained: the true inf is negative (Remark 1 false)
    assert r.sigma is None and r.sigma_min is None and r.tube_radius is None and not r.gives_tube
    assert "J_lower < 0" in r.reason and "Remark 1" in r.reason
    assert any("no tube from Lemma 1: J_lower < 0" in line for line in r.summary_lines())


@pytest.mark.parametrize("name", ["paper_currents", "paper"])
def test_corrected_law_sigma_and_radius_match_the_papers_formula(name):
    r = route(name, "corrected")
    assert r["J_lower"].bound == 1.0  # J K = I exactly
    s_min = _exact_sigma_min(r)
    assert Fraction(r.sigma_min) >= s_min and r.sigma_min == pytest.approx(float(s_min), rel=1e-12)
    assert Fraction(r.sigma) >= 2 * s_min and r.sigma == pytest.approx(2 * float(s_min), rel=1e-12)
    exact = _exact_radius(r, r.sigma)
    assert Fraction(r.tube_radius) >= exact and r.tube_radius == pytest.approx(float(exact), rel=1e-12)
    # at twice sigma_min the paper's radius is xi_bar / (L1 + L2)
    assert r.tube_radius == pytest.approx(r["xi_bar"].bound / (r["L1"].bound + r["L2"].bound), rel=1e-9)
    assert r.reason is None


def test_xi_bar_is_omega_bar_over_epsilon_at_paper_currents():
    """ε = 0.5 m < 1: sup ‖ξ‖ = ω̄ / ε (Remark 2 false), attained at e_o = 0, e_d = ε."""
    r = route("paper_currents", "corrected")
    omega_bar = Region.from_scenario(CURRENTS).omega_bar
    expected = omega_bar / CURRENTS.epsilon
    assert r["xi_bar"].bound >= expected * (1 - 1e-12)
    assert r["xi_bar"].sampled == pytest.approx(expected, rel=1e-6)


def test_sigma_argument_and_the_strict_inequality():
    r = route("paper_currents", "corrected")
    above = paper_route(CURRENTS, "corrected", sigma=10.0)
    assert above.sigma == 10.0 and above.sigma_rule == "argument"
    exact = _exact_radius(above, 10.0)
    assert Fraction(above.tube_radius) >= exact and above.tube_radius == pytest.approx(float(exact), rel=1e-12)
    at = paper_route(CURRENTS, "corrected", sigma=float(_exact_sigma_min(r)) * 0.999)
    assert at.tube_radius is None and "does not exceed" in at.reason and at.sigma_min == r.sigma_min


def test_scenario_sigma_is_used():
    sc = dataclasses.replace(CURRENTS, controller=dataclasses.replace(CURRENTS.controller, sigma=25.0))
    r = paper_route(sc, "corrected")
    assert r.sigma == 25.0 and r.sigma_rule == "scenario controller.sigma"
    assert r.tube_radius == pytest.approx(float(_exact_radius(r, 25.0)), rel=1e-12)


def test_why_not_the_verdict_names_the_loop_that_runs():
    line = route("paper_currents", "corrected").why_not_the_verdict
    c = CURRENTS.controller
    assert "\n" not in line
    for part in ("reset", "ZOH", f"delta = {c.dt:g} s", f"h = {1 / c.ancillary_rate_hz:g} s",
                 "(J(e) - J(e_i)) kappa_i", "verify.theorem.sampled"):
        assert part in line


@pytest.mark.parametrize("law", ["paper", "corrected"])
def test_round_trip_through_json(law):
    r = route("paper_currents", law)
    d = json.loads(json.dumps(r.to_dict()))
    assert PaperRoute.from_dict(d) == r
    assert set(d["quantities"]) == {"L1", "L2", "J_lower", "xi_bar"}
    assert "elapsed_s" not in json.dumps(d)  # no wall time: the JSON is the same under load




@pytest.mark.parametrize("edit, match", [
    (lambda d: _without(d, "sigma_min"), r"paper_route\.sigma_min: expected present"),
    (lambda d: _without(d, "quantities", "xi_bar"), r"paper_route\.quantities\.xi_bar: expected present"),
    (lambda d: _with(d, "3", "sigma"), r"paper_route\.sigma: expected a number"),
    (lambda d: _with(d, [], "quantities"), r"paper_route\.quantities: expected a JSON object"),
    (lambda d: _with(d, "yes", "quantities", "L1", "converged"), r"quantities\.L1\.converged: expected true or false"),
    (lambda d: _with(d, 1.5, "budget"), r"paper_route\.budget: expected an integer"),
    (lambda d: _with(d, 7, "reason"), r"paper_route\.reason: expected a string"),
    (lambda d: [d], r"paper_route: expected a JSON object"),
])
def test_from_dict_refuses_malformed(edit, match):
    d = edit(route("paper_currents", "corrected").to_dict())
    with pytest.raises(ConfigError, match=match):
        PaperRoute.from_dict(d, "certificate.paper_route")


@pytest.mark.parametrize("kwargs, match", [
    (dict(scenario="paper"), r"scenario: expected a tubekit.scenario.Scenario"),
    (dict(law="nope"), r"law: expected one of"),
    (dict(budget=0), r"budget: expected an integer >= 1"),
    (dict(budget=2.5), r"budget: expected an integer >= 1"),
    (dict(sigma=-1.0), r"sigma: expected a finite number > 0"),
    (dict(sigma=math.inf), r"sigma: expected a finite number > 0"),
    (dict(region={"e_d": [0.5, 2]}), r"region: expected a verify.Region"),
])
def test_paper_route_refuses_bad_input(kwargs, match):
    args = dict(scenario=CURRENTS, law="corrected")
    args.update(kwargs)
    with pytest.raises(ConfigError, match=match):
        paper_route(args.pop("scenario"), args.pop("law"), **args)


@settings(max_examples=12)
@given(name=st.sampled_from(sorted(SCENARIOS)), law=st.sampled_from(["paper", "corrected"]),
       budget=st.integers(1, 60), eps_scale=st.sampled_from([1.0, 1.5, 3.0]))
def test_sampled_never_beyond_certified(name, law, budget, eps_scale):
    """Property: at any budget and over shrunken regions, each sampled value lies on the safe side of its certified
    bound (sup: sampled <= bound; J_lower: sampled >= bound), and a radius is given only for σ > σ_min."""
    sc = SCENARIOS[name]
    base = Region.from_scenario(sc)
    lo = min(base.e_d[0] * eps_scale, 0.5 * (base.e_d[0] + base.e_d[1]))
    r = paper_route(sc, law, region=base.replace(e_d=(lo, base.e_d[1])), budget=budget)
    for q in r.quantities:
        if q.name == "J_lower":
            assert q.sampled >= q.bound
        else:
            assert q.sampled <= q.bound
        assert q.boxes <= budget + 8  # the budget is a work unit per quantity (+ one box per initial case)
    if r.tube_radius is not None:
        assert r.sigma > r.sigma_min > 0 and Fraction(r.tube_radius) >= _exact_radius(r, r.sigma)
    else:
        assert r.reason
