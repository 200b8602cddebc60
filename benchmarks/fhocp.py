"""Benchmark v2 of the FHOCP solvers, like for like, along a closed loop of the paper's Section VI scenario.

Usage::

    python benchmarks/fhocp.py --json fhocp.json            # full run (100 s, 1000 states)
    python benchmarks/fhocp.py --quick --json quick.json    # 20 s of closed loop
    python benchmarks/fhocp.py --scaling [--per-cell 4]     # step time against N and obstacles in range

1. A closed loop is simulated: the real-time SCP controller drives a plant that
   integrates the nominal kinematics plus the paper's current (RK4, 10 substeps
   per dt, zero-order hold; no ancillary feedback, no sway).
2. The recorded states are replayed **round-robin**: at each state every method
   solves, in an order rotated from state to state, so machine noise lands on all
   methods alike. Each method is warm-started from its own previous solution
   (IPOPT and sqpmethod with primal and dual variables). Every method solves the
   same NLP with the same number of obstacle slots (the SCP's, ``obstacle_slots``).
   The first state (a cold start) is not timed. The garbage collector runs between
   states, never inside a timed step (the peers' garbage otherwise lands in ours).
3. Timed on every side: the **whole controller step** (``solve_time_s``: input
   checks, reference, obstacle selection, the solver, rollout and exact evaluation),
   and beside it the solver alone (``solver_time_s``: the bare Clarabel ``solve()``
   calls, or the CasADi ``nlpsol`` call).

Methods: ``scp_realtime`` (ours, one convex solve), ``scp_converged`` (ours, SCP
to convergence), opt-in beside them (:data:`OPT_IN`) ``scp_realtime_piqp`` (``--piqp``),
``scp_realtime_qoco`` (``--qoco``: the QOCO backend), ``scp_realtime_qocogen`` (``--qocogen``: QOCO generated
as C for the subproblem's pattern; its build, seconds the first time on a machine, is in the untimed cold start) and ``scp_realtime_1e7`` (``--clarabel-1e7``:
Clarabel at 1e-7 with refinement, the real-time setting before ``REALTIME_CLARABEL_SETTINGS``), ``ipopt`` (CasADi + IPOPT, tuned: tol 1e-8, adaptive mu,
warm start with multipliers), ``sqpmethod_qrqp`` (CasADi ``sqpmethod``, exact
Hessian with eigenvalue clipping, ``qrqp``).

For each: median, p90, p99 (ms), failures (fallback or a non-solved status) and
the cost gap to the best optimum: (merit - best) / |best|, best = the lowest
merit of the converged methods that did not fail at that state. For the real-time
mode the same gap is its per-step suboptimality (median and max).

The tightening is a hand-made stand-in for the verifier's: V-bar = V, e_d_min = epsilon + 0.05 m,
obstacle margin 0.05 m, region bounds unchanged.
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import gc
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
from tubekit.fhocp import FHOCP, IpoptFHOCP, ScpOptions
from tubekit.fhocp.options import DEFAULT_RATE_PENALTY
from tubekit.model.kinematics import kinematics
from tubekit.plant.kinematic import Plant
from tubekit.scenario import Obstacle, Scenario

REQUIRED_KEYS = ("rt_step_ms_median", "rt_step_ms_p99", "converged_ms_median", "ipopt_ms_median",
                 "clarabel_ms_median", "ratio_rt_vs_ipopt", "ratio_converged_vs_ipopt", "cost_gap_max", "n_states",
                 "peers")
PEER_KEYS = ("median_ms", "p90_ms", "p99_ms", "failures", "cost_gap_max", "converged")
#: IPOPT's tuning (beside warm_start_duals=True): adaptive mu was the fastest of monotone / adaptive /
#: tol 1e-6 on 300 states (3.5 ms against 5.0 and 4.1 ms median), at the same optimum.
IPOPT_TUNING = {"mu_strategy": "adaptive"}
#: Clarabel at 1e-7 with iterative refinement: the real-time mode's setting before
#: :data:`tubekit.fhocp.convex.REALTIME_CLARABEL_SETTINGS` (``benchmarks/clarabel_settings.py`` chose that one).
CLARABEL_1E7 = {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7, "iterative_refinement_enable": True}
#: The opt-in methods beside ours: flag -> (method name, ScpOptions changes, table label); each the real-time SCP.
OPT_IN: dict[str, tuple[str, dict, str]] = {
    "piqp": ("scp_realtime_piqp", {"qp_solver": "piqp"}, "real-time SCP, PIQP path"),
    "qoco": ("scp_realtime_qoco", {"qp_solver": "qoco"}, "real-time SCP, QOCO backend"),
    "qocogen": ("scp_realtime_qocogen", {"qp_solver": "qocogen"}, "real-time SCP, generated QOCO (qocogen)"),
    "clarabel_1e7": ("scp_realtime_1e7", {"clarabel_settings": CLARABEL_1E7}, "real-time SCP, Clarabel 1e-7"),
}


def benchmark_tightening(scenario: Scenario) -> Tightening:
    """The stand-in tightening used by the benchmark (see module docstring)."""
    reg = scenario.region
    return Tightening(v_max=scenario.limits.vector.copy(), e_d_min=scenario.epsilon + 0.05,
                      e_o_max=reg.e_o_max, e_z_max=reg.e_z_max, e_d_max=reg.e_d_max,
                      obstacle_margin=0.05, sigma=0.0)


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


def closed_loop(scenario: Scenario, tightening: Tightening, duration: float,
                rate_penalty: float = DEFAULT_RATE_PENALTY) -> list[tuple[float, np.ndarray, list]]:
    """Simulate the real-time SCP controller (rate penalty ``rate_penalty``, s).

    Returns [(t, state, detected obstacles)]."""
    ctrl = FHOCP(scenario, tightening, mode="realtime", options=ScpOptions(rate_penalty=rate_penalty))
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


def make_methods(scenario: Scenario, tightening: Tightening, slots: int | None = None,
                 with_casadi: bool = True, rate_penalty: float = DEFAULT_RATE_PENALTY,
                 opt_in: tuple[str, ...] = ()) -> dict[str, tuple[object, bool]]:
    """{name: (solver, converged?)}: ours and the CasADi peers, all on one problem: the same obstacle slots
    and the same rate penalty lambda (s). ``sqpmethod`` joins only at ``rate_penalty == 0``: its QP solver
    (qrqp, eigen-clip) fails on the rate penalty's node-to-node coupling, so it cannot solve the same problem."""
    opts = ScpOptions(max_obstacles=slots, rate_penalty=rate_penalty)
    rt = FHOCP(scenario, tightening, mode="realtime", options=opts)
    slots = rt.max_obstacles
    opts = ScpOptions(max_obstacles=slots, rate_penalty=rate_penalty)
    methods: dict[str, tuple[object, bool]] = {
        "scp_realtime": (rt, False),
        "scp_converged": (FHOCP(scenario, tightening, mode="converged", options=opts), True)}
    for flag in opt_in:  # the opt-in methods (OPT_IN), real-time mode
        name, changes, _ = OPT_IN[flag]
        methods[name] = (FHOCP(scenario, tightening, mode="realtime", options=dataclasses.replace(opts, **changes)),
                         False)
    if with_casadi:
        methods["ipopt"] = (IpoptFHOCP(scenario, tightening, max_obstacles=slots, warm_start_duals=True,
                                       ipopt_options=IPOPT_TUNING, rate_penalty=rate_penalty), True)
        if rate_penalty == 0.0:
            methods["sqpmethod_qrqp"] = (IpoptFHOCP(scenario, tightening, max_obstacles=slots, warm_start_duals=True,
                                                    nlp_solver="sqpmethod", rate_penalty=0.0), True)
    return methods


def _failed(result) -> bool:
    """A fallback, a non-finite merit or a status that is not a solve."""
    status = getattr(result.status, "value", str(result.status))
    return bool(result.fallback) or not math.isfinite(result.merit) or status not in (
        "optimal", "optimal_inaccurate", "iteration_limit")


def replay(methods: dict, run_states: list, profile: cProfile.Profile | None = None) -> dict[str, dict]:
    """Round-robin replay: every method at every state, the order rotated per state; the first is untimed.

    Returns {name: {"step": [s], "solver": [s], "merit": [], "failed": [], "iterations": []}}.
    """
    names = list(methods)
    rec = {n: {"step": [], "solver": [], "merit": [], "failed": [], "iterations": []} for n in names}
    for i, (t, s, obs) in enumerate(run_states):
        k = i % len(names)
        gc.collect()  # the garbage of one method must not be collected inside another's timed step
        for name in names[k:] + names[:k]:
            solver = methods[name][0]
            if profile is not None and name == "scp_realtime" and i > 0:
                profile.enable()
            r = solver.solve(t, s, obs)
            if profile is not None:
                profile.disable()
            if i == 0:
                continue
            out = rec[name]
            out["step"].append(r.solve_time_s)
            out["solver"].append(r.solver_time_s)
            out["merit"].append(r.merit)
            out["failed"].append(_failed(r))
            out["iterations"].append(r.iterations)
    return rec


def median_step_alone(ctrl, run_states: list) -> float:
    """Median step (ms) of ``ctrl`` along ``run_states`` with nothing else between its steps (its caches warm);
    the first state's solve, a cold start (a generated solver's build or load), is not timed."""
    ctrl.solve(*run_states[0])
    gc.collect()
    times = []
    for t, s, obs in run_states[1:]:
        t0 = time.perf_counter()
        ctrl.solve(t, s, obs)
        times.append(time.perf_counter() - t0)
    return float(np.median(times) * 1e3)


def gaps(rec: dict, methods: dict) -> dict[str, np.ndarray]:
    """Relative merit gap of each method to the best converged, non-failed merit, per state (NaN if failed)."""
    merits = {n: np.where(rec[n]["failed"], np.nan, rec[n]["merit"]) for n in rec}
    conv = [merits[n] for n in rec if methods[n][1]]
    best = np.nanmin(np.vstack(conv), axis=0)
    return {n: (m - best) / np.maximum(np.abs(best), 1e-12) for n, m in merits.items()}


def _pct_ms(x: list[float], q: float) -> float:
    return float(np.percentile(x, q) * 1e3) if len(x) else math.nan


def summarize(rec: dict, methods: dict) -> dict[str, dict]:
    """Per method: step and solver-only percentiles (ms), failures, cost gap, iterations."""
    gap = gaps(rec, methods)
    out = {}
    for n, r in rec.items():
        g = gap[n][np.isfinite(gap[n])]
        out[n] = {"median_ms": _pct_ms(r["step"], 50), "p90_ms": _pct_ms(r["step"], 90),
                  "p99_ms": _pct_ms(r["step"], 99), "failures": int(np.sum(r["failed"])),
                  "cost_gap_max": float(np.max(g)) if len(g) else math.nan,
                  "cost_gap_median": float(np.median(g)) if len(g) else math.nan,
                  "converged": methods[n][1], "solver_median_ms": _pct_ms(r["solver"], 50),
                  "solver_p99_ms": _pct_ms(r["solver"], 99),
                  "iterations_mean": float(np.mean(r["iterations"])) if r["iterations"] else math.nan}
    return out


def run(duration: float, with_ipopt: bool = True, profile: bool = False, tolerance: float | None = None,
        rate_penalty: float = DEFAULT_RATE_PENALTY, opt_in: tuple[str, ...] = ()) -> dict:
    """Run the benchmark (every method on the problem with rate penalty ``rate_penalty``, s); a JSON-ready dict."""
    sc = paper_scenario()
    tg = benchmark_tightening(sc)
    t0 = time.perf_counter()
    run_states = closed_loop(sc, tg, duration, rate_penalty)
    sim_s = time.perf_counter() - t0
    methods = make_methods(sc, tg, with_casadi=with_ipopt, rate_penalty=rate_penalty, opt_in=opt_in)
    if tolerance is not None:
        slots = methods["scp_realtime"][0].max_obstacles
        methods["scp_converged"] = (FHOCP(sc, tg, mode="converged", options=ScpOptions(
            tolerance=tolerance, max_obstacles=slots, rate_penalty=rate_penalty)), True)
    prof = cProfile.Profile() if profile else None
    gc.disable()
    try:
        rec = replay(methods, run_states, prof)
    finally:
        gc.enable()
    peers = summarize(rec, methods)
    rt, cv = peers["scp_realtime"], peers["scp_converged"]
    ip = peers.get("ipopt", {"median_ms": math.nan, "cost_gap_max": math.nan})
    fastest = min((p["median_ms"] for n, p in peers.items() if p["converged"] and n != "scp_converged"),
                  default=math.nan)
    rt_gap = gaps(rec, methods)["scp_realtime"]
    rt_gap = rt_gap[np.isfinite(rt_gap)]
    out: dict = {
        "rt_step_ms_median": rt["median_ms"], "rt_step_ms_p99": rt["p99_ms"],
        "converged_ms_median": cv["median_ms"], "ipopt_ms_median": ip["median_ms"],
        "clarabel_ms_median": rt["solver_median_ms"],
        "ratio_rt_vs_ipopt": rt["median_ms"] / ip["median_ms"],
        "ratio_converged_vs_ipopt": cv["median_ms"] / ip["median_ms"],
        "cost_gap_max": cv["cost_gap_max"], "n_states": len(rec["scp_realtime"]["step"]), "peers": peers,
        "targets": {"rt_over_clarabel": rt["median_ms"] / rt["solver_median_ms"],
                    "rt_p99_over_median": rt["p99_ms"] / rt["median_ms"],
                    "converged_over_fastest_converged_peer": cv["median_ms"] / fastest,
                    "rt_suboptimality_median": float(np.median(rt_gap)) if len(rt_gap) else math.nan,
                    "rt_suboptimality_max": float(np.max(rt_gap)) if len(rt_gap) else math.nan},
    }
    out["details"] = {
        "duration_s": duration, "rate_penalty": rate_penalty, "closed_loop_sim_s": sim_s,
        "obstacle_slots": methods["scp_realtime"][0].max_obstacles,
        "rt_fallbacks": int(np.sum([bool(f) for f in rec["scp_realtime"]["failed"]])),
        "ipopt_options": IPOPT_TUNING, "order": "round-robin, rotated per state",
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
    """A Markdown table of every method: whole step and solver-only times, failures, cost gap."""
    lines = ["| method | step median ms | p90 | p99 | solver-only median ms | failures | max cost gap |",
             "|---|---|---|---|---|---|---|"]
    label = {"scp_realtime": "real-time SCP step", "scp_converged": "converged SCP", "ipopt": "IPOPT (tuned)",
             "sqpmethod_qrqp": "CasADi sqpmethod + qrqp",
             **{name: text for name, _, text in OPT_IN.values()}}
    for n, p in res["peers"].items():
        lines.append(f"| {label.get(n, n)} | {p['median_ms']:.3f} | {p['p90_ms']:.3f} | {p['p99_ms']:.3f} | "
                     f"{p['solver_median_ms']:.3f} | {p['failures']} | {p['cost_gap_max']:.2e} |")
    tg = res["targets"]
    lines.append("")
    lines.append(f"states {res['n_states']}; rt / Clarabel {tg['rt_over_clarabel']:.2f} (target <= 1.25); "
                 f"rt p99 / median {tg['rt_p99_over_median']:.2f} (<= 5); converged / fastest converged peer "
                 f"{tg['converged_over_fastest_converged_peer']:.2f} (<= 1); rt suboptimality median "
                 f"{tg['rt_suboptimality_median']:.2e}, max {tg['rt_suboptimality_max']:.2e}")
    return "\n".join(lines)


SCALING_N = (8, 16, 32, 64)
SCALING_OBSTACLES = (0, 1, 2, 4, 8, 16)


def synthetic_obstacles(state: np.ndarray, count: int, rng: np.random.Generator, sensing_range: float,
                        clearance: float) -> list[Obstacle]:
    """``count`` obstacles in sensing range of ``state``: up to two just ahead on the heading (they become
    active), the others at random bearings, none closer than the clearance to the vehicle."""
    out: list[Obstacle] = []
    p, psi = np.asarray(state[:3], dtype=float), float(state[3])
    for j in range(count):
        radius = 0.15
        if j < 2:
            d, b = 0.6 + 0.2 * j, (-1) ** j * 0.15
        else:
            d, b = rng.uniform(radius + clearance + 0.3, sensing_range + radius - 0.05), rng.uniform(-np.pi, np.pi)
        c = p + np.array([d * np.cos(psi + b), d * np.sin(psi + b), rng.uniform(-0.2, 0.2) if j >= 2 else 0.0])
        out.append(Obstacle(center=tuple(float(x) for x in c), radius=radius))
    return out


def _active(states: np.ndarray, obstacles: list[Obstacle], clearance: float) -> int:
    """How many obstacles a plan touches: clearance along its samples below 1 mm."""
    return sum(bool(np.min(np.linalg.norm(states[1:, :3] - np.asarray(o.center), axis=1)) - o.radius - clearance
                    < 1e-3) for o in obstacles)


def _scaling_cell(sc: Scenario, tg: Tightening, run_states: list, n_obs: int | None, per_cell: int,
                  with_casadi: bool, rng: np.random.Generator,
                  rate_penalty: float = DEFAULT_RATE_PENALTY) -> dict[str, float]:
    """Median whole-step time (ms) per method on ``per_cell`` warm steps (the solve after one at the
    previous recorded state, same obstacles), methods in rotated order; failures and active obstacles
    (in the converged SCP's plan) summed over the cell."""
    slots = None if n_obs is None else max(n_obs, 1)
    methods = make_methods(sc, tg, slots, with_casadi, rate_penalty)
    names, times = list(methods), {n: [] for n in methods}
    fails, active = {n: 0 for n in methods}, 0
    starts = np.linspace(1, len(run_states) - 2, per_cell).astype(int)
    clearance = sc.vehicle_radius + tg.obstacle_margin
    for c, i in enumerate(starts):
        (t0, s0, obs0), (t1, s1, _) = run_states[i], run_states[i + 1]
        obs = obs0 if n_obs is None else synthetic_obstacles(s0, n_obs, rng, sc.sensing_range, clearance)
        gc.collect()
        for name in names[c % len(names):] + names[:c % len(names)]:
            solver = methods[name][0]
            solver.reset()
            solver.solve(t0, s0, obs)
            r = solver.solve(t1, s1, obs)
            times[name].append(r.solve_time_s)
            fails[name] += _failed(r)
            if name == "scp_converged":
                active += _active(r.states, list(obs), clearance)
    out: dict = {n: float(np.median(v) * 1e3) for n, v in times.items()}
    out["failures"] = fails
    out["active_obstacles"] = active
    return out


def _exponent(x: list[float], y: list[float]) -> float:
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def scaling(per_cell: int = 4, with_casadi: bool = True, seed: int = 0,
            rate_penalty: float = DEFAULT_RATE_PENALTY) -> dict:
    """Step time against the horizon N (paper obstacles) and against obstacles in range (N = 8), every method
    on the problem with rate penalty ``rate_penalty`` (s)."""
    base = paper_scenario()
    tg = benchmark_tightening(base)
    run_states = closed_loop(base, tg, 30.0, rate_penalty)
    rng = np.random.default_rng(seed)
    by_n, by_obs = {}, {}
    for n in SCALING_N:
        sc = dataclasses.replace(base, controller=dataclasses.replace(base.controller, horizon_steps=n))
        by_n[n] = _scaling_cell(sc, tg, run_states, None, per_cell, with_casadi, rng, rate_penalty)
    for m in SCALING_OBSTACLES:
        by_obs[m] = _scaling_cell(base, tg, run_states, m, per_cell, with_casadi, rng, rate_penalty)
    names = list(by_n[SCALING_N[0]]["failures"])
    fit_n = {k: _exponent(list(by_n), [by_n[n][k] for n in by_n]) for k in names}
    pos = [m for m in by_obs if m > 0]
    fit_obs = {k: _exponent(pos, [by_obs[m][k] for m in pos]) for k in names}
    return {"per_cell": per_cell, "by_horizon": by_n, "by_obstacles": by_obs,
            "exponent_horizon": fit_n, "exponent_obstacles": fit_obs}


def scaling_table(res: dict) -> str:
    """Markdown: median step (ms, failures in brackets) per method against N and against obstacles in range,
    with the fitted exponents and the obstacles active in the converged plans."""
    names = list(res["exponent_horizon"])

    def row(label: str, v: dict) -> str:
        cells = [f"{v[k]:.2f}" + (f" ({v['failures'][k]} f)" if v["failures"][k] else "") for k in names]
        return f"| {label} | " + " | ".join(cells) + f" | {v['active_obstacles']} |"

    head = "| " + " | ".join(["cell"] + names + ["active"]) + " |\n|" + "---|" * (len(names) + 2)
    rows = [row(f"N = {n}", v) for n, v in res["by_horizon"].items()]
    rows.append("| exponent in N | " + " | ".join(f"{res['exponent_horizon'][k]:.2f}" for k in names) + " | |")
    rows += [row(f"{m} obstacles", v) for m, v in res["by_obstacles"].items()]
    rows.append("| exponent in obstacles (1..16) | "
                + " | ".join(f"{res['exponent_obstacles'][k]:.2f}" for k in names) + " | |")
    return head + "\n" + "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, help="write the results to this JSON file")
    ap.add_argument("--quick", action="store_true", help="20 s of closed loop instead of 100 s")
    ap.add_argument("--duration", type=float, help="closed-loop duration (s); overrides --quick")
    ap.add_argument("--profile", action="store_true", help="cProfile the real-time steps")
    ap.add_argument("--tolerance", type=float, help="converged-mode tolerance (default: FHOCP's)")
    ap.add_argument("--scaling", action="store_true", help="run the scaling study instead (N and obstacles)")
    ap.add_argument("--rate-penalty", type=float, default=DEFAULT_RATE_PENALTY,
                    help="the rate penalty lambda (s) of every method's problem (default: the controller's; "
                         "CasADi sqpmethod joins only at 0)")
    for flag, (_, _, text) in OPT_IN.items():
        ap.add_argument(f"--{flag.replace('_', '-')}", dest=flag, action="store_true", help=f"add the {text}")
    ap.add_argument("--no-casadi", action="store_true", help="leave the CasADi peers out")
    ap.add_argument("--per-cell", type=int, default=4, help="warm steps per scaling cell (default 4)")
    args = ap.parse_args(argv)
    duration = args.duration if args.duration else (20.0 if args.quick else 100.0)
    with_casadi = importlib.util.find_spec("casadi") is not None and not args.no_casadi
    if importlib.util.find_spec("casadi") is None:
        print("casadi not installed (pip install 'tubekit[bench]'): the CasADi peers are left out", file=sys.stderr)
    if args.scaling:
        res = scaling(args.per_cell, with_casadi, rate_penalty=args.rate_penalty)
        print(scaling_table(res))
    else:
        res = run(duration, with_ipopt=with_casadi, profile=args.profile, tolerance=args.tolerance,
                  rate_penalty=args.rate_penalty, opt_in=tuple(f for f in OPT_IN if getattr(args, f)))
        print(table(res))
        if args.profile:
            print(res["details"]["rt_profile"])
    if args.json:
        args.json.write_text(json.dumps(res, indent=2, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
