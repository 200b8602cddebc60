"""Benchmark the FHOCP solvers along a closed loop of the paper's Section VI scenario.

Usage::

    python benchmarks/fhocp.py --json fhocp.json            # full run (100 s, 1000 states)
    python benchmarks/fhocp.py --quick --json quick.json    # 20 s of closed loop (< 30 s wall)

1. A closed loop is simulated: the real-time SCP controller drives a plant that
   integrates the nominal kinematics plus the paper's current
   omega = 0.1 [sin(2 pi t/15), cos(2 pi t/15), sin(2 pi t/15)] m/s (RK4, 10
   substeps per dt, zero-order-hold input; no ancillary feedback, no sway).
   Obstacles join when their surface is within the sensing range.
2. The recorded states are replayed, in the same process, by three independent
   solvers, one pass each (as each would run as the controller), each
   warm-started from its own previous solution shifted by one step: the SCP in
   real-time mode (one convex solve per step), the SCP to convergence, and
   CasADi + IPOPT on the same NLP. The first state (a cold start) is not timed.

Reported (milliseconds are medians over the states):

* ``rt_step_ms_median``: the whole real-time ``FHOCP.solve`` call;
* ``converged_ms_median``: the whole converged ``FHOCP.solve`` call;
* ``ipopt_ms_median``: the IPOPT solver call (CasADi function call);
* ``clarabel_ms_median``: the bare Clarabel ``solve()`` inside the real-time step (the floor);
* ``ratio_rt_vs_ipopt``, ``ratio_converged_vs_ipopt``: ratios of the medians;
* ``cost_gap_max``: max over states of (merit_SCP - merit_IPOPT) / |merit_IPOPT|,
  merit = the NLP objective (cost + exact penalties); negative = SCP better;
* ``n_states``.

The tightening is a hand-made stand-in for the verifier's: V-bar = V (the
target moves at 0.377 m/s, barely below u_max = 0.4 m/s), e_d_min = epsilon + 0.05 m,
obstacle margin 0.05 m, region bounds unchanged.
"""

from __future__ import annotations

import argparse
import cProfile
import importlib.metadata
import importlib.util
import io
import json
import math
import os
import platform
import pstats
import sys
import time
from pathlib import Path

import numpy as np

from tubekit import Tightening, paper_scenario
from tubekit.fhocp import FHOCP
from tubekit.model import kinematics
from tubekit.plant import Plant
from tubekit.scenario import Scenario

REQUIRED_KEYS = ("rt_step_ms_median", "converged_ms_median", "ipopt_ms_median", "clarabel_ms_median",
                 "ratio_rt_vs_ipopt", "ratio_converged_vs_ipopt", "cost_gap_max", "n_states")


def benchmark_tightening(scenario: Scenario) -> Tightening:
    """The stand-in tightening used by the benchmark (see module docstring)."""
    reg = scenario.region
    return Tightening(v_max=scenario.limits.vector.copy(), e_d_min=scenario.epsilon + 0.05,
                      e_o_max=reg.e_o_max, e_z_max=reg.e_z_max, e_d_max=reg.e_d_max,
                      obstacle_margin=0.05, rho_tilde=0.05, sigma=0.0)


def plant_step(scenario: Scenario, t: float, s: np.ndarray, v: np.ndarray, dt: float,
               substeps: int = 10) -> np.ndarray:
    """Integrate nominal kinematics + current over ``dt`` with RK4 (input held)."""
    h = dt / substeps
    current = Plant.of(scenario).current

    def f(tt: float, ss: np.ndarray) -> np.ndarray:
        return kinematics(ss, v, current(tt))

    for i in range(substeps):
        ti = t + i * h
        k1 = f(ti, s)
        k2 = f(ti + h / 2, s + h / 2 * k1)
        k3 = f(ti + h / 2, s + h / 2 * k2)
        k4 = f(ti + h, s + h * k3)
        s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return s


def detected(scenario: Scenario, s: np.ndarray) -> list:
    """Obstacles whose surface is within the sensing range of position s[:3]."""
    return [o for o in scenario.obstacles
            if np.linalg.norm(s[:3] - np.asarray(o.center)) - o.radius <= scenario.sensing_range]


def closed_loop(scenario: Scenario, tightening: Tightening, duration: float) -> list[tuple[float, np.ndarray, list]]:
    """Simulate the real-time SCP controller; return [(t, state, detected obstacles)]."""
    ctrl = FHOCP(scenario, tightening, mode="realtime")
    dt = scenario.controller.dt
    s = np.asarray(scenario.initial_state, dtype=float)
    out = []
    for k in range(int(round(duration / dt))):
        t = k * dt
        obs = detected(scenario, s)
        out.append((t, s.copy(), obs))
        res = ctrl.solve(t, s, obs)
        s = plant_step(scenario, t, s, res.first_input, dt)
    return out


def _versions() -> dict:
    out = {}
    for name in ("numpy", "cvxpy", "clarabel", "casadi"):
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = None
    return out


def _replay(solver, run_states: list, rec: dict, key: str, *, timing: str, fail: str) -> None:
    """Warm-start ``solver`` on the first state, then time it along the rest, into ``rec``."""
    t, s, obs = run_states[0]
    solver.solve(t, s, obs)
    for t, s, obs in run_states[1:]:
        r = solver.solve(t, s, obs)
        rec[key].append(getattr(r, timing))
        rec[f"{key}_iters"].append(r.iterations)
        rec[f"{key}_merit"].append(r.merit)
        rec[f"{key}_viol"].append(r.max_violation)
        rec[fail].append(r.fallback)


def _median_ms(x: list[float]) -> float:
    return float(np.median(x) * 1e3)


def run(duration: float, with_ipopt: bool = True, profile: bool = False, tolerance: float | None = None) -> dict:
    """Run the benchmark and return the JSON-ready dict."""
    sc = paper_scenario()
    tg = benchmark_tightening(sc)
    t0 = time.perf_counter()
    run_states = closed_loop(sc, tg, duration)
    sim_s = time.perf_counter() - t0
    rt = FHOCP(sc, tg, mode="realtime")
    cv = FHOCP(sc, tg, mode="converged") if tolerance is None else \
        FHOCP(sc, tg, mode="converged", tolerance=tolerance)
    ip = None
    if with_ipopt:
        from tubekit.fhocp import IpoptFHOCP
        ip = IpoptFHOCP(sc, tg, warm_start_duals=True)
    rec: dict[str, list] = {k: [] for k in ("rt", "rt_clarabel", "cv", "cv_iters", "cv_merit", "ip",
                                           "ip_iters", "ip_merit", "rt_viol", "cv_viol", "ip_viol",
                                           "rt_fallback", "cv_fallback", "ip_fail")}
    prof = cProfile.Profile() if profile else None
    # one pass per method (as each would run as the controller); the first state is a cold
    # start for every method and is not timed
    t, s, obs = run_states[0]
    rt.solve(t, s, obs)
    for t, s, obs in run_states[1:]:
        if prof:
            prof.enable()
        r = rt.solve(t, s, obs)
        if prof:
            prof.disable()
        rec["rt"].append(r.solve_time_s)
        rec["rt_clarabel"].append(r.solver_time_s)
        rec["rt_viol"].append(r.max_violation)
        rec["rt_fallback"].append(r.fallback)
    _replay(cv, run_states, rec, "cv", timing="solve_time_s", fail="cv_fallback")
    if ip is not None:
        # IPOPT is timed by its bare nlpsol call (conservative for SCP, timed by the whole step)
        _replay(ip, run_states, rec, "ip", timing="solver_time_s", fail="ip_fail")
        rec["gap"] = list((np.array(rec["cv_merit"]) - np.array(rec["ip_merit"]))
                          / np.maximum(np.abs(rec["ip_merit"]), 1e-12))
    else:
        rec["gap"] = []
    n = len(rec["rt"])
    out: dict = {
        "rt_step_ms_median": _median_ms(rec["rt"]),
        "converged_ms_median": _median_ms(rec["cv"]),
        "ipopt_ms_median": _median_ms(rec["ip"]) if rec["ip"] else math.nan,
        "clarabel_ms_median": _median_ms(rec["rt_clarabel"]),
    }
    out["ratio_rt_vs_ipopt"] = out["rt_step_ms_median"] / out["ipopt_ms_median"]
    out["ratio_converged_vs_ipopt"] = out["converged_ms_median"] / out["ipopt_ms_median"]
    out["cost_gap_max"] = float(np.max(rec["gap"])) if rec["gap"] else math.nan
    out["n_states"] = n
    out["details"] = {
        "duration_s": duration,
        "closed_loop_sim_s": sim_s,
        "rt_step_ms_p90": float(np.percentile(rec["rt"], 90) * 1e3),
        "converged_ms_p90": float(np.percentile(rec["cv"], 90) * 1e3),
        "ipopt_ms_p90": float(np.percentile(rec["ip"], 90) * 1e3) if rec["ip"] else math.nan,
        "converged_iterations_mean": float(np.mean(rec["cv_iters"])),
        "converged_iterations_max": int(np.max(rec["cv_iters"])),
        "ipopt_iterations_mean": float(np.mean(rec["ip_iters"])) if rec["ip_iters"] else math.nan,
        "cost_gap_min": float(np.min(rec["gap"])) if rec["gap"] else math.nan,
        "cost_gap_abs_median": float(np.median(np.abs(rec["gap"]))) if rec["gap"] else math.nan,
        "rt_max_violation_median": float(np.median(rec["rt_viol"])),
        "converged_max_violation_median": float(np.median(rec["cv_viol"])),
        "rt_fallbacks": int(np.sum(rec["rt_fallback"])),
        "converged_fallbacks": int(np.sum(rec["cv_fallback"])),
        "ipopt_failures": int(np.sum(rec["ip_fail"])) if rec["ip_fail"] else 0,
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                    "processor": platform.processor() or platform.machine(),
                    "load_average_1min_at_end": os.getloadavg()[0], "versions": _versions()},
    }
    if prof:
        buf = io.StringIO()
        pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(15)
        out["details"]["rt_profile"] = buf.getvalue()
    return out


def table(res: dict) -> str:
    """A Markdown table of the headline numbers."""
    rows = [("real-time SCP step (whole controller step)", f"{res['rt_step_ms_median']:.3f} ms"),
            ("converged SCP", f"{res['converged_ms_median']:.3f} ms"),
            ("IPOPT, same NLP, warm-started", f"{res['ipopt_ms_median']:.3f} ms"),
            ("bare Clarabel solve (floor)", f"{res['clarabel_ms_median']:.3f} ms"),
            ("real-time / IPOPT", f"{res['ratio_rt_vs_ipopt']:.3f}"),
            ("converged / IPOPT", f"{res['ratio_converged_vs_ipopt']:.3f}"),
            ("max relative cost gap (SCP - IPOPT)", f"{res['cost_gap_max']:.2e}"),
            ("states", f"{res['n_states']}")]
    w = max(len(r[0]) for r in rows)
    lines = [f"| {'quantity'.ljust(w)} | median |", f"|{'-' * (w + 2)}|--------|"]
    lines += [f"| {a.ljust(w)} | {b} |" for a, b in rows]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, help="write the results to this JSON file")
    ap.add_argument("--quick", action="store_true", help="20 s of closed loop instead of 100 s")
    ap.add_argument("--duration", type=float, help="closed-loop duration (s); overrides --quick")
    ap.add_argument("--profile", action="store_true", help="cProfile the real-time steps")
    ap.add_argument("--tolerance", type=float, help="converged-mode tolerance (default: FHOCP's)")
    args = ap.parse_args(argv)
    duration = args.duration if args.duration else (20.0 if args.quick else 100.0)
    with_ipopt = importlib.util.find_spec("casadi") is not None
    if not with_ipopt:
        print("casadi not installed (pip install 'tubekit[bench]'): IPOPT columns are NaN", file=sys.stderr)
    res = run(duration, with_ipopt=with_ipopt, profile=args.profile, tolerance=args.tolerance)
    print(table(res))
    if args.profile:
        print(res["details"]["rt_profile"])
    if args.json:
        args.json.write_text(json.dumps(res, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
