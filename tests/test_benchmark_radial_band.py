"""benchmarks/radial_band.py: the narrowest band of distance any rate-limited controller holds (docs/plant.md §4)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from .scripts import load_script

OMEGA, DT, S_RANGE = 0.1533, 0.1, (-0.2, 0.2)


def _module():
    return load_script("benchmarks/radial_band.py", "bench_radial_band")


@pytest.mark.parametrize("rate", [0.05, 0.1])
@pytest.mark.slow
def test_the_smallest_band_is_the_continuous_time_argument_plus_a_sampling_margin(rate):
    """The adversary that reverses the disturbance once the command has matched it moves the distance by
    (2 omega)^2 / (2 rho) while the command catches up: a half-width of omega^2 / rho (docs/plant.md section 4).
    The polygon iteration, an independent computation on the sampled system, lands at that value plus a margin
    of a few periods' drift, never below it."""
    mod = _module()
    x = mod.smallest_band(S_RANGE, DT, rate * DT, OMEGA)
    closed_form = OMEGA ** 2 / rate
    assert closed_form <= x <= closed_form + 3 * OMEGA * DT


@pytest.mark.slow
def test_every_corner_of_the_invariant_set_has_a_command_step_that_keeps_it_in_the_set():
    """Property: the computed set is robustly control-invariant. The successor is affine in (the step, the
    disturbance) and the set convex, so it suffices that each corner has one step |Delta| <= J whose successors
    under both extreme disturbances lie in the set (one linear feasibility problem per corner); a band narrower
    than the smallest holds no set."""
    mod = _module()
    jump = 0.05 * DT
    band = mod.smallest_band(S_RANGE, DT, jump, OMEGA) + 0.02
    c = mod.invariant_set(band, S_RANGE, DT, jump, OMEGA)
    assert c is not None
    corners = c.vertices()
    assert corners is not None and len(corners) >= 4
    for x, s in corners:
        rows, rhs = [], []
        for w in (-OMEGA, OMEGA):  # successor (x - dt (s + d) + dt w, s + d) = base + d * (-dt, 1)
            base = np.array([x - DT * s + DT * w, s])
            rows.append(c.a @ np.array([-DT, 1.0]))
            rhs.append(c.b - c.a @ base + 1e-9)
        found = linprog([0.0], A_ub=np.concatenate(rows)[:, None], b_ub=np.concatenate(rhs),
                        bounds=[(-jump, jump)], method="highs")
        assert found.status == 0, (x, s)
    assert mod.invariant_set(band - 0.04, S_RANGE, DT, jump, OMEGA) is None


@pytest.mark.parametrize("argv, message", [
    (["--omega", "0"], "must be finite and > 0"),
    (["--rate", "-0.1"], "must be finite and > 0"),
    (["--speed", "0.5"], "must contain --speed"),
])
def test_bad_arguments_are_refused(argv, message, capsys):
    with pytest.raises(SystemExit) as stop:
        _module().main(argv)
    assert stop.value.code == 2 and message in capsys.readouterr().err
