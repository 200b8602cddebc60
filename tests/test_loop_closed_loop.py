"""Closed loop: plant integration, nominal propagation, fallback path, saturation counting, rho log."""

from __future__ import annotations

from tubekit.tiers import Tiers

import dataclasses
import math

import numpy as np
import pytest

from tubekit import ConfigError, SolverError, Tightening, paper_scenario
from tubekit.loop.closed_loop import PlanMemory, run_closed_loop, saturate
from tubekit.loop.result import CSV_COLUMNS
from tubekit.plant.kinematic import nominal_arc
from tubekit.fhocp import FhocpResult
from tubekit.loop.metrics import read_trajectory_csv
from tubekit.model.kinematics import SwayModel
from tubekit.scenario import Disturbance
from tubekit.model.backup import BackupPlan, SafeSet, StationKeeping, station_keeping_input


def _scenario(duration=5.0, **dist):
    sc = paper_scenario().with_changes(duration=duration)
    if dist:
        sc = sc.with_changes(disturbance=Disturbance(**dist))
    return sc


class Pursuit:
    """Stand-in FHOCP: pursue a point 1 s ahead on p_d; optional injected failures.

    ``nan_at``: steps whose result has a NaN first input (flagged fallback);
    ``raise_at``: steps that raise SolverError; ``flag_at``: finite fallback results.
    """

    def __init__(self, sc, tg, nan_at=(), raise_at=(), flag_at=(), u=0.3):
        self.sc, self.tg, self.k, self.u = sc, tg, -1, u
        self.nan_at, self.raise_at, self.flag_at = set(nan_at), set(raise_at), set(flag_at)
        self.plans = {}

    def solve(self, t, state, obstacles):
        self.k += 1
        if self.k in self.raise_at:
            raise SolverError("injected")
        pd = self.sc.trajectory.position(t + 1.0)
        bearing = math.atan2(pd[1] - state[1], pd[0] - state[0])
        err = math.atan2(math.sin(bearing - state[3]), math.cos(bearing - state[3]))
        n = self.sc.controller.horizon_steps
        plan = np.column_stack([np.full(n, self.u), 0.1 * np.arange(n) / n - 0.05,
                                np.clip(1.5 * err + 0.01 * np.arange(n), -0.45, 0.45)])
        self.plans[self.k] = plan
        inputs = plan.copy()
        if self.k in self.nan_at:
            inputs[0] = np.nan  # the first input is not finite
        fallback = self.k in self.nan_at or self.k in self.flag_at
        return FhocpResult(status="fallback" if fallback else "optimal", states=np.zeros((n + 1, 4)),
                           inputs=inputs, cost=1.0, iterations=1, solve_time_s=2e-5, setup_time_s=0.0,
                           max_violation=0.0, fallback=fallback, t=t)


def _tightening(sc, sigma):
    return dataclasses.replace(Tightening.untightened(sc), sigma=sigma)


# ---- closed loop ---------------------------------------------------------------------

def test_no_disturbance_means_no_deviation_from_nominal():
    sc = _scenario(amplitude=(0.0, 0.0, 0.0), sway=SwayModel(gain=0.0, amplitude=0.0, bound=0.0))
    res = run_closed_loop(sc, tightening=_tightening(sc, 1.0), solver_factory=Pursuit, progress=False)
    assert np.max(np.abs(res.rho)) < 1e-9
    assert np.max(np.abs(res.kappa[:-1])) < 1e-8
    assert res.saturated_ticks == 0


@pytest.mark.parametrize("sigma", [0.0, 1.0])
def test_the_observer_is_told_the_state_the_nominal_and_the_target_at_every_tick(sigma):
    """With or without the ancillary law (sigma = 0 does not call it), ``observer`` hears every tick a plan is
    followed, before its command: the logged state, the nominal (rho = state - nominal) and the desired position."""
    sc = _scenario(duration=2.0)
    heard = []
    res = run_closed_loop(sc, tightening=_tightening(sc, sigma), solver_factory=Pursuit, progress=False,
                          observer=lambda x, x_hat, p_d: heard.append((x.copy(), x_hat.copy(), p_d.copy())))
    ticks = sc.steps * res.ticks_per_step
    assert len(heard) == ticks
    np.testing.assert_array_equal(np.array([h[0] for h in heard]), res.states[:ticks])
    np.testing.assert_array_equal(np.array([h[2] for h in heard]), res.desired[:ticks])
    gap = np.array([h[0] - h[1] for h in heard])
    at_samples = np.arange(ticks) % res.ticks_per_step == 0
    np.testing.assert_allclose(gap[at_samples], 0.0, atol=1e-12)      # the nominal is reset onto the state
    np.testing.assert_allclose(gap[~at_samples], (res.states[:ticks] - res.nominal[:ticks])[~at_samples], atol=1e-12)


def test_rho_logged_and_reset_each_sample():
    sc = _scenario(duration=6.0)
    res = run_closed_loop(sc, tightening=_tightening(sc, 1.0), solver_factory=Pursuit, progress=False)
    m = res.ticks_per_step
    rho = np.linalg.norm(res.rho, axis=1)
    assert res.states.shape == (sc.steps * m + 1, 4)
    assert rho[0] == 0.0
    assert np.max(rho) > 1e-4  # the current really perturbs the plant
    # kappa at each sampling instant uses the reset nominal (rho = 0) ...
    np.testing.assert_allclose(res.kappa[0:-1:m], 0.0, atol=1e-12)
    # ... and inside an interval it is -sigma J^-1 rho computed from the logged rho
    from tubekit.model.ancillary import jacobian_at
    i = 5 * m + 7
    want = -1.0 * np.linalg.solve(jacobian_at(res.states[i], res.desired[i]), res.rho[i])
    np.testing.assert_allclose(res.kappa[i], want, rtol=1e-9, atol=1e-12)
    # the logged nominal is the exact arc under the held v_hat from the state at the sampling instant
    k0 = 3 * m
    arc = nominal_arc(res.states[k0], res.v_hat[k0], np.arange(m + 1) * (sc.controller.dt / m))
    np.testing.assert_allclose(res.nominal[k0 + 1:k0 + m], arc[1:m], atol=1e-12)
    np.testing.assert_allclose(res.nominal[k0 + m], arc[m], atol=1e-12)  # left limit at the next sample


def test_baseline_has_no_feedback():
    sc = _scenario()
    res = run_closed_loop(sc, tube=False, solver_factory=Pursuit, progress=False)
    assert res.sigma == 0.0
    np.testing.assert_array_equal(res.inputs[:-1], res.v_hat[:-1])
    assert np.all(res.kappa[:-1] == 0.0)


def test_tube_requires_tightening():
    with pytest.raises(ConfigError, match="tightening"):
        run_closed_loop(_scenario(), tube=True, solver_factory=Pursuit, progress=False)


def test_fallback_path_never_passes_nan_and_is_counted():
    sc = _scenario(duration=5.0)
    nan_at, raise_at, flag_at = {3, 4, 20}, {10, 11, 12}, {30}
    holder = {}

    def factory(s, tg):
        holder["p"] = Pursuit(s, tg, nan_at=nan_at, raise_at=raise_at, flag_at=flag_at)
        return holder["p"]

    res = run_closed_loop(sc, tightening=_tightening(sc, 1.0), solver_factory=factory, progress=False)
    m = res.ticks_per_step
    assert all(res.checks.values()), res.checks
    assert np.all(np.isfinite(res.inputs[:-1])) and np.all(np.isfinite(res.states))
    assert res.replaced_steps == len(nan_at | raise_at)
    assert res.fallback_steps == len(nan_at | raise_at | flag_at)
    assert [k for k in range(sc.steps) if res.replaced[k * m]] == sorted(nan_at | raise_at)
    plans = holder["p"].plans
    # replaced steps use the last good plan, shifted by the steps elapsed since it was computed
    np.testing.assert_allclose(res.v_hat[3 * m], plans[2][1])
    np.testing.assert_allclose(res.v_hat[4 * m], plans[2][2])
    np.testing.assert_allclose(res.v_hat[12 * m], plans[9][3])
    # a flagged but finite fallback result is applied as given
    np.testing.assert_allclose(res.v_hat[30 * m], plans[30][0])
    assert res.statuses.count("exception") == len(raise_at)


def test_fallback_with_exhausted_plan_stops_the_vehicle():
    sc = _scenario(duration=2.0)
    res = run_closed_loop(sc, tube=False, progress=False,
                          solver_factory=lambda s, tg: Pursuit(s, tg, raise_at=set(range(20))))
    assert res.replaced_steps == sc.steps
    np.testing.assert_array_equal(res.inputs[:-1], 0.0)
    assert np.all(np.isfinite(res.states))


class AtTheBounds(Pursuit):
    """v_hat on a corner of V, sign flipping every step: any kappa pointing outward must be clipped."""

    def solve(self, t, state, obstacles):
        res = super().solve(t, state, obstacles)
        sign = 1.0 if self.k % 2 == 0 else -1.0
        return dataclasses.replace(res, inputs=np.tile(sign * self.sc.limits.vector, (len(res.inputs), 1)))


def test_saturation_only_when_needed_and_counted():
    sc = _scenario(duration=5.0)
    res = run_closed_loop(sc, tightening=_tightening(sc, 5.0), progress=False, solver_factory=AtTheBounds)
    lim = sc.limits.vector
    raw = res.v_hat[:-1] + res.kappa[:-1]
    outside = np.any(np.abs(raw) > lim, axis=1)
    assert 0 < outside.sum() < len(outside)
    assert res.saturated_ticks == int(outside.sum())
    np.testing.assert_array_equal(res.saturated[:-1], outside)
    np.testing.assert_allclose(res.inputs[:-1], np.clip(raw, -lim, lim))
    assert res.saturated_steps == len({int(res.step[i]) for i in np.flatnonzero(outside)})
    # where v_hat + kappa is inside V it is applied unchanged
    np.testing.assert_array_equal(res.inputs[:-1][~outside], raw[~outside])
    assert res.checks["inputs_within_limits"]


def test_csv_round_trip(tmp_path):
    sc = _scenario(duration=2.0)
    res = run_closed_loop(sc, tightening=_tightening(sc, 1.0), solver_factory=Pursuit, progress=False)
    path = res.write_csv(tmp_path / "trajectory.csv")
    cols = read_trajectory_csv(path)
    assert tuple(cols) == CSV_COLUMNS
    for key in ("t", "x", "y", "z", "psi", "u", "w", "r", "x_d", "y_d", "z_d"):
        np.testing.assert_allclose(cols[key], res.columns()[key], rtol=1e-11, atol=1e-12, equal_nan=True)
    assert np.isnan(cols["u"][-1]) and cols["t"][-1] == pytest.approx(2.0)


def test_real_fhocp_short_closed_loop():
    pytest.importorskip("tubekit.fhocp")
    sc = _scenario(duration=3.0)
    base = run_closed_loop(sc, tube=False, progress=False)
    tube = run_closed_loop(sc, tightening=_tightening(sc, 0.5), progress=False)
    for res in (base, tube):
        assert all(res.checks.values()), res.checks
        assert res.steps == 30
        # the vehicle closes on the target: e_d after 3 s is below its initial 0.5 m
        assert res.errors[-1, 0] < res.errors[0, 0]


def test_real_fhocp_with_injected_fallbacks():
    fhocp = pytest.importorskip("tubekit.fhocp")
    sc = _scenario(duration=3.0)
    flagged, broken = {5, 6}, {12}

    class Flaky:
        def __init__(self, s, tg):
            self.inner, self.k, self.last = fhocp.FHOCP(s, tg), -1, None

        def solve(self, t, state, obstacles):
            self.k += 1
            res = self.inner.solve(t, state, obstacles)
            if self.k in flagged:  # what the FHOCP returns when it fails: the shifted plan, flagged
                shifted = np.vstack([self.last.inputs[1:], self.last.inputs[-1:]])
                return dataclasses.replace(res, inputs=shifted, status="fallback", fallback=True)
            if self.k in broken:
                return dataclasses.replace(res, inputs=np.full_like(res.inputs, np.nan), fallback=True)
            self.last = res
            return res

    res = run_closed_loop(sc, tightening=_tightening(sc, 0.5), solver_factory=Flaky, progress=False)
    m = res.ticks_per_step
    assert all(res.checks.values()), res.checks
    assert res.fallback_steps == 3 and res.replaced_steps == 1
    assert res.statuses.count("fallback") == 2
    assert np.all(np.isfinite(res.v_hat[12 * m:13 * m]))


def test_a_minimum_surge_holds_for_every_plan_and_every_applied_input():
    """The baseline (nominal MPC, V_bar = V) started facing away from the target: without a floor it backs up;
    with ``limits.u_min`` = 0.1 m/s every planned and applied surge stays at or above it, none clipped."""
    pytest.importorskip("tubekit.fhocp")
    sc = _scenario(duration=1.5)
    turned = list(sc.initial_state)
    turned[3] += math.pi
    sc = sc.with_changes(initial_state=tuple(turned))
    free = run_closed_loop(sc, tube=False, progress=False)
    assert np.min(free.inputs[:-1, 0]) < 0.0
    floored = run_closed_loop(sc.with_changes(**{"limits.u_min": 0.1}), tube=False, progress=False)
    assert np.min(floored.v_hat[:-1, 0]) >= 0.1 and np.min(floored.inputs[:-1, 0]) >= 0.1
    assert floored.saturated_ticks == 0 and all(floored.checks.values())

# ---- named steps -----------------------------------------------------------------------

def test_saturate_clips_only_outside_the_box():
    lim = (0.4, 0.3, 0.5)
    assert saturate((0.1, -0.3, 0.5), lim) == ((0.1, -0.3, 0.5), False)
    v, clipped = saturate((0.5, -0.35, 0.2), lim)
    assert clipped and v == (0.4, -0.3, 0.2)


def test_plan_memory_shifts_the_last_good_plan_then_stops():
    sc = _scenario(duration=1.0)
    good = Pursuit(sc, None).solve(0.0, np.asarray(sc.initial_state, dtype=float), ())
    memory = PlanMemory()
    np.testing.assert_array_equal(memory.replacement(), 0.0)  # nothing to shift yet
    assert memory.remember(good.inputs, good.fallback) is False and memory.age == 0
    assert memory.remember(good.inputs, True) is True and memory.age == 1  # a flagged plan is not remembered
    np.testing.assert_array_equal(memory.replacement(), good.inputs[2])
    for _ in range(len(good.inputs)):
        last = memory.replacement()
    np.testing.assert_array_equal(last, 0.0)


def test_dynamic_plant_run_logs_body_velocities_and_thrusts(tmp_path):
    from tubekit.loop.result import DYNAMIC_COLUMNS
    from tubekit.model.vehicles import PlantSettings
    sc = _scenario(duration=2.0).with_changes(plant=PlantSettings("dynamic"))
    res = run_closed_loop(sc, tightening=_tightening(sc, 1.0), solver_factory=Pursuit, progress=False)
    assert res.body.shape == (len(res.t), 4) and res.thrust.shape == (len(res.t), 3)
    cols = read_trajectory_csv(res.write_csv(tmp_path / "trajectory.csv"))
    assert tuple(cols) == CSV_COLUMNS + DYNAMIC_COLUMNS
    np.testing.assert_allclose(cols["v_b"], res.body[:, 1], rtol=1e-11, atol=1e-13)
    limits = np.array([sc.plant.truth_params.thrust_limits_at(u) for u in res.body[:, 0]])  # fins: ∝ u²
    assert np.all(np.abs(res.thrust) <= limits * (1 + 1e-3) + 1e-9)  # lagged by T_thr while u drifts
    # the logged omega is what moved the vehicle beyond f(x) v: current + loop error + hull sway
    assert np.all(np.isfinite(res.omega[:-1])) and np.max(np.abs(res.body[:, 1])) > 0.0
    kin_sc = sc.with_changes(**{"plant.kind": "kinematic"})
    kin = run_closed_loop(kin_sc, tightening=_tightening(sc, 1.0), solver_factory=Pursuit, progress=False)
    assert kin.body is None and np.max(np.abs(kin.states - res.states)) > 1e-4


def test_kinematic_plant_is_the_default_and_unchanged():
    from tubekit.model.vehicles import PlantSettings
    sc = _scenario(duration=1.0)
    a = run_closed_loop(sc, tightening=_tightening(sc, 1.0), solver_factory=Pursuit, progress=False)
    b = run_closed_loop(sc.with_changes(plant=PlantSettings("kinematic")), tightening=_tightening(sc, 1.0),
                        solver_factory=Pursuit, progress=False)
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.omega, b.omega)
    assert a.body is None and tuple(a.columns()) == CSV_COLUMNS


# ---- what runs is the scenario's ------------------------------------------------------

def test_signature_has_no_scenario_overrides():
    import inspect
    params = inspect.signature(run_closed_loop).parameters
    assert list(params) == ["scenario", "tightening", "tube", "progress", "label", "solver_factory", "disturbance",
                            "plant_substeps", "remember_obstacles", "observer"]
    assert params["tube"].kind is inspect.Parameter.KEYWORD_ONLY
    sc = _scenario(duration=0.5)
    for override in ({"law": "paper"}, {"sigma": 1.0}, {"mode": "converged"}, {"plant": "dynamic"}):
        with pytest.raises(TypeError, match="unexpected keyword"):
            run_closed_loop(sc, _tightening(sc, 1.0), solver_factory=Pursuit, progress=False, **override)


def test_law_from_the_scenario_and_sigma_from_the_tightening():
    sc = _scenario(duration=1.0)
    paper = sc.with_changes(**{"controller.law": "paper"})
    a = run_closed_loop(paper, _tightening(sc, 2.5), solver_factory=Pursuit, progress=False)
    b = run_closed_loop(sc, _tightening(sc, 2.5), solver_factory=Pursuit, progress=False)
    c = run_closed_loop(sc, _tightening(sc, 0.5), solver_factory=Pursuit, progress=False)
    assert (a.law, a.sigma, b.law, c.sigma) == ("paper", 2.5, "corrected", 0.5)
    assert np.max(np.abs(a.kappa[:-1] - b.kappa[:-1])) > 0.0   # another law, another feedback
    assert np.max(np.abs(b.kappa[:-1] - c.kappa[:-1])) > 0.0   # another gain, another feedback


def test_default_solver_is_the_scenarios_backend(monkeypatch):
    from tubekit.fhocp import registry
    monkeypatch.setattr(registry, "_BACKENDS", dict(registry._BACKENDS))
    built = []

    def pursuit_backend(s, tg):
        built.append(Pursuit(s, tg))
        return built[-1]

    registry.register_backend("pursuit", pursuit_backend)
    sc = _scenario(duration=1.0).with_changes(**{"controller.fhocp_backend": "pursuit"})
    res = run_closed_loop(sc, _tightening(sc, 1.0), progress=False)
    assert len(built) == 1 and built[0].k == sc.steps - 1 and res.fallback_steps == 0
    with pytest.raises(ConfigError, match="controller.fhocp_backend"):
        run_closed_loop(sc.with_changes(**{"controller.fhocp_backend": "nope"}), _tightening(sc, 1.0),
                        progress=False)


@pytest.mark.parametrize("kwargs, match", [
    ({"duration": 0.04}, r"duration: expected at least one FHOCP period \(0\.1 s\)"),
    ({"plant_substeps": 0}, "plant_substeps"),
    ({"plant_substeps": True}, "plant_substeps"),
])
def test_bad_run_inputs(kwargs, match):
    sc = _scenario(duration=kwargs.pop("duration", 1.0))
    with pytest.raises(ConfigError, match=match):
        run_closed_loop(sc, _tightening(sc, 1.0), solver_factory=Pursuit, progress=False, **kwargs)
    with pytest.raises(ConfigError, match="scenario"):
        run_closed_loop(sc.to_dict(), _tightening(sc, 1.0), solver_factory=Pursuit, progress=False)


# ---- phases: accept, replay, backup, resume (issue 21) --------------------------------------------------

BACKUP = BackupPlan(StationKeeping(0.2, 0.5, 0.05, 0.3, 0.05), SafeSet(0.8, 0.45, 0.1), handover=(0.35, 0.1))


def _safe_only(sc, backup=BACKUP):
    """Arc check on positions only (tracking not certified), zero margins, with or without a backup."""
    n = sc.controller.horizon_steps
    return dataclasses.replace(Tightening.untightened(sc), margins=np.zeros((n, 4)), backup=backup,
                               tiers=Tiers(True, False))


def test_the_backup_takes_over_when_the_replay_is_exhausted_and_tracking_resumes():
    sc = _scenario(duration=4.0).with_changes(**{"controller.candidate": False})
    n = sc.controller.horizon_steps
    fail = range(5, 25)   # periods 5..24 fail; the plan of period 4 replays for n - 1 periods, then the backup

    def factory(s, t):
        return Pursuit(s, t, nan_at=fail)
    res = run_closed_loop(sc, tightening=_safe_only(sc), solver_factory=factory, progress=False)
    m = res.ticks_per_step
    per_period = res.backup_active[:-1:m]
    want = np.zeros(sc.steps, dtype=bool)
    want[5 + n - 1:25] = True
    np.testing.assert_array_equal(per_period, want)
    assert np.all(res.backup_active[(5 + n - 1) * m:25 * m]) and not np.any(res.backup_active[25 * m:])
    # the backup law, never the zero input, about the nominal end of the plan accepted at period 4
    on = res.backup_active[:-1]
    assert np.all(np.linalg.norm(res.inputs[:-1][on], axis=1) > 0.0) and not np.any(res.saturated)
    state4 = res.states[4 * m]
    plan4 = Pursuit(sc, None).solve(0.4, state4, ()).inputs  # the stand-in's plan depends only on t, state
    end = state4
    for v in plan4:
        end = nominal_arc(end, v, np.array([sc.controller.dt]))[-1]
    np.testing.assert_allclose(res.backup_anchor[:-1][on], np.tile(end[:3], (int(on.sum()), 1)), atol=1e-12)
    assert np.all(np.isnan(res.backup_anchor[:-1][~on]))
    metrics = res.metrics
    assert metrics["backup_engagements"] == 1
    assert metrics["backup_s"] == pytest.approx((25 - (5 + n - 1)) * sc.controller.dt)


def test_the_backup_is_anchored_where_the_terminal_condition_placed_it_within_its_reach():
    """With a backup proved for an anchor up to 0.2 m from the plan's end, the loop anchors it where the accepted
    plan's terminal condition held: at the plan's depth, within 0.2 m of its end, and not at the end itself. The
    sensing range 1.2 m leaves the safe set about the plan's end (0.24 m ahead: hypot(0.24 + 0.8, ...) > 1.0)
    outside the sensed region, and moving the anchor back toward the vehicle brings it in."""
    sc = _scenario(duration=4.0).with_changes(sensing_range=1.2, **{"controller.candidate": False})
    n = sc.controller.horizon_steps
    movable = dataclasses.replace(BACKUP, anchor_reach=0.2)
    res = run_closed_loop(sc, tightening=_safe_only(sc, movable), progress=False,
                          solver_factory=lambda s, t: Pursuit(s, t, nan_at=range(5, 25)))
    m = res.ticks_per_step
    state4 = res.states[4 * m]
    end = state4
    for v in Pursuit(sc, None).solve(0.4, state4, ()).inputs:
        end = nominal_arc(end, v, np.array([sc.controller.dt]))[-1]
    on = res.backup_active[:-1]
    assert on.sum() == (25 - (5 + n - 1)) * m
    anchors = np.unique(res.backup_anchor[:-1][on], axis=0)
    assert anchors.shape == (1, 3)
    moved = anchors[0] - end[:3]
    assert moved[2] == 0.0 and 0.1 < math.hypot(moved[0], moved[1]) <= 0.2 * (1 + 1e-12)
    assert np.dot(moved[:2], state4[:2] - end[:2]) > 0.0                       # toward the vehicle at acceptance


def test_the_backup_law_is_the_station_keeping_input_at_every_tick():
    sc = _scenario(duration=2.0).with_changes(**{"controller.candidate": False})
    res = run_closed_loop(sc, tightening=_safe_only(sc), progress=False,
                          solver_factory=lambda s, t: Pursuit(s, t, nan_at=range(1, 100)))
    on = np.flatnonzero(res.backup_active[:-1])
    assert on.size > 0
    for i in on[::7]:
        want = station_keeping_input(BACKUP.law, tuple(res.states[i]), tuple(res.backup_anchor[i]))
        np.testing.assert_allclose(res.inputs[i], want, atol=1e-15)
        assert np.all(res.kappa[i] == 0.0)


def test_without_a_backup_the_exhausted_replay_keeps_the_zero_input_and_says_so(caplog):
    sc = _scenario(duration=2.0).with_changes(**{"controller.candidate": False})
    with caplog.at_level("WARNING", logger="tubekit.loop.closed_loop"):
        res = run_closed_loop(sc, tightening=_safe_only(sc, backup=None), progress=False,
                              solver_factory=lambda s, t: Pursuit(s, t, nan_at=range(1, 100)))
    n = sc.controller.horizon_steps
    m = res.ticks_per_step
    assert not np.any(res.backup_active)
    np.testing.assert_array_equal(res.v_hat[(1 + n - 1) * m:-1], 0.0)
    assert sum("no backup" in r.getMessage() for r in caplog.records) == 1   # once per engagement


# ---- the rate limit (issue 22 design (1)) --------------------------------------------------------------------

class _FailingFhocp:
    """The real FHOCP, raising SolverError in the periods ``fail`` (replay, then the backup, then resume)."""

    def __init__(self, scenario, tightening, fail=range(5, 20)):
        from tubekit.fhocp import FHOCP
        self.inner, self.fail, self.k = FHOCP(scenario, tightening), set(fail), 0

    def solve(self, t, state, obstacles, v_last=None):
        self.k += 1
        if self.k - 1 in self.fail:
            raise SolverError("injected")
        return self.inner.solve(t, state, obstacles, v_last=v_last)


def test_with_a_rate_limit_no_command_jumps_more_than_j_between_periods():
    """Measured on the log alone: every change of v̂ into a tracking or replayed tick (plans, replay, and the
    resume after the backup) is at most J = rate dt; the periods 5..19 fail, so all three phases occur."""
    sc = _scenario(duration=4.0).with_changes(**{"limits.rate": [0.5, 0.5, 1.0]})
    res = run_closed_loop(sc, tightening=_safe_only(sc), solver_factory=_FailingFhocp, progress=False)
    jump = np.array([0.5, 0.5, 1.0]) * sc.controller.dt
    v, backup = res.v_hat[:-1], res.backup_active[:-1]
    steps = np.abs(np.diff(v, axis=0))[~backup[1:]]            # into a tick that follows a plan
    assert res.replaced.any() and backup.any() and not backup[-1]   # replay, backup, resumed tracking
    assert np.all(steps <= jump + 1e-9), steps.max(axis=0)
    first = np.flatnonzero(backup[:-1] & ~backup[1:])[0]          # the resume: from the backup's last command
    assert np.all(np.abs(v[first + 1] - v[first]) <= jump + 1e-9)


def test_with_a_rate_limit_the_run_starts_at_rest_and_a_ramped_backup_starts_from_the_last_command():
    """The first plan starts within J of 0 (the vehicle starts at rest); at the hand-over the ramped backup's first
    command is the last applied one (the blend), and every tick's command stays in V."""
    sc = _scenario(duration=4.0).with_changes(**{"limits.rate": [0.5, 0.5, 1.0], "controller.candidate": False})
    ramped = dataclasses.replace(BACKUP, law=dataclasses.replace(BACKUP.law, surge_fade=0.2, yaw_fade=0.2, ramp=1.0))
    res = run_closed_loop(sc, tightening=_safe_only(sc, backup=ramped), solver_factory=_FailingFhocp, progress=False)
    jump = np.array([0.5, 0.5, 1.0]) * sc.controller.dt
    assert np.all(np.abs(res.v_hat[0]) <= jump + 1e-9)
    backup = res.backup_active[:-1]
    start = np.flatnonzero(backup)[0]
    np.testing.assert_array_equal(res.inputs[start], res.inputs[start - 1])
    want = station_keeping_input(ramped.law, tuple(res.states[start + 3]), tuple(res.backup_anchor[start + 3]),
                                 3 * sc.controller.dt / res.ticks_per_step, tuple(res.inputs[start - 1]))
    np.testing.assert_allclose(res.inputs[start + 3], want, atol=1e-15)
    assert not np.any(res.saturated)


# ---- issue 30: every path safe (attacks 2 and 3 on the certified paper_currents) -------------------------------

@pytest.fixture(scope="module")
def paper_currents():
    """The certified paper_currents design (both tiers, σ = 0) and a 3 s run of it (a shorter run is covered)."""
    import verify
    from tubekit.scenario import load_scenario

    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
    cert = verify.certify(sc)
    assert cert.certified and cert.tightening.sigma == 0.0
    return sc.with_changes(duration=3.0), cert.tightening


class _Tampered:
    """The scenario's own FHOCP whose result is edited by ``edit(result, tightening)`` before the loop reads it."""

    def __init__(self, edit):
        self.edit = edit

    def __call__(self, sc, tight):
        from tubekit.fhocp.registry import make_solver
        solver = make_solver(sc, tight)
        edit = self.edit

        class _Solver:
            def solve(self, t, state, obstacles, v_last=None):
                return edit(solver.solve(t, state, obstacles, v_last=v_last), tight)
        return _Solver()


def _extra_rows(result, tight):
    """Attack 2: the N checked rows, then 60 more driving straight at full speed (never checked)."""
    extra = np.tile([0.4, 0.0, 0.0], (60, 1))
    return dataclasses.replace(result, inputs=np.vstack([result.inputs, extra]))


def test_a_plan_with_more_rows_than_the_horizon_is_refused(paper_currents):
    """Issue 30, attack 2: the loop used to store and replay every row; now a result with more than N rows is a
    failed solve: nothing of it runs (no plan is accepted, the certified backup holds the vehicle)."""
    sc, tight = paper_currents
    res = run_closed_loop(sc, tight, solver_factory=_Tampered(_extra_rows), progress=False)
    assert np.all(res.replaced[:-1]) and not np.any(res.saturated[:-1])
    assert res.metrics["min_clearance"] > 0.0


def _other_first_input(result, tight):
    """Attack 2b: ``first_input`` that is not the plan's first row (the row the check verified)."""
    class _Lying(type(result)):
        @property
        def first_input(self):
            return np.array([0.4, 0.0, 0.5])
    return _Lying(**{f.name: getattr(result, f.name) for f in dataclasses.fields(result)})


def test_a_first_input_other_than_the_first_row_is_refused(paper_currents):
    sc, tight = paper_currents
    res = run_closed_loop(sc, tight, solver_factory=_Tampered(_other_first_input), progress=False)
    assert np.all(res.replaced[:-1])
    assert not np.any(np.all(np.isclose(res.v_hat[:-1], [0.4, 0.0, 0.5]), axis=1))


def _above_v_bar(result, tight):
    """Attack 3: the first row pushed 5e-10 m/s above V̄ = V (σ = 0), inside the check's old tolerance of 1e-9."""
    inputs = np.array(result.inputs, dtype=float)
    inputs[0, 0] = float(tight.v_max[0]) + 5e-10
    return dataclasses.replace(result, inputs=inputs)


def test_no_tolerance_outside_the_proof_a_plan_above_v_bar_never_clips(paper_currents):
    """Issue 30, attack 3: a plan 5e-10 above V̄ was accepted and then clipped at every tick (220 clipped ticks in
    100 s on paper_currents, breaking "inputs never clipped"); the loop now projects the plan onto V̄ and checks it
    exactly, so the command applied is in V and nothing saturates."""
    sc, tight = paper_currents
    res = run_closed_loop(sc, tight, solver_factory=_Tampered(_above_v_bar), progress=False)
    assert not np.any(res.saturated[:-1])
    assert np.max(np.abs(res.inputs[:-1, 0])) <= float(tight.v_max[0])
    assert np.all(res.plan_age == 0) and not np.any(res.backup_active)   # a plan accepted at every period


def test_a_rejected_plan_is_replaced_by_the_shifted_candidate_and_tracking_is_kept(paper_currents):
    """Issue 31: the solver answers once, then never again (every later result is refused); the loop no longer
    replays that plan to its end and hands over to the backup: the shifted candidate passes the exact check
    every period, so a plan is followed the whole time and every promise of both tiers is kept."""
    import tubekit
    sc, tight = paper_currents

    class OnceThenNothing:
        def __init__(self, s, t):
            from tubekit.fhocp.registry import make_solver
            self.solver, self.k = make_solver(s, t), -1

        def solve(self, t, state, obstacles, v_last=None):
            self.k += 1
            if self.k > 0:
                raise SolverError("refused on purpose")
            return self.solver.solve(t, state, obstacles, v_last=v_last)

    res = run_closed_loop(sc, tight, solver_factory=OnceThenNothing, progress=False)
    assert np.all(res.candidate[1:]) and not res.candidate[0]
    assert not np.any(res.backup_active) and np.all(res.plan_age == 0)
    assert all(p.ok for p in tubekit.check_promises(res))
    off = run_closed_loop(sc.with_changes(**{"controller.candidate": False}), tight, solver_factory=OnceThenNothing,
                          progress=False)
    assert np.any(off.backup_active) and not np.any(off.candidate)   # without it: replay, then the backup


def test_a_loiter_backup_keeps_its_surge_and_the_vehicle_clear_in_the_loop():
    """Section VI with the loiter backup (``controller.backup = "loiter"``) and a 6 m sensing range, 30 s: the
    loop falls back to the loiter, whose surge command is u_l at every tick it runs, never clipped, and every
    safety promise holds."""
    import verify
    from tubekit import simulate
    from tubekit.loop.promises import check_promises
    from tubekit.model.loiter import Loiter
    sc = paper_scenario().with_changes(duration=30.0, sensing_range=6.0, **{"controller.backup": "loiter"})
    cert = verify.certify(sc)
    assert cert.tiers.safe and isinstance(cert.backup.law, Loiter)
    run = simulate(sc, cert, progress=False)
    on = run.backup_active[:-1]
    assert on.sum() > 0 and np.all(run.inputs[:-1][on][:, 0] == cert.backup.law.surge)
    assert run.saturated_ticks == 0 and run.metrics["min_clearance"] > 0.0
    safety = {p.name: p.ok for p in check_promises(run)}
    assert safety["clearance"] and safety["inputs"] and safety["workspace"]


@pytest.mark.slow
def test_a_hold_backup_keeps_its_disc_and_hands_back_to_a_plan_in_the_loop():
    """examples/bluerov2_pier.toml with the FHOCP failing for 15 s (periods 100..249, the candidate off): the hold law
    takes over from the moving vehicle without a jump (its sway command starts at 0), commands sway to hold the
    vehicle inside its certified disc and depth band, and a plan takes over again only once its sway command is
    within the law's release; every promise of the certificate's tier holds (the recursive-feasibility premise
    fails by construction)."""
    from pathlib import Path

    import verify
    from tubekit.loop.promises import check_promises
    from tubekit.model.hold import Hold
    from tubekit.scenario import load_scenario

    from .failing_solver import failing_between

    _Failing = failing_between(100, 250)

    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "bluerov2_pier.toml")
    cert = verify.certify(sc)
    law, disc = cert.backup.law, cert.backup.safe_set
    assert cert.tiers.safe and isinstance(law, Hold)
    sc = sc.with_changes(duration=40.0, **{"controller.candidate": False})
    res = run_closed_loop(sc, tightening=cert.tightening, solver_factory=_Failing, progress=False)
    on = np.flatnonzero(res.backup_active[:-1])
    assert res.metrics["backup_engagements"] == 1 and on.size * 0.01 > 10.0 and not res.backup_active[-2]
    first, last = on[0], on[-1]
    np.testing.assert_array_equal(res.inputs[first], res.inputs[first - 1])      # the blend: no jump
    assert res.sway_command[first] == 0.0 and np.linalg.norm(res.inputs[first - 1]) > 0.05
    anchor = res.backup_anchor[on]
    assert np.hypot(*(res.states[on, :2] - anchor[:, :2]).T).max() <= disc.level
    assert np.abs(res.states[on, 2] - anchor[:, 2]).max() <= disc.depth
    assert 0.0 < np.abs(res.sway_command[on]).max() <= law.speed
    assert abs(res.sway_command[last]) <= law.release and np.all(res.sway_command[last + 1:] == 0.0)
    broken = [p.name for p in check_promises(res) if p.given and not p.ok and p.name != "recursive_feasibility"]
    assert broken == []
