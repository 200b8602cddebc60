"""Tests of tubekit.loop.promises on hand-built runs: each promise holds on a clean run and breaks on a run
built to break it, with the observed figure recomputed here.

The clean run: a stationary target at p_d = (0, 3, 0), the vehicle parked at (-2, 3, 0) heading +x
(toward it: e = (2, 0, 0)), the nominal equal to the state, zero input and zero disturbance, 3 periods
of 10 ticks.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tubekit.loop.promises import PREMISES, TIER_OF, Promise, broken_promises, check_promises, current_bound
from tubekit.loop.result import SimulationResult
from tubekit.plant.kinematic import Plant
from tubekit.scenario import Disturbance
from tubekit.tightening import Tightening
from tubekit.tiers import Tiers
from tubekit.model.vehicles import PlantSettings
from .tier_checks import refused_only_by_the_row_faces

TICKS, STEPS = 10, 3
TUBE = np.array([0.01, 0.01, 0.02])


def _tight(**changes) -> Tightening:
    base = dict(v_max=np.array([0.35, 0.28, 0.35]), e_d_min=0.6, e_o_max=0.3, e_z_max=0.9, e_d_max=2.9,
                obstacle_margin=0.1, sigma=10.0, margins=np.zeros((8, 4)),
                rates=np.zeros(4), tube=TUBE, region=np.array([0.5, 3.0, 1.0, 0.5]),
                disturbance=np.array([0.04, 0.02, 0.02]), tiers=Tiers(True, True))
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
            backup_anchor=np.full((rows, 3), np.nan), recovery=np.zeros(rows, dtype=bool), sway_command=np.zeros(rows))
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


def test_an_applied_surge_below_u_min_breaks_inputs(stationary):
    """With a minimum surge u_min = 0.1 m/s the surge is bounded below too: one tick at 0.05 m/s is outside V even
    though |u| <= u_max (observed 1 + (u_min - u) / u_max), a broken promise of the safe tier; at u_min it holds."""
    keep_moving = stationary.with_changes(**{"limits.u_min": 0.1})
    run = _run(stationary, scenario=keep_moving)
    inputs = run.inputs.copy()
    inputs[:-1, 0] = 0.2
    assert _promise(replace(run, inputs=inputs), "inputs").ok
    inputs[7, 0] = 0.05
    slow = replace(run, inputs=inputs)
    p = _promise(slow, "inputs")
    assert not p.ok and p.observed == pytest.approx(1.0 + 0.05 / keep_moving.limits.u_max) and "u_min" in p.detail
    assert "inputs" in broken_promises(check_promises(slow)) and not slow.checks["inputs_within_limits"]
    assert _promise(replace(run, inputs=inputs, scenario=stationary), "inputs").ok   # no floor: 0.05 is in V
    inputs[7, 0] = 0.1
    assert _promise(replace(run, inputs=inputs), "inputs").ok and replace(run, inputs=inputs).checks[
        "inputs_within_limits"]


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

    best_effort = _run(stationary, tightening=_tight(tiers=Tiers(), tube=np.zeros(3)))
    with pytest.raises(ConfigError, match=r"^run\.tightening: expected a certified tightening .* best-effort "
                                          r"tightening, tube = \[0\.0, 0\.0, 0\.0\]"):
        check_promises(best_effort)
    figures = {p.name: p for p in check_promises(best_effort, uncertified=True)}
    assert figures["tube"].observed == math.inf  # asked for: a zero tube gives an infinite ratio


# ---- issue 30: on the dynamic plant the premise is the water current; the derived bounds are promises ----------

LOOP = (0.005, 0.005, 0.01)  # E (m/s, m/s, rad/s): the certificate's derived loop bound in these runs
GAMMA = 0.02                 # γ̄ (m/s): its derived bound on the hull's sway
WATER = Disturbance(amplitude=(0.0, 0.0, 0.0), constant=(0.03, 0.0, 0.02))  # a steady current at its bound


def _design(scenario) -> dict:
    """Tightening fields recording the design a certificate of ``scenario`` read (its current, its box)."""
    from tubekit.design_inputs import DesignInputs
    return {"design": DesignInputs.of(scenario, sigma=10.0)}


def _dynamic(stationary, **changes) -> SimulationResult:
    """A clean run on the dynamic plant: the hull at the command (no loop error, no sway) in the steady current
    WATER, so ω = δ; ω̄ composed as the certificate does: ω̄_xy = ‖c_xy‖ + ‖(E_u, γ̄)‖, ω̄_z = |c_z| + E_w."""
    sc = replace(stationary, plant=PlantSettings("dynamic", "bluerov2_heavy"), disturbance=WATER)
    cxy, cz = current_bound(sc)
    tight = _tight(velocity_loop=LOOP, disturbance=np.array([cxy + math.hypot(LOOP[0], GAMMA), cz + LOOP[1], GAMMA]),
                   **_design(sc))
    run = _run(stationary, scenario=sc, tightening=tight)
    water = Plant(WATER).current(run.t)
    water[-1] = np.nan
    fields = dict(body=np.zeros((len(run.t), 4)), thrust=np.zeros((len(run.t), 3)), omega=water)
    fields.update(changes)
    return replace(run, **fields)


def _off_the_hull(run, row: int, du: float = 0.0, vb: float = 0.0, dw: float = 0.0) -> SimulationResult:
    """``run`` with the hull off its command at ``row`` (ψ = 0): ω gains (u_b - u, v_b, w_b - w), as the plant logs."""
    body, omega = run.body.copy(), run.omega.copy()
    body[row, :3] += [du, vb, dw]
    omega[row] += [du, vb, dw]
    return replace(run, body=body, omega=omega)


def test_the_current_bound_is_the_certificates_current_term(stationary):
    """max(a_x, a_y) + ||c_xy|| and a_z + |c_z| (verify.theorem.design.disturbance_bounds), by hand."""
    sc = replace(stationary, disturbance=Disturbance(amplitude=(0.01, 0.04, 0.03), constant=(0.03, 0.04, -0.02)))
    assert current_bound(sc) == pytest.approx((0.04 + 0.05, 0.03 + 0.02))


def test_on_the_dynamic_plant_a_loop_error_over_its_bound_is_a_broken_promise_not_a_failed_premise(stationary):
    """Issue 30: w_b - w = 0.02 > E_w = 0.005 lifts ω_z to 0.04 > ω̄_z = 0.025, while the current stays at its
    bound 0.02: the premise (the current) holds and velocity_loop is broken (exit 4), no longer suppressed."""
    clean = _dynamic(stationary)
    assert all(p.ok for p in check_promises(clean)), [p for p in check_promises(clean) if not p.ok]
    run = _off_the_hull(clean, 4, dw=0.02)
    assert run.omega[4, 2] > run.tightening.disturbance.omega_z  # the old premise (total ω) fails here
    by = {p.name: p for p in check_promises(run)}
    assert by["disturbance"].ok and by["plant_in_box"].ok
    assert not by["velocity_loop"].ok and by["velocity_loop"].observed == pytest.approx(4.0)
    assert by["velocity_loop"].depends_on == ("disturbance", "recursive_feasibility", "plant_in_box")
    assert broken_promises(list(by.values())) == ("velocity_loop",)


def test_on_the_dynamic_plant_hull_sway_over_gamma_bar_is_a_broken_promise_not_a_failed_premise(stationary):
    """v_b = 0.05 > γ̄ = 0.02 lifts ||ω_xy|| to ||(0.03, 0.05)|| = 0.058 > ω̄_xy = 0.051: sway is broken."""
    run = _off_the_hull(_dynamic(stationary), 7, vb=0.05)
    assert math.hypot(*run.omega[7, :2]) > run.tightening.disturbance.omega_xy
    by = {p.name: p for p in check_promises(run)}
    assert by["disturbance"].ok and not by["sway"].ok and by["sway"].observed == pytest.approx(0.05)
    assert broken_promises(list(by.values())) == ("sway",)


def test_the_dynamic_premise_reads_the_logged_current_and_its_peak_between_ticks(stationary):
    """With the plant's ``current`` column and ``current_peak`` the premise reads them, not ω: a total ω
    peak far over ω̄ leaves it held; a current peak over its bound between ticks fails it, and then the
    broken loop bound is void (a premise failure is never a broken promise)."""
    clean = _dynamic(stationary)
    run = replace(_off_the_hull(clean, 4, dw=0.02), current=clean.omega.copy(), current_peak=(0.03, 0.02),
                  omega_peak=(0.5, 0.5))
    by = {p.name: p for p in check_promises(run)}
    assert by["disturbance"].ok and "0.03, 0.02 m/s" in by["disturbance"].detail
    assert broken_promises(list(by.values())) == ("velocity_loop",)
    stormy = replace(run, current_peak=(0.03, 0.026))  # 0.006 m/s over a_z + |c_z| = 0.02, between ticks
    by = {p.name: p for p in check_promises(stormy)}
    assert not by["disturbance"].ok and by["disturbance"].observed == pytest.approx(0.006, abs=1e-11)
    assert not by["velocity_loop"].ok and broken_promises(list(by.values())) == ()


def test_the_kinematic_premise_still_reads_the_total_omega(stationary):
    """On the kinematic plant ω = current + the sway model is what the certificate assumes: unchanged."""
    run = _run(stationary)
    omega = run.omega.copy()
    omega[3] = [0.03, 0.04, 0.0]
    by = {p.name: p for p in check_promises(replace(run, omega=omega))}
    assert not by["disturbance"].ok and "plant_in_box" not in by
    assert by["tube"].depends_on == ("disturbance", "recursive_feasibility")


def test_plant_in_box_is_a_premise_of_both_tiers_on_the_dynamic_plant(stationary):
    assert "plant_in_box" in PREMISES and TIER_OF["plant_in_box"] == "premise"
    by = {p.name: p for p in check_promises(_dynamic(stationary))}
    assert by["plant_in_box"].ok and by["plant_in_box"].tier == "premise" and by["plant_in_box"].depends_on == ()
    for name in ("tube", "clearance", "sway", "velocity_loop"):
        assert "plant_in_box" in by[name].depends_on


def _scaled(factor: float) -> PlantSettings:
    """The BlueROV2 Heavy with every coefficient of its nominal point times ``factor`` (a point vehicle)."""
    nominal = PlantSettings("dynamic", "bluerov2_heavy").params.nominal.to_dict()
    return PlantSettings("dynamic", "bluerov2_heavy",
                         overrides={k: factor * v for k, v in nominal.items() if not isinstance(v, str)})


@pytest.mark.parametrize("factor", [0.2, 0.5, 1.6])
def test_a_vehicle_outside_the_certified_box_fails_plant_in_box(stationary, factor):
    """Issue 30: the vehicle simulated is the certified one with every coefficient times 0.2, 0.5 or 1.6; the
    certificate's box is its design's vehicle. The premise fails naming the first coefficient outside (m), and
    the promises resting on it are void."""
    clean = _dynamic(stationary)
    moved = replace(clean.scenario, plant=_scaled(factor))
    run = _off_the_hull(replace(clean, scenario=moved), 4, dw=0.02)
    by = {p.name: p for p in check_promises(run)}
    p = by["plant_in_box"]
    m = PlantSettings("dynamic", "bluerov2_heavy").params.m
    assert not p.ok and p.observed > 1 and f"first m = {factor * m:.6g} outside [{m:.6g}, {m:.6g}]" in p.detail
    assert by["disturbance"].ok and not by["velocity_loop"].ok and broken_promises(list(by.values())) == ()


def test_a_truth_anywhere_in_the_box_keeps_plant_in_box(stationary):
    """The midpoints (no truth) and a corner of the box (every interval at its low end) are in the box."""
    clean = _dynamic(stationary)
    box = clean.scenario.plant.params
    assert box.interval_fields  # the shipped BlueROV2 Heavy is a box
    corner = PlantSettings("dynamic", "bluerov2_heavy", truth={k: box.interval(k)[0] for k in box.interval_fields})
    for run in (clean, replace(clean, scenario=replace(clean.scenario, plant=corner))):
        p = _promise(run, "plant_in_box")
        assert p.ok and p.observed == 0.0 and "every coefficient inside" in p.detail
    no_design = replace(clean, tightening=replace(clean.tightening, design=None),
                        scenario=replace(clean.scenario, plant=_scaled(1.6)))
    assert _promise(no_design, "plant_in_box").ok  # no design recorded: the run's own vehicle is the box


SLOW = Path(__file__).resolve().parents[1] / "examples" / "bluerov2_slow.toml"


@pytest.fixture(scope="module")
def slow_cert():
    """The certificate of examples/bluerov2_slow.toml (both tiers, a few seconds)."""
    import verify
    from tubekit import load_scenario
    return verify.certify(load_scenario(SLOW))


def test_a_real_dynamic_run_over_its_loop_bound_reports_velocity_loop_broken(slow_cert):
    """End to end (issue 30): the certified examples/bluerov2_slow.toml for 4 s, with the loop bound E replaced by
    E / 1000 and ω̄ recomposed from it (current bound + ||(E_u, γ̄)||, + E_w). The loop error exceeds that E
    hundreds of times and the total ω exceeds ω̄_z (the premise as it was failed and suppressed the promise);
    the water current the plant logged stays within its certified bound, so velocity_loop is broken."""
    import tubekit
    from tubekit import load_scenario
    sc = load_scenario(SLOW)
    tight = slow_cert.tightening
    tiny = tuple(e / 1000.0 for e in tight.velocity_loop)
    cxy, cz = current_bound(sc)
    gamma = tight.disturbance.sway
    tight = replace(tight, velocity_loop=tiny, disturbance=(cxy + math.hypot(tiny[0], gamma), cz + tiny[1], gamma))
    run = tubekit.simulate(sc, tight, duration=4.0, progress=False)
    assert run.omega_peak[1] > tight.disturbance.omega_z
    by = {p.name: p for p in check_promises(run)}
    assert not by["velocity_loop"].ok and by["velocity_loop"].observed > 100.0
    assert by["disturbance"].ok and by["plant_in_box"].ok and by["recursive_feasibility"].ok
    assert "velocity_loop" in broken_promises(list(by.values()))
    np.testing.assert_array_equal(run.current, Plant(sc.disturbance).current(run.t))  # logged apart from ω
    assert run.current_peak[0] <= cxy + 1e-12 and run.current_peak[1] <= cz + 1e-12


def _p(name, ok, tier, depends_on=("disturbance",), observed=0.0):
    from tubekit.loop.promises import Promise
    return Promise(name, observed, 1.0, ok, "", tier=tier, depends_on=depends_on, given=True)


@pytest.mark.parametrize("promises, tiers, want", [
    ([_p("clearance", True, "safe"), _p("tube", True, "tracking", ("disturbance", "recursive_feasibility")),
      _p("disturbance", True, "premise", ()), _p("recursive_feasibility", True, "premise", ())],
     Tiers(True, True), {"safe": "certified, kept", "tracking": "certified, kept"}),
    ([_p("clearance", True, "safe"), _p("tube", False, "tracking", ("disturbance", "recursive_feasibility")),
      _p("disturbance", True, "premise", ()), _p("recursive_feasibility", False, "premise", ())],
     Tiers(True, True), {"safe": "certified, kept",
                         "tracking": "certified, not in force (recursive_feasibility failed)"}),
    ([_p("clearance", False, "safe"), _p("disturbance", True, "premise", ())],
     Tiers(True, False), {"safe": "certified, BROKEN (clearance)", "tracking": "not certified"}),
    ([_p("clearance", True, "safe")], Tiers(), {"safe": "not certified", "tracking": "not certified"}),
])
def test_each_tier_says_what_happened_on_the_run(promises, tiers, want):
    """Issue 31, item 3: a certified tier is reported with its outcome (kept, BROKEN, not in force), never alone."""
    from tubekit.loop.promises import tier_outcomes
    assert tier_outcomes(promises, tiers) == want


_LAW = dict(d_lo=0.6, d_hi=2.5, d_star=1.5, alpha_max=0.2, z_max=0.8, gain_d=0.5, gain_z=0.3, turn=0.5)


def test_with_the_tracking_theorem_a_plan_at_every_period_is_a_promise_of_tracking(stationary):
    """With the terminal law (and the candidate on), recursive feasibility is proved: ``plan_available`` replaces
    the premise, tracking rests on the disturbance bound alone, and a clean run keeps it."""
    from tubekit.model.terminal_law import TerminalLaw
    run = _run(stationary, tightening=_tight(terminal_law=TerminalLaw(**_LAW)))
    p = _promise(run, "plan_available")
    assert p.ok and p.tier == "tracking" and p.depends_on == ("disturbance",) and p.given
    assert "recursive_feasibility" not in {q.name for q in check_promises(run)}
    assert _promise(run, "tube").depends_on == ("disturbance",)


@pytest.mark.parametrize("lapse", ["replay", "backup"])
def test_a_lapse_of_plans_under_the_tracking_theorem_is_a_broken_promise(stationary, lapse):
    """A replayed plan or a backup tick under a certified tracking tier with its terminal law: broken (exit 4), not
    a failed premise."""
    from tubekit.model.terminal_law import TerminalLaw
    run = _run(stationary, tightening=_tight(terminal_law=TerminalLaw(**_LAW)))
    if lapse == "replay":
        age = run.plan_age.copy()
        age[1] = 1
        run = replace(run, plan_age=age)
    else:
        active = run.backup_active.copy()
        active[2:4] = True
        run = replace(run, backup_active=active)
    p = _promise(run, "plan_available")
    assert not p.ok and p.observed >= 1
    assert "plan_available" in broken_promises(check_promises(run))


def test_without_the_candidate_plans_stay_a_premise(stationary):
    from tubekit.model.terminal_law import TerminalLaw
    sc = stationary.with_changes(**{"controller.candidate": False})
    run = _run(stationary, scenario=sc, tightening=_tight(terminal_law=TerminalLaw(**_LAW)))
    assert "plan_available" not in {q.name for q in check_promises(run)}
    assert _promise(run, "recursive_feasibility").tier == "premise"


def test_the_bluerov2_in_the_papers_current_keeps_every_safe_promise_with_its_sway_loop():
    """examples/bluerov2_current.toml (0.1 m/s of current per axis, the paper's): the safe tier is certified because
    the lateral thrust regulates the sway (γ̄ = E_v, below 1 cm/s, instead of the hull's ~0.1 m/s); flown for 20 s
    every safe promise is kept, a plan is followed at every period and the sway stays within E_v."""
    import tubekit
    import verify
    from tubekit import load_scenario
    sc = load_scenario(SLOW.with_name("bluerov2_current.toml"))
    cert = verify.certify(sc)
    assert cert.tiers.safe and refused_only_by_the_row_faces(c.condition for c in cert.failures)
    assert cert.velocity_loop.sway <= cert.disturbance.gamma < 0.01      # E_v below the sway ω̄ assumed
    run = tubekit.simulate(sc, cert.tightening, duration=20.0, progress=False)
    by = {p.name: p for p in check_promises(run)}
    assert all(p.ok for p in by.values() if p.tier in ("safe", "premise")), [p for p in by.values() if not p.ok]
    assert by["sway"].observed <= cert.disturbance.gamma and by["recursive_feasibility"].observed == 0


@pytest.mark.parametrize("end", [0, 1])
def test_the_bluerov2_over_twenty_percent_keeps_every_safe_promise_at_a_corner_of_its_box(end):
    """examples/bluerov2_spread.toml (every coefficient von Benzon's ±20 %, the loop at 20 rad/s): the safe tier is
    certified for the whole box; flown for 20 s with the simulated hull at a corner of the box (every interval at
    its low, then its high end; the controller's feedforward keeps the midpoints) every safe promise is kept, a plan
    is followed at every period, and the loop's error stays within the certificate's E."""
    import dataclasses

    import tubekit
    import verify
    from tubekit import load_scenario
    sc = load_scenario(SLOW.with_name("bluerov2_spread.toml"))
    box = sc.plant.params
    assert box.loop_bandwidth == 20.0 and box.interval("X_uu") == pytest.approx((-169.2, -112.8))
    cert = verify.certify(sc)
    assert cert.tiers == Tiers(True, False)
    corner = dataclasses.replace(sc.plant, truth=tuple((k, box.interval(k)[end]) for k in box.interval_fields))
    run = tubekit.simulate(sc.with_changes(plant=corner), cert.tightening, duration=20.0, progress=False)
    by = {p.name: p for p in check_promises(run)}
    assert all(p.ok for p in by.values() if p.tier in ("safe", "premise")), [p for p in by.values() if not p.ok]
    assert by["plant_in_box"].observed == 0.0 and by["recursive_feasibility"].observed == 0
    assert 0.0 < by["velocity_loop"].observed < 1.0


def test_the_bluerov2_after_a_fifth_of_a_metre_per_second_in_the_papers_current_keeps_every_safe_promise():
    """examples/bluerov2_brisk_current.toml (a 0.2 m/s target, 0.1 m/s of current per axis, every coefficient ±10 %,
    the loop at 20 rad/s): the safe tier is certified with tracking refused only for ``terminal_rate`` (the fixed
    point closes from a restart); flown for 20 s every safe promise is kept and a plan is followed at every period."""
    import tubekit
    import verify
    from tubekit import load_scenario
    sc = load_scenario(SLOW.with_name("bluerov2_brisk_current.toml"))
    assert sc.trajectory.rate * sc.trajectory.radius == pytest.approx(0.2) and sc.disturbance.amplitude[0] == 0.1
    cert = verify.certify(sc)
    assert cert.tiers.safe and refused_only_by_the_row_faces(c.condition for c in cert.failures)
    keep_up = next(c for c in cert.conditions if c.condition == "keep_up[u]")
    assert keep_up.ok and keep_up.rhs < keep_up.lhs == pytest.approx(0.35)
    run = tubekit.simulate(sc, cert.tightening, duration=20.0, progress=False)
    by = {p.name: p for p in check_promises(run)}
    assert all(p.ok for p in by.values() if p.tier in ("safe", "premise")), [p for p in by.values() if not p.ok]
    assert by["recursive_feasibility"].observed == 0 and 0.0 < by["velocity_loop"].observed < 1.0

