"""Tests of tubekit.loop.promises on hand-built runs: each promise holds on a clean run and breaks on a run
built to break it, with the observed figure recomputed here.

The clean run: a stationary target at p_d = (0, 3, 0), the vehicle parked at (-2, 3, 0) heading +x
(toward it: e = (2, 0, 0)), the nominal equal to the state, zero input and zero disturbance, 3 periods
of 10 ticks.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tubekit.loop.promises import Promise, check_promises
from tubekit.loop.result import SimulationResult
from tubekit.tightening import Tightening
from tubekit.model.vehicles import PlantSettings

TICKS, STEPS = 10, 3
TUBE = np.array([0.01, 0.01, 0.02])


def _tight(**changes) -> Tightening:
    base = dict(v_max=np.array([0.35, 0.28, 0.35]), e_d_min=0.6, e_o_max=0.3, e_z_max=0.9, e_d_max=2.9,
                obstacle_margin=0.1, rho_tilde=float(np.linalg.norm(TUBE)), sigma=10.0, margins=np.zeros((8, 4)),
                rates=np.zeros(4), tube=TUBE, region=np.array([0.5, 3.0, 1.0, 0.5]),
                disturbance=np.array([0.04, 0.02, 0.02]), certified=True)
    base.update(changes)
    return Tightening(**base)


def _run(stationary, **changes) -> SimulationResult:
    rows = STEPS * TICKS + 1
    states = np.tile([-2.0, 3.0, 0.0, 0.0], (rows, 1))
    inputs = np.zeros((rows, 3))
    inputs[-1] = np.nan
    omega = np.zeros((rows, 3))
    omega[-1] = np.nan
    fields = dict(
        scenario=stationary, tube=True, law="corrected", sigma=10.0, tightening=_tight(), plant_step_s=0.005,
        ticks_per_step=TICKS, t=np.arange(rows) * 0.01, step=np.minimum(np.arange(rows) // TICKS, STEPS),
        states=states, desired=np.tile([0.0, 3.0, 0.0], (rows, 1)), nominal=states.copy(), v_hat=inputs.copy(),
        kappa=np.zeros((rows, 3)), inputs=inputs, omega=omega, saturated=np.zeros(rows, dtype=bool),
        fallback=np.zeros(rows, dtype=bool), replaced=np.zeros(rows, dtype=bool), n_detected=np.zeros(rows, int),
        solve_ms=np.zeros(rows), step_ms=np.zeros(rows), wall=np.zeros(rows), rejected=np.zeros(STEPS, dtype=bool),
        plan_age=np.zeros(STEPS, dtype=int), plan_slack=np.zeros(STEPS),
            backup_active=np.zeros(rows, dtype=bool),
            backup_anchor=np.full((rows, 3), np.nan))
    fields.update(changes)
    return SimulationResult(**fields)


def _promise(run, name) -> Promise:
    found = [p for p in check_promises(run) if p.name == name]
    assert len(found) == 1
    return found[0]


def test_a_clean_run_keeps_every_promise(stationary):
    promises = check_promises(_run(stationary))
    assert {p.name for p in promises} == {"tube", "region", "epsilon", "inputs", "clearance", "workspace", "sway",
                                          "disturbance", "recursive_feasibility"}
    assert all(p.ok for p in promises), [p for p in promises if not p.ok]
    by = {p.name: p for p in promises}
    assert by["tube"].observed == 0.0 and by["epsilon"].observed == pytest.approx(2.0)
    assert by["region"].observed == pytest.approx(0.5)     # |e_o| = 0 against 0.5 is the smallest slack
    for p in promises:
        d = p.to_dict()
        assert set(d) == {"name", "observed", "bound", "ok", "detail", "tier", "depends_on", "given"}


def test_a_deviation_beyond_the_tube_breaks_tube(stationary):
    run = _run(stationary)
    nominal = run.nominal.copy()
    nominal[13, 0] -= 0.015           # nominal 2.015 m from the target, real 2 m: |rho_d| = 0.015 = 1.5 tube_d
    p = _promise(replace(run, nominal=nominal), "tube")
    assert not p.ok and p.observed == pytest.approx(1.5) and p.bound == 1.0
    nominal[13, 0] += 0.0059          # 0.0091 m: inside
    assert _promise(replace(run, nominal=nominal), "tube").ok


def test_saturated_ticks_break_inputs(stationary):
    run = _run(stationary)
    sat = run.saturated.copy()
    sat[4] = True
    p = _promise(replace(run, saturated=sat), "inputs")
    assert not p.ok and "clipped ticks = 1" in p.detail
    inputs = run.inputs.copy()
    inputs[7] = [0.44, 0.0, 0.0]      # 1.1 u_max
    p = _promise(replace(run, inputs=inputs), "inputs")
    assert not p.ok and p.observed == pytest.approx(1.1)


@pytest.mark.parametrize("age, replaced0, ok", [
    ([0, 1, 7], False, True),         # N - 1 = 7 periods old: still covered by the candidate
    ([0, 1, 8], False, False),        # older than N - 1
    ([0, 0, 0], True, False),         # no plan accepted at t = 0
])
def test_recursive_feasibility(stationary, age, replaced0, ok):
    run = _run(stationary)
    replaced = run.replaced.copy()
    replaced[0] = replaced0
    p = _promise(replace(run, plan_age=np.array(age), replaced=replaced), "recursive_feasibility")
    assert p.ok is ok and p.observed == max(age) and p.bound == 7.0


def test_leaving_r_breaks_region_and_epsilon(stationary):
    run = _run(stationary)
    states = run.states.copy()
    states[20:, 0] = -0.45            # e_d = 0.45 < epsilon = 0.5
    moved = replace(run, states=states, nominal=states.copy())
    assert not _promise(moved, "epsilon").ok and _promise(moved, "epsilon").observed == pytest.approx(0.45)
    assert not _promise(moved, "region").ok and _promise(moved, "region").observed == pytest.approx(-0.05)
    away = run.states.copy()
    away[5:, 3] = math.pi             # pointing away: outside the certified hemisphere
    assert not _promise(replace(run, states=away, nominal=away.copy()), "region").ok


def test_clearance_is_padded_by_half_a_tick(stationary):
    """Obstacle (-3, 0, 0) r 0.4, vehicle r 0.2; pad = 0.005 s * (||(0.4, 0.3)|| + ||(0.04, 0.02)||)."""
    run = _run(stationary)
    pad = 0.005 * (0.5 + math.hypot(0.04, 0.02))
    states = run.states.copy()
    states[10] = [-3.0 + 0.6 + pad / 2, 0.0, 0.0, 0.0]    # clear at the tick, not by the pad
    p = _promise(replace(run, states=states, nominal=states.copy()), "clearance")
    assert not p.ok and p.observed == pytest.approx(-pad / 2)


def test_disturbance_and_sway_are_checked(stationary):
    run = _run(stationary)
    omega = run.omega.copy()
    omega[3] = [0.03, 0.04, 0.0]      # ||omega_xy|| = 0.05 > 0.04
    p = _promise(replace(run, omega=omega), "disturbance")
    assert not p.ok and p.observed == pytest.approx(0.01, abs=1e-11)
    inputs = run.inputs.copy()
    inputs[2] = [0.4, 0.0, 0.5]       # sway model: 0.1 * 0.4 * 0.5 = 0.02 m/s
    assert _promise(replace(run, inputs=inputs), "sway").ok
    low = replace(run, inputs=inputs, tightening=_tight(disturbance=np.array([0.04, 0.02, 0.01])))
    p = _promise(low, "sway")
    assert not p.ok and p.observed == pytest.approx(0.02)


def test_dynamic_runs_check_hull_sway_and_the_velocity_loop(stationary):
    sc = replace(stationary, plant=PlantSettings("dynamic"))
    run = replace(_run(stationary, scenario=sc), tightening=_tight(velocity_loop=(0.05, 0.02, 0.1)))
    rows = len(run.t)
    body = np.zeros((rows, 4))
    thrust = np.zeros((rows, 3))
    clean = replace(run, body=body, thrust=thrust)
    assert all(p.ok for p in check_promises(clean))
    assert _promise(clean, "velocity_loop").observed == 0.0
    off = body.copy()
    off[4] = [0.06, 0.0, 0.0, 0.05]     # |u_b - u| = 0.06 > 0.05: ratio 1.2
    p = _promise(replace(run, body=off, thrust=thrust), "velocity_loop")
    assert not p.ok and p.observed == pytest.approx(1.2)
    off = body.copy()
    off[7, 1] = 0.03                    # hull sway 0.03 m/s > gamma_bar = 0.02
    p = _promise(replace(run, body=off, thrust=thrust), "sway")
    assert not p.ok and p.observed == pytest.approx(0.03)
    assert "velocity_loop" not in {p.name for p in check_promises(run)}  # kinematic: no such promise
    no_bound = replace(clean, tightening=_tight())
    assert "velocity_loop" not in {p.name for p in check_promises(no_bound)}  # no certified loop bound: none


def test_a_run_without_a_certificate_is_refused(stationary):
    """The baseline (no tube) is promised nothing: no infinite tube ratio comes back, a ConfigError does."""
    from tubekit.exceptions import ConfigError

    baseline = replace(_run(stationary), tube=False, sigma=0.0, tightening=Tightening.untightened(stationary))
    with pytest.raises(ConfigError, match="run: expected a tube run .* without a certificate"):
        check_promises(baseline)


def test_a_best_effort_run_is_refused_unless_asked(stationary):
    """Issue 24 item 9: a tube run under a tightening no certificate gave (here tube-less: zeros) is refused,
    naming what is missing, instead of measuring an infinite tube ratio; ``uncertified=True`` measures it."""
    from tubekit.exceptions import ConfigError

    best_effort = _run(stationary, tightening=_tight(certified=False, tube=np.zeros(3)))
    with pytest.raises(ConfigError, match=r"^run\.tightening: expected a certified tightening .* best-effort "
                                          r"tightening, tube = \[0\.0, 0\.0, 0\.0\]"):
        check_promises(best_effort)
    figures = {p.name: p for p in check_promises(best_effort, uncertified=True)}
    assert figures["tube"].observed == math.inf  # asked for: a zero tube gives an infinite ratio
