"""verify.kernel.compiled: the shipped objectives are fresh, are the derived ones bit for bit, and are used only when
they may be (built-in law, current sources, switched on); a certificate needs no sympy."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from flint import arb

import verify
from tubekit.model.ancillary import BUILTIN_LAWS, LAWS, AncillaryLaw
from verify.kernel import compiled
from verify.theorem.gains import GAIN_KEYS, _derived_terms
from verify.kernel.intervals import enclose
from verify.lemma1.bounds import BOUND_NAMES
from verify.lemma1.objectives import derived_objectives

ROOT = Path(__file__).resolve().parents[1]
HINT = "stale: run `python -m verify.studies.generate_compiled`"
#: Sample ranges of the box dimensions and parameters (any values inside the objectives' domains).
RANGES = {"e_d": (0.3, 3.0), "e_z": (-1.0, 1.0), "e_o": (-0.9, 0.9), "theta": (0.0, 6.0), "gamma": (0.0, 6.0),
          "u_max": (0.1, 2.0), "w_max": (0.1, 2.0), "r_max": (0.1, 2.0), "h_xy": (0.0, 1.0), "p_z": (0.0, 1.0)}


def _same_ball(a: arb, b: arb) -> bool:
    """The same Arb ball: equal midpoints and radii (NaN balls alike)."""
    if not (a.is_finite() and b.is_finite()):
        return a.is_finite() == b.is_finite()
    return a.mid() == b.mid() and a.rad() == b.rad()


def _points(names: tuple[str, ...], n: int = 64) -> list[np.ndarray]:
    rng = np.random.default_rng(3)
    return [rng.uniform(*RANGES[k], n) for k in names]


def _balls(names: tuple[str, ...]) -> list[list[arb]]:
    """A few boxes: the whole sample range and two small boxes inside it, per argument."""
    out = []
    for frac in ((0.0, 1.0), (0.2, 0.21), (0.7, 0.9)):
        out.append([enclose(lo + frac[0] * (hi - lo), lo + frac[1] * (hi - lo)) for lo, hi in map(RANGES.get, names)])
    return out


def _identical(shipped_arb, derived_arb, shipped_np, derived_np, names: tuple[str, ...]) -> None:
    for balls in _balls(names):
        got, want = shipped_arb(*balls), derived_arb(*balls)
        assert len(got) == len(want) and all(_same_ball(g, w) for g, w in zip(got, want))
    pts = _points(names)
    np.testing.assert_array_equal(shipped_np(*pts), derived_np(*pts))


def test_the_shipped_objectives_are_fresh():
    for name in compiled.GENERATED:
        mod = __import__(name, fromlist=["SOURCE_HASH"])
        assert mod.SOURCE_HASH == compiled.source_hash(), HINT
    assert compiled.fresh()


@pytest.mark.parametrize("law", BUILTIN_LAWS)
@pytest.mark.parametrize("sign", [-1, 1])
def test_the_shipped_gain_terms_are_the_derived_ones_bit_for_bit(law, sign):
    shipped, derived = compiled.gain_terms(law, sign), _derived_terms(law, sign)
    assert shipped is not None and set(shipped) == set(derived) == set(GAIN_KEYS)
    for key in GAIN_KEYS:
        s, d = shipped[key], derived[key]
        assert s.constant == d.constant, key
        if s.constant is None:
            _identical(s.arb, d.arb, s.numpy, d.numpy, ("e_d", "e_o"))


@pytest.mark.parametrize("name", BOUND_NAMES)
@pytest.mark.parametrize("sign", [-1, 1])
def test_the_shipped_route_objectives_are_the_derived_ones_bit_for_bit(name, sign):
    for law in BUILTIN_LAWS:
        shipped, derived = compiled.route_objectives(name, law, sign), derived_objectives(name, law, sign)
        assert shipped is not None and len(shipped) == len(derived) > 0
        for s, d in zip(shipped, derived):
            assert (s.label, s.kind, s.dims, s.pars, s.shape) == (d.label, d.kind, d.dims, d.pars, d.shape)
            _identical(s.arb, d.arb, s.numpy, d.numpy, s.dims + s.pars)


def test_linear_in_speed_is_shipped_for_both_velocity_bounds():
    from verify.lemma1.objectives import linear_in_speed

    for name in ("L2", "zeta_theta"):
        for sign in (-1, 1):
            assert compiled.linear_in_speed(name, sign) is linear_in_speed(name, sign)


def test_a_law_free_bound_ignores_the_law_and_a_law_bound_needs_a_builtin_one(monkeypatch):
    monkeypatch.setitem(LAWS, "test-user", AncillaryLaw("test-user", lambda J: J, "test"))
    assert compiled.route_objectives("L1", "test-user", -1) == compiled.route_objectives("L1", "paper", -1)
    assert compiled.route_objectives("J_lower", "test-user", -1) is None
    assert compiled.gain_terms("test-user", -1) is None


def test_a_law_replacing_a_builtin_one_is_not_served(monkeypatch):
    monkeypatch.setitem(LAWS, "paper", AncillaryLaw("paper", lambda J: J, "test"))
    assert compiled.gain_terms("paper", 1) is None and compiled.route_objectives("JK_norm", "paper", 1) is None


def test_switched_off_nothing_is_served():
    was = compiled.use(False)
    try:
        assert compiled.gain_terms("corrected", 1) is None
        assert compiled.route_objectives("L1", "", 1) is None and compiled.linear_in_speed("L2", 1) is None
    finally:
        compiled.use(was)
    assert compiled.gain_terms("corrected", 1) is not None


def test_stale_modules_are_not_served(monkeypatch):
    monkeypatch.setattr(compiled, "source_hash", lambda: "0" * 64)
    compiled._module.cache_clear()
    try:
        assert not compiled.fresh()
        assert compiled.gain_terms("corrected", 1) is None and compiled.route_objectives("L2", "", -1) is None
    finally:
        monkeypatch.undo()
        compiled._module.cache_clear()
    assert compiled.fresh()


@pytest.mark.parametrize("text, header, expected", [
    ("a = 1\ndef f(x,\n      y):\n    return x\n\n    # inside\ndef g():\n    pass\n", "def f",
     "def f(x,\n      y):\n    return x\n\n    # inside\n"),
    ("class A:\n    x = 1\n# after\n", "class A", "class A:\n    x = 1\n"),
    ("def g():\n    pass\n", "def g", "def g():\n    pass\n"),
    ("def g():\n    pass\n", "def h", ""),  # a renamed definition: the hash changes, nothing raises
])
def test_segment_takes_a_top_level_definition_to_the_next_top_level_line(text, header, expected):
    assert compiled._segment(text, header) == expected


def test_the_source_hash_reads_every_source_file():
    missing = [rel for rel in compiled.SOURCES if not (ROOT / rel).is_file()]
    assert not missing
    assert len(compiled.source_hash()) == 64


def test_a_certificate_is_the_same_with_the_shipped_or_the_derived_objectives():
    """Every number of the certificate (gains, route, tube, verdict) is the same either way."""
    from verify.lemma1 import bounds

    scenario = verify.certifiable_scenario()
    shipped = verify.certify(scenario).to_dict()
    was = compiled.use(False)
    bounds._solve.cache_clear()
    try:
        derived = verify.certify(scenario).to_dict()
    finally:
        compiled.use(was)
        bounds._solve.cache_clear()
    shipped.pop("elapsed_s")
    derived.pop("elapsed_s")
    assert shipped == derived


def test_certifying_a_shipped_scenario_loads_no_sympy():
    code = ("import sys, verify; c = verify.certify(verify.certifiable_scenario()); "
            "print(c.certified, 'sympy' in sys.modules)")
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["True", "False"], run.stdout


def test_a_term_is_a_constant_or_a_pair_of_evaluators():
    terms = compiled.gain_terms("corrected", -1)
    assert terms[("g", 0)].constant == 1.0 and terms[("g", 0)].arb is None  # J K = I: G_dd = 1 exactly
    k_uu = terms[("k_abs", 0)]  # |K_uu| = 1 / sqrt(1 - e_o^2) for K = J^-1 (by hand)
    assert k_uu.constant is None
    assert float(k_uu.numpy(np.array([1.0]), np.array([0.6]))[0, 0]) == pytest.approx(1.25)
    assert math.isclose(float(k_uu.arb(arb(1), arb("0.6"))[0].mid()), 1.25, rel_tol=1e-12)
