"""The converged SCP reaches IPOPT's optimum of the same discretised NLP (within 1 %)."""

from __future__ import annotations

import builtins
import dataclasses

import numpy as np
import pytest

from tubekit import NotAvailableError
from tubekit.fhocp import FHOCP, ScpOptions

from tubekit.loop.plan_check import plan_arcs
from tubekit.loop.terminal import terminal_condition

from .fhocp_cases import SC, backup_plan, tightening
from .fhocp_cases import STATES as CASES
from .fhocp_cases import RUN_STATES as STATES


@pytest.fixture(scope="module")
def solvers():
    pytest.importorskip("casadi")
    from tubekit.fhocp.ipopt import IpoptFHOCP
    return FHOCP(SC, tightening(), mode="converged"), IpoptFHOCP(SC, tightening())


def test_states_cover_obstacles():
    from tubekit.fhocp.nlp import select_obstacles
    near = sum(len(select_obstacles(np.array(s), SC.obstacles, SC.sensing_range, 4)[0]) > 0 for _, s in STATES)
    assert len(STATES) >= 10 and near >= 10


@pytest.mark.parametrize("t, state", STATES)
def test_converged_scp_matches_ipopt(solvers, t, state):
    scp, ipopt = solvers
    s = np.array(state)
    scp.reset()
    ipopt.reset()
    N = SC.controller.horizon_steps
    a = scp.solve(t, s, SC.obstacles)                                 # cold start: zero inputs
    b = ipopt.solve(t, s, SC.obstacles, initial_inputs=np.zeros((N, 3)))  # the same initial guess
    assert b.status == "optimal", b.message
    assert not a.fallback
    gap = (a.merit - b.merit) / abs(b.merit)
    assert gap <= 0.01, f"SCP merit {a.merit:.6g} vs IPOPT {b.merit:.6g}"
    # the same local optimum, not just the same value: the planned paths agree to 1 cm and
    # 0.05 rad (the inputs are not compared entry by entry: where an exact penalty is active
    # the merit is flat in the yaw rate and both solvers stop at their tolerances)
    assert np.max(np.abs(a.states[:, :3] - b.states[:, :3])) < 0.01
    assert np.max(np.abs(a.states[:, 3] - b.states[:, 3])) < 0.05
    # both plans violate the nonlinear constraints by the same amount (zero when feasible)
    assert a.max_violation == pytest.approx(b.max_violation, abs=1e-4)


def test_ipopt_warm_start_and_terminal_modes():
    pytest.importorskip("casadi")
    from tubekit.fhocp.ipopt import IpoptFHOCP
    for terminal in ("hard", "off"):
        peer = IpoptFHOCP(SC, tightening(), terminal=terminal)
        scp = FHOCP(SC, tightening(), mode="converged", options=ScpOptions(terminal=terminal))
        t, s = STATES[1]
        a = scp.solve(t, np.array(s), SC.obstacles)
        b = peer.solve(t, np.array(s), SC.obstacles)
        assert b.status == "optimal"
        assert a.merit == pytest.approx(b.merit, rel=1e-4)
        nxt = peer.solve(t + SC.controller.dt, b.states[1], SC.obstacles)   # warm start
        assert nxt.status == "optimal" and nxt.iterations <= b.iterations + 5


def test_missing_casadi_raises_not_available(monkeypatch):
    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name == "casadi" or name.startswith("casadi."):
            raise ImportError("No module named 'casadi'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)
    from tubekit.fhocp.ipopt import IpoptFHOCP
    with pytest.raises(NotAvailableError, match=r"pip install -e \"\.\[bench\]\""):
        IpoptFHOCP(SC, tightening())


def test_sqpmethod_peer_solves_the_same_nlp():
    """The sqpmethod + qrqp peer (benchmark v2) reaches IPOPT's merit on a state it solves."""
    pytest.importorskip("casadi")
    from tubekit.exceptions import ConfigError
    from tubekit.fhocp.ipopt import IpoptFHOCP
    with pytest.raises(ConfigError, match="nlp_solver"):
        IpoptFHOCP(SC, tightening(), nlp_solver="snopt")
    t, state = STATES[0]
    N = SC.controller.horizon_steps
    # the paper's NLP (no rate penalty: qrqp fails on its node-to-node coupling, a fallback below)
    sqp = IpoptFHOCP(SC, tightening(), nlp_solver="sqpmethod", warm_start_duals=True, rate_penalty=0.0)
    a = sqp.solve(t, np.array(state), SC.obstacles, initial_inputs=np.zeros((N, 3)))
    b = IpoptFHOCP(SC, tightening(), rate_penalty=0.0).solve(t, np.array(state), SC.obstacles,
                                                             initial_inputs=np.zeros((N, 3)))
    assert not a.fallback and a.status in ("optimal", "optimal_inaccurate")
    assert abs(a.merit - b.merit) <= 1e-2 * max(1.0, abs(b.merit))
    assert not sqp.solve(t + SC.controller.dt, np.array(state), SC.obstacles).fallback  # dual warm start
    coupled = IpoptFHOCP(SC, tightening(), nlp_solver="sqpmethod", rate_penalty=1.0)
    failed = coupled.solve(t, np.array(state), SC.obstacles, initial_inputs=np.zeros((N, 3)))
    assert np.all(np.isfinite(failed.inputs)) and (failed.fallback or failed.status == "optimal")  # no exception


def test_ipopt_carries_the_backup_terminal_rows_where_they_bind():
    """The same sensed-region case as the SCP's: with a 1.2 m sensing range the plan end must stay within
    0.195 m of the start; IPOPT meets the rows that the free plan breaks."""
    pytest.importorskip("casadi")
    from tubekit.fhocp.ipopt import IpoptFHOCP
    sc = SC.with_changes(sensing_range=1.2)
    t, s = CASES[0]
    s = np.asarray(s, dtype=float)
    res = IpoptFHOCP(sc, dataclasses.replace(tightening(sc), backup=backup_plan())).solve(t, s, ())
    end = plan_arcs(s, res.inputs, sc.controller.dt, 1)[-1, -1]
    check = terminal_condition(end[:3], backup_plan(), sc.vehicle_radius, (), sc.workspace, s[:3], sc.sensing_range)
    assert check.ok and check.slack < 5e-3 and res.violations["backup_terminal"] <= 1e-6   # it binds


def test_ipopt_meets_the_rate_rows_and_agrees_with_the_scp():
    """The same rate rows (steps, first node, terminal rest with a backup) and rate penalty in both backends."""
    pytest.importorskip("casadi")
    from tubekit.fhocp.ipopt import IpoptFHOCP
    sc = SC.with_changes(**{"limits.rate": [1.0, 1.0, 2.0]})
    tight = dataclasses.replace(tightening(sc), backup=backup_plan())
    t, s = CASES[2]
    v_last = np.array([0.35, -0.2, 0.4])
    a = FHOCP(sc, tight, mode="converged").solve(t, np.array(s), sc.obstacles, v_last=v_last)
    b = IpoptFHOCP(sc, tight, max_obstacles=1).solve(t, np.array(s), sc.obstacles, v_last=v_last)
    jump = np.array(sc.limits.rate) * sc.controller.dt
    for res in (a, b):
        steps = np.abs(np.diff(np.vstack([v_last, res.inputs]), axis=0))
        assert np.all(steps <= jump) and np.all(np.abs(res.inputs[-1]) <= jump)
    assert b.status == "optimal" and abs(a.merit - b.merit) <= 1e-2 * abs(b.merit)


def test_ipopt_keeps_the_surge_floor_and_the_loiters_terminal_command():
    """The same lower corner and terminal command as the SCP's: facing away from the target the free plan backs
    up, the floored one never slows below 0.15 m/s; with the loiter (u_l = 0.25 m/s) the plan ends within J of it."""
    pytest.importorskip("casadi")
    from tubekit.fhocp.ipopt import IpoptFHOCP
    from tubekit.model.loiter import Loiter
    t, s = CASES[1]
    away = np.array(s)
    away[3] += np.pi
    tight = tightening()
    floor = np.array([0.15, -tight.v_max[1], -tight.v_max[2]])
    free = IpoptFHOCP(SC, tight, max_obstacles=1).solve(t, away, SC.obstacles)
    held = IpoptFHOCP(SC, dataclasses.replace(tight, v_min=floor), max_obstacles=1).solve(t, away, SC.obstacles)
    assert free.inputs[:, 0].min() < 0.05 and held.status == "optimal"
    assert np.all(held.inputs[:, 0] >= 0.15 - 1e-7) and held.violations["input"] == 0.0
    sc = SC.with_changes(**{"limits.rate": [1.0, 1.0, 2.0]})
    loiter = dataclasses.replace(backup_plan(), law=Loiter(0.25, 0.3, 0.5, 0.05, 0.3))
    t, s = CASES[2]
    res = IpoptFHOCP(sc, dataclasses.replace(tightening(sc), backup=loiter), max_obstacles=1).solve(
        t, np.array(s), sc.obstacles, v_last=np.zeros(3))
    jump = np.array(sc.limits.rate) * sc.controller.dt
    assert res.status == "optimal" and np.all(np.abs(res.inputs[-1] - [0.25, 0.0, 0.0]) <= jump)
