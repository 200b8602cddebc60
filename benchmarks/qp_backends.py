"""The QP backends on the real-time FHOCP's recorded subproblems, and in the closed loop: which one earns its place?

Usage::

    python benchmarks/qp_backends.py [--duration S] [--only NAME ...] [--backends clarabel qocogen ...] [--json FILE]
    python benchmarks/qp_backends.py --closed-loop [--duration S] [--only NAME ...] [--backends ...]
    python benchmarks/qp_backends.py --qocogen-tolerances 1e-6 1e-5 [--duration S] [--only NAME ...]

Every shipped scenario (those of ``benchmarks/clarabel_settings.py``: Section VI, ``paper_currents``,
``certifiable``, ``examples/paper_law.toml`` with their faster and steady currents, the transit, the examples
``circle``, ``helix``, ``line``, ``waypoints``) is certified and its tube run simulated once with the shipped
controller; every convex subproblem the real-time SCP solves is recorded as a
:class:`~tubekit.fhocp.qp.base.ConeProgramData`. Each recorded problem is then solved again by one persistent
backend per name (``clarabel`` built as the real-time mode builds it; the others with their defaults), the
backends' order rotated from problem to problem. Per backend: the problems not solved (``optimal``; an
``optimal_inaccurate`` is counted apart), the largest difference of the plan's inputs (u, w, r) and of the
objective from Clarabel's, and the median and p99 of the backend's whole ``solve`` call (ms: the data handed over,
the solve, the solution checked; reported, never a verdict). A backend's one-time set-up (the generated solver's
build or load) is in its first problem, which is not timed.

``--steps`` instead times the whole real-time step alone: along the 999 states of ``benchmarks/fhocp.py``'s closed
loop (Section VI, its stand-in tightening), each backend's controller (and IPOPT's, tuned as there, when CasADi is
installed) solves every state in sequence, one method per round, the rounds alternated (``--rounds`` each): no
other method runs between two steps, so each keeps its caches warm (the round robin of ``benchmarks/fhocp.py``
does the opposite). Per method: the median of its rounds' median step (ms) and its ratio to IPOPT's.

``--closed-loop`` instead runs each scenario's certified tube run once per backend (``ScpOptions(qp_solver=...)``)
and prints its tracking RMSE, the seconds the backup ran, the periods the candidate replaced a plan, the smallest
clearance and the promises broken: what the backend does to the loop rather than to one subproblem.

``--qocogen-tolerances TOL ...`` instead solves every recorded subproblem with the generated solver at its default
tolerance (1e-7) and at each TOL (absolute and relative), the order rotated: per setting the failures, inaccurate
solves, the largest input difference from the default's plan, the mean iterations and the median call (ms). It
chose :data:`tubekit.fhocp.qp.qocogen.REALTIME_QOCOGEN_SETTINGS`.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["BACKENDS", "record", "compare", "qocogen_tolerances", "closed_loop", "steps", "main"]

#: The backends compared by default: the shipped one first, then the opt-in ones that take cones.
BACKENDS = ("clarabel", "qoco", "qocogen")


def _study(name: str):
    import importlib.util

    path = Path(__file__).resolve().parent / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"_qp_backends_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def record(scenario, duration: float) -> tuple[list, np.ndarray]:
    """The certified tube run's subproblems (copies of each :class:`ConeProgramData`) and the columns of the plan's
    inputs (u, w, r) in their x."""
    import dataclasses

    import verify
    from tubekit.fhocp.registry import make_solver
    from tubekit.loop.closed_loop import run_closed_loop

    sc = scenario.with_changes(duration=float(duration))
    tight = verify.certify(sc).best_effort_tightening()
    problems: list = []
    columns: list[np.ndarray] = []

    def factory(scen, tightening):
        solver = make_solver(scen, tightening)
        compiled = solver.subproblem.compiled
        variables = solver.subproblem.variables
        columns.append(np.concatenate([compiled.columns_of(variables[n]) for n in ("u", "w", "r")]))
        backend = compiled.backend
        original = backend.solve

        def recording_solve(data):
            problems.append(dataclasses.replace(
                data, p_values=None if data.p_values is None else data.p_values.copy(), q=data.q.copy(),
                a_values=data.a_values.copy(), b=data.b.copy(), a_changed=None, p_changed=True))
            return original(data)

        backend.solve = recording_solve
        return solver

    run_closed_loop(sc, tight, tube=True, progress=False, solver_factory=factory)
    return problems, columns[0]


def _backend(name: str):
    from tubekit.fhocp.convex import DEFAULT_CLARABEL_SETTINGS, REALTIME_CLARABEL_SETTINGS
    from tubekit.fhocp.qp.registry import make_qp_backend

    shipped = {**DEFAULT_CLARABEL_SETTINGS, **REALTIME_CLARABEL_SETTINGS}  # what the real-time mode runs
    return make_qp_backend(name, {"clarabel": shipped})


def _solve_rotated(problems: list, inputs: np.ndarray, backends: dict, reference: str) -> dict:
    """Every problem solved by each backend, the order rotated per problem: per backend its failures, inaccurate
    solves, iterations, call times (every problem but the first) and the largest differences of the plan's inputs
    and of the objective (relative) from ``reference``'s."""
    keys = tuple(backends)
    stats = {k: {"failed": 0, "inaccurate": 0, "iterations": [], "times": [], "dv": 0.0, "dobj": 0.0} for k in keys}
    for i, data in enumerate(problems):
        sols = {}
        for key in keys[i % len(keys):] + keys[:i % len(keys)]:
            t0 = time.perf_counter()
            sol = backends[key].solve(data)
            if i:
                stats[key]["times"].append(time.perf_counter() - t0)
            stats[key]["iterations"].append(sol.iterations)
            if sol.status.value == "optimal_inaccurate":
                stats[key]["inaccurate"] += 1
            elif sol.status.value != "optimal":
                stats[key]["failed"] += 1
            sols[key] = sol
        base = sols[reference]
        for key in keys:
            if base.x is not None and sols[key].x is not None:
                x = sols[key].x
                stats[key]["dv"] = max(stats[key]["dv"], float(np.max(np.abs(x[inputs] - base.x[inputs]))))
                gap = abs(sols[key].objective - base.objective) / max(1.0, abs(base.objective))
                stats[key]["dobj"] = max(stats[key]["dobj"], gap)
    return stats


def compare(problems: list, inputs: np.ndarray, names: tuple[str, ...] = BACKENDS) -> dict:
    """Per backend: failures, inaccurate solves, the largest input and objective differences from Clarabel's,
    the whole ``solve`` call's median and p99 (ms) over every problem but the first."""
    stats = _solve_rotated(problems, inputs, {name: _backend(name) for name in names}, "clarabel")
    return {n: {"failed": s["failed"], "inaccurate": s["inaccurate"], "max_input_diff": s["dv"],
                "max_objective_gap": s["dobj"], "median_ms": float(np.median(s["times"]) * 1e3),
                "p99_ms": float(np.percentile(s["times"], 99) * 1e3)} for n, s in stats.items()}


def qocogen_tolerances(problems: list, inputs: np.ndarray, tolerances: tuple[float, ...]) -> dict:
    """The generated solver at QOCO's default tolerance (1e-7) and at each of ``tolerances`` (absolute = relative),
    the order rotated per problem: per setting its failures, inaccurate solves, the largest input difference from
    the default's plan, its iterations and call times (s, every problem but the first)."""
    from tubekit.fhocp.qp.registry import make_qp_backend

    settings = {"1e-07 (default)": {}, **{f"{tol:g}": {"abstol": tol, "reltol": tol} for tol in tolerances}}
    backends = {k: make_qp_backend("qocogen", {"qocogen": v}) for k, v in settings.items()}
    stats = _solve_rotated(problems, inputs, backends, "1e-07 (default)")
    return {k: {"failed": s["failed"], "inaccurate": s["inaccurate"], "max_input_diff": s["dv"],
                "iterations": s["iterations"], "times": s["times"]} for k, s in stats.items()}


def closed_loop(scenario, duration: float, names: tuple[str, ...] = BACKENDS) -> dict:
    """Per backend: the certified tube run's figures (module doc)."""
    import verify
    from tubekit.fhocp.options import ScpOptions
    from tubekit.fhocp.scp import FHOCP
    from tubekit.loop.pipeline import certified_run

    sc = scenario.with_changes(duration=float(duration))
    tight = verify.certify(sc).best_effort_tightening()
    out = {}
    for name in names:
        options = ScpOptions(qp_solver=name)
        done = certified_run(sc, tight, progress=False,
                             solver_factory=lambda scen, tightening, o=options: FHOCP(scen, tightening, options=o))
        m = done.metrics
        out[name] = {"tracking_rmse": m["tracking_rmse"], "backup_s": m["backup_s"],
                     "candidate_periods": int(done.run.candidate.sum()), "min_clearance": m["min_clearance"],
                     "broken": list(done.broken)}
    return out


def steps(names: tuple[str, ...], rounds: int, duration: float = 100.0) -> dict:
    """Per method (each backend's real-time SCP, then IPOPT if CasADi is there), built by ``benchmarks/fhocp.py``'s
    ``make_methods`` (the same obstacle slots and rate penalty): its rounds' median steps (ms) and their median."""
    import importlib.util

    fhocp = _study("fhocp")
    from tubekit import paper_scenario

    sc = paper_scenario()
    tg = fhocp.benchmark_tightening(sc)
    states = fhocp.closed_loop(sc, tg, duration)
    with_casadi = importlib.util.find_spec("casadi") is not None
    picks = {("scp_realtime" if name == "clarabel" else fhocp.OPT_IN[name][0]): name for name in names}
    if with_casadi:
        picks["ipopt"] = "ipopt"
    opt_in = tuple(name for name in names if name != "clarabel")
    medians: dict[str, list[float]] = {k: [] for k in picks}
    for _ in range(rounds):
        for method in picks:
            ctrl = fhocp.make_methods(sc, tg, with_casadi=method == "ipopt", opt_in=opt_in)[method][0]
            medians[method].append(fhocp.median_step_alone(ctrl, states))
    out = {k: {"median_ms": float(np.median(v)), "rounds_ms": v} for k, v in medians.items()}
    if "ipopt" in out:
        for k in out:
            out[k]["over_ipopt"] = out[k]["median_ms"] / out["ipopt"]["median_ms"]
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=100.0, help="simulated seconds of each recorded run")
    ap.add_argument("--only", nargs="*", help="scenario names (default all)")
    ap.add_argument("--backends", nargs="*", default=list(BACKENDS), help="QP backend names, Clarabel first")
    ap.add_argument("--json", type=Path, help="write the rows to this JSON file")
    ap.add_argument("--closed-loop", action="store_true", help="compare whole tube runs instead (module doc)")
    ap.add_argument("--steps", action="store_true", help="time the real-time step alone per backend (module doc)")
    ap.add_argument("--rounds", type=int, default=2, help="rounds per method with --steps (default 2)")
    ap.add_argument("--qocogen-tolerances", type=float, nargs="+", metavar="TOL",
                    help="compare the generated solver at these tolerances with its default instead")
    args = ap.parse_args(argv)
    names = tuple(args.backends)
    if args.steps:
        print(json.dumps(steps(names, args.rounds, args.duration), indent=1), flush=True)
        return 0
    if "clarabel" not in names:
        ap.error("--backends must include clarabel (the reference)")
    scenarios = {k: v for k, v in _study("clarabel_settings")._scenarios().items() if not args.only or k in args.only}
    if args.qocogen_tolerances:
        print(json.dumps(_tolerance_study(scenarios, args.duration, tuple(args.qocogen_tolerances)), indent=1))
        return 0
    if args.closed_loop:
        for name, sc in scenarios.items():
            print(json.dumps({"scenario": name, "backends": closed_loop(sc, args.duration, names)}), flush=True)
        return 0
    rows, total = [], 0
    for name, sc in scenarios.items():
        problems, inputs = record(sc, args.duration)
        total += len(problems)
        row = {"scenario": name, "problems": len(problems), "backends": compare(problems, inputs, names)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    summary = {n: {"failed": sum(r["backends"][n]["failed"] for r in rows),
                   "inaccurate": sum(r["backends"][n]["inaccurate"] for r in rows),
                   "max_input_diff": max(r["backends"][n]["max_input_diff"] for r in rows),
                   "median_ms_per_scenario": [round(r["backends"][n]["median_ms"], 4) for r in rows]}
               for n in names}
    print(json.dumps({"problems": total, "summary": summary}), flush=True)
    if args.json:
        from tubekit.jsonable import write_text

        write_text(args.json, json.dumps({"rows": rows, "problems": total, "summary": summary}, indent=1) + "\n")
    return 0


def _tolerance_study(scenarios: dict, duration: float, tolerances: tuple[float, ...]) -> dict:
    """:func:`qocogen_tolerances` over every scenario's recorded subproblems, pooled."""
    pooled: dict = {}
    total = 0
    for sc in scenarios.values():
        problems, inputs = record(sc, duration)
        total += len(problems)
        for key, row in qocogen_tolerances(problems, inputs, tolerances).items():
            acc = pooled.setdefault(key, {"failed": 0, "inaccurate": 0, "max_input_diff": 0.0, "iterations": [],
                                          "times": []})
            for name in ("failed", "inaccurate"):
                acc[name] += row[name]
            acc["max_input_diff"] = max(acc["max_input_diff"], row["max_input_diff"])
            acc["iterations"] += row["iterations"]
            acc["times"] += row["times"]
    return {"problems": total, **{k: {"failed": v["failed"], "inaccurate": v["inaccurate"],
                                      "max_input_diff": v["max_input_diff"],
                                      "mean_iterations": float(np.mean(v["iterations"])),
                                      "median_ms": float(np.median(v["times"]) * 1e3)} for k, v in pooled.items()}}


if __name__ == "__main__":
    sys.exit(main())
