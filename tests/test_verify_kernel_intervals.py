"""Tests of verify.kernel.intervals: rigorous rounding, sympy->arb compilation, eigenvalue bounds, B&B."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp
from flint import arb
from hypothesis import given, settings
from hypothesis import strategies as st

from verify.kernel.intervals import (Case, compile_arb, compile_numpy, enclose, lower, maximise, raise_upper,
                                     sym_eig_bounds, upper)

X, Y = sp.symbols("x y", real=True)


def test_upper_and_lower_round_outward():
    s = arb(0.1) + arb(0.2)  # exact sum of the two doubles, not representable as a double
    exact = Fraction(0.1) + Fraction(0.2)
    assert Fraction(upper(s)) >= exact
    assert Fraction(lower(s)) <= exact
    third = arb(1) / 3
    assert Fraction(lower(third)) <= Fraction(1, 3) <= Fraction(upper(third))
    assert upper(arb("nan")) == math.inf and lower(arb("nan")) == -math.inf


def test_enclose_contains_its_endpoints():
    b = enclose(0.1, 0.3)
    assert lower(b) <= 0.1 and upper(b) >= 0.3
    with pytest.raises(ValueError):
        enclose(1.0, 0.0)


def test_compile_arb_is_exact_on_rationals_and_rejects_floats():
    f = compile_arb([sp.Rational(1, 3) * 3 * X, X**2], [X])
    one, sq = f(enclose(-1.0, 0.5))
    assert lower(one) <= -1.0 and upper(one) >= 0.5
    assert lower(sq) >= -1e-8  # even power of a ball straddling 0 stays (essentially) non-negative
    assert upper(sq) >= 1.0
    with pytest.raises(ValueError, match="float"):
        compile_arb([sp.Float(0.1) * X], [X])
    with pytest.raises(ValueError, match="free symbol"):
        compile_arb([X * Y], [X])


EXPRS = [X**2 * Y - sp.sqrt(1 + X**2) / (2 + sp.cos(Y)), sp.sin(X * Y) + sp.Abs(X - Y) ** 3,
         (X - sp.Rational(1, 7)) ** 3 / (3 + Y**2)]
F_ARB = compile_arb(EXPRS, [X, Y])
F_NP = compile_numpy(EXPRS, [X, Y])


@settings(derandomize=True, max_examples=120, deadline=None)
@given(x0=st.floats(-3, 3), y0=st.floats(-3, 3), wx=st.floats(0, 2), wy=st.floats(0, 2),
       tx=st.floats(0, 1), ty=st.floats(0, 1))
def test_enclosures_contain_point_values(x0, y0, wx, wy, tx, ty):
    """Property: for any box and any point in it, the arb enclosure of each expression
    contains the numpy value at the point."""
    encl = F_ARB(enclose(x0, x0 + wx), enclose(y0, y0 + wy))
    vals = F_NP(np.array(x0 + tx * wx), np.array(y0 + ty * wy))
    for e, v in zip(encl, vals):
        assert lower(e) - 1e-12 * (1 + abs(v)) <= v <= upper(e) + 1e-12 * (1 + abs(v))


@settings(derandomize=True, max_examples=80, deadline=None)
@given(seed=st.integers(0, 10_000), width=st.floats(0.0, 0.5))
def test_sym_eig_bounds_contain_member_eigenvalues(seed, width):
    """Property: every symmetric matrix inside an interval matrix has its eigenvalues
    within sym_eig_bounds (checked on the midpoint and random members)."""
    rng = np.random.default_rng(seed)
    M = rng.normal(size=(3, 3))
    M = M + M.T
    R = width * rng.random((3, 3))
    R = R + R.T
    entries = [[enclose(M[i, j] - R[i, j], M[i, j] + R[i, j]) for j in range(3)] for i in range(3)]
    lo, hi = sym_eig_bounds(entries)
    for _ in range(5):
        T = rng.uniform(-1, 1, size=(3, 3))
        T = (T + T.T) / 2
        w = np.linalg.eigvalsh(M + T * R)
        assert lo <= w[0] + 1e-12 and w[-1] <= hi + 1e-12


def test_sym_eig_bounds_are_tight_on_point_matrices():
    rng = np.random.default_rng(1)
    M = rng.normal(size=(3, 3))
    M = M + M.T
    lo, hi = sym_eig_bounds([[arb(float(M[i, j])) for j in range(3)] for i in range(3)])
    w = np.linalg.eigvalsh(M)
    assert lo <= w[0] and w[0] - lo < 1e-9
    assert hi >= w[-1] and hi - w[-1] < 1e-9


def _case(expr, lo, hi) -> Case:
    fa = compile_arb([expr], [X, Y])
    fn = compile_numpy([expr], [X, Y])
    return Case("c", ("x", "y"), np.array(lo, float), np.array(hi, float),
                interval=lambda b: fa(*b)[0], point=lambda P: fn(P[:, 0], P[:, 1])[:, 0])


def test_maximise_brackets_a_known_sup():
    # sup of sin(x) + cos(y) over [0, 3]^2 is 2 (x = pi/2, y = 0)
    res = maximise([_case(sp.sin(X) + sp.cos(Y), [0, 0], [3, 3])], gap=0.01, max_boxes=20000)
    assert res.sampled <= 2.0 + 1e-12 <= res.bound + 1e-12
    assert res.converged and res.gap <= 0.01
    assert res.bound <= 2.0 * 1.01


def test_maximise_over_a_union_takes_the_largest_case():
    cases = [_case(-(X - 1) ** 2 - Y**2, [-2, -2], [2, 2]), _case(3 - (X**2 + Y**2), [1, 1], [2, 2])]
    res = maximise(cases, gap=0.02, max_boxes=20000)
    # case 1 sup 0; case 2 sup 3 - 2 = 1 at (1, 1)
    assert res.sampled <= 1.0 + 1e-12 <= res.bound
    assert res.bound <= 1.02 + 1e-9


def test_maximise_reports_an_unreached_gap_honestly():
    res = maximise([_case(sp.sin(3 * X) * sp.cos(2 * Y) + X * Y / 5, [-3, -3], [3, 3])], gap=1e-9,
                   max_boxes=3, n_samples=50)
    assert not res.converged
    assert res.gap > 1e-9
    assert res.bound >= res.sampled


def test_bisect_sup_covers_the_interval_and_stops_on_negative_bounds():
    """A negative bound ends a branch; the largest bound of the cover is returned, within the budget."""
    from verify.kernel.intervals import bisect_sup

    assert bisect_sup(lambda a, b: -1.0, 0.0, 1.0, 64) == (-1.0, 1)
    seen = []

    def bound(a: float, b: float) -> float:      # an upper bound of x - 0.75 over [a, b]
        seen.append((a, b))
        return b - 0.75

    sup, used = bisect_sup(bound, 0.0, 1.0, 64)
    assert sup == pytest.approx(0.25) and used == len(seen) <= 64 + 1
    assert min(a for a, _ in seen) == 0.0 and max(b for _, b in seen) == 1.0
    assert any(b < 0.75 for _, b in seen)        # the part where x - 0.75 < 0 was proved negative
    assert bisect_sup(bound, 0.0, 1.0, 3)[1] <= 3 + 1


def test_arb_source_names_its_function_and_prefixes_its_exact_constants():
    from verify.kernel.intervals import arb_source

    source, consts = arb_source([sp.Rational(1, 3) * X + Y, sp.Rational(-5, 7) * X], [X, Y], name="g", prefix="_c")
    assert source.startswith("def g(a0, a1):") and consts == {"_c0": (1, 3), "_c1": (-5, 7)}
    namespace = {"_arb": arb, **{k: arb(p) / q for k, (p, q) in consts.items()}}
    exec(source, namespace)
    out = namespace["g"](arb(3), arb(1))
    assert out[0].contains(2) and (7 * out[1]).contains(-15)  # 1/3 * 3 + 1 = 2; 7 * (-5/7 * 3) = -15


def test_vectorised_broadcasts_every_entry_to_float():
    from verify.kernel.intervals import vectorised

    f = vectorised(lambda x, y: [x + y, 0, 2 * y])
    out = f(np.array([1.0, 2.0]), 3.0)
    assert out.dtype == float and out.shape == (2, 3)
    np.testing.assert_array_equal(out, [[4.0, 0.0, 6.0], [5.0, 0.0, 6.0]])
    assert vectorised(lambda x: [x])(2.0).shape == (1,)


@settings(deadline=None)
@given(mid=st.floats(0.0, 1e6), rad=st.floats(0.0, 1e3), best=st.floats(-1e6, 2e6), exponent=st.integers(-300, 300))
def test_raise_upper_is_the_running_maximum_of_the_exact_upper_bounds(mid, rad, best, exponent):
    """Property: for a ball x >= 0 (any scale) raise_upper(best, x) == max(best, upper(x)): skipping the exact upper
    bound below best never changes the maximum."""
    scale = 2.0 ** exponent
    x = abs(arb(mid * scale, rad * scale))
    assert raise_upper(best * scale, x) == max(best * scale, upper(x))


def test_raise_upper_at_the_edge_takes_the_exact_bound():
    """A ball whose float top is within 1e-12 of best, or not finite, is compared exactly."""
    x = arb(1.0, 1e-20)
    assert raise_upper(1.0, x) == max(1.0, upper(x)) > 1.0
    assert raise_upper(5.0, arb("inf")) == math.inf
