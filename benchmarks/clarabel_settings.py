"""Which Clarabel settings the real-time FHOCP needs: failures and plan differences on recorded subproblems.

Usage::

    python benchmarks/clarabel_settings.py [--duration S] [--only NAME ...] [--json FILE] [--closed-loop]

Every shipped scenario (Section VI, ``paper_currents``, ``certifiable``, ``examples/paper_law.toml`` with their
faster and steady currents, the transit, the examples ``circle``, ``helix``, ``line``, ``waypoints``) is certified
and its tube run simulated once with the shipped settings; every convex subproblem the real-time SCP solves is
recorded as Clarabel's canonical data (P, q, A, b, cones). Each recorded problem is then solved again by one
persistent solver per setting (``update`` then ``solve``, as the controller does; the settings interleaved per
problem), for

* ``shipped``: what the real-time mode runs, :data:`tubekit.fhocp.convex.DEFAULT_CLARABEL_SETTINGS` with
  :data:`tubekit.fhocp.convex.REALTIME_CLARABEL_SETTINGS` on top (gap and feasibility 1e-6, Clarabel's iterative
  refinement off: chosen by this study);
* ``1e-7`` (the setting shipped before), ``1e-6``, ``1e-6/no-refinement``, ``1e-7/no-refinement``: the
  tolerances at 1e-6 or 1e-7 with and without refinement.

Per setting: the problems not ``Solved`` (``AlmostSolved`` counted apart: the controller's status map takes it as
inaccurate), the largest difference of the solution from the shipped setting's (all of x, slacks included, and the
plan's inputs u, w, r), the median and p99 of the bare solve time (ms; reported, never a verdict). Nothing here
changes the controller: it measures what a change would do.

``--closed-loop`` instead runs each scenario's certified tube loop once per setting (the FHOCP built with the
setting as ``ScpOptions(clarabel_settings=...)``, on top of the shipped defaults) and prints, per
setting, the tracking RMSE, the seconds the backup ran, the periods the candidate replaced a plan, the smallest
clearance and the promises broken: what the change does to the loop rather than to one subproblem.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["SETTINGS", "record", "compare", "closed_loop", "main"]

#: The settings compared (overrides on top of what the real-time mode ships), the shipped one first; each names
#: every setting it compares, so it means the same whatever the defaults are.
_TOL6 = {"tol_gap_abs": 1e-6, "tol_gap_rel": 1e-6, "tol_feas": 1e-6}
_TOL7 = {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7}
SETTINGS: dict[str, dict] = {
    "shipped": {},
    "1e-7": {**_TOL7, "iterative_refinement_enable": True},
    "1e-6": {**_TOL6, "iterative_refinement_enable": True},
    "1e-6/no-refinement": {**_TOL6, "iterative_refinement_enable": False},
    "1e-7/no-refinement": {**_TOL7, "iterative_refinement_enable": False},
}


def _scenarios() -> dict:
    """The scenarios of the module doc, by name (``benchmarks/mission.py``'s, plus the examples)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import mission  # noqa: E402 - the sibling benchmark's scenario list
    from tubekit.scenario import load_scenario

    out = dict(mission.scenarios())
    for name in ("circle", "helix", "line", "waypoints"):
        out[name] = load_scenario(mission.ROOT / "examples" / f"{name}.toml")
    return out


def record(scenario, duration: float) -> tuple[list[tuple], object, np.ndarray]:
    """The certified tube run's subproblems as (P, q, A, b), the compiled program they came from and the columns
    of the plan's inputs (u, w, r) in its x."""
    import verify
    from tubekit.fhocp.registry import make_solver
    from tubekit.loop.closed_loop import run_closed_loop

    sc = scenario.with_changes(duration=float(duration))
    tight = verify.certify(sc).best_effort_tightening()
    problems: list[tuple] = []
    compiled_of: list = []
    columns: list[np.ndarray] = []

    def factory(scen, tightening):
        solver = make_solver(scen, tightening)
        compiled = solver.subproblem.compiled
        compiled_of.append(compiled)
        variables = solver.subproblem.variables
        columns.append(np.concatenate([compiled.columns_of(variables[n]) for n in ("u", "w", "r")]))
        original = compiled.solve

        def recording_solve():
            P, q, A, b, _ = compiled.data()
            problems.append((P.copy(), q.copy(), A.copy(), b.copy()))
            return original()

        compiled.solve = recording_solve
        return solver

    run_closed_loop(sc, tight, tube=True, progress=False, solver_factory=factory)
    return problems, compiled_of[0], columns[0]


def compare(problems: list[tuple], compiled, inputs: np.ndarray) -> dict:
    """Per setting: failures, AlmostSolved, the largest solution differences from ``shipped``, solve times."""
    import clarabel
    from tubekit.fhocp.convex import DEFAULT_CLARABEL_SETTINGS, REALTIME_CLARABEL_SETTINGS
    from tubekit.fhocp.qp.clarabel import clarabel_cones, clarabel_settings

    P0, q0, A0, b0 = problems[0]
    shipped = {**DEFAULT_CLARABEL_SETTINGS, **REALTIME_CLARABEL_SETTINGS}  # what the real-time mode runs
    solvers = {name: clarabel.DefaultSolver(P0, q0, A0, b0, clarabel_cones(compiled.dims),
                                            clarabel_settings({**shipped, **over}))
               for name, over in SETTINGS.items()}
    names = list(SETTINGS)
    stats = {n: {"failed": 0, "almost": 0, "times": [], "dx": 0.0, "dv": 0.0} for n in names}
    for i, (P, q, A, b) in enumerate(problems):
        order = names if i % 2 == 0 else names[::-1]
        xs = {}
        for name in order:
            s = solvers[name]
            s.update(P=P, q=q, A=A, b=b)
            t0 = time.perf_counter()
            sol = s.solve()
            stats[name]["times"].append(time.perf_counter() - t0)
            status = str(sol.status)
            if status == "AlmostSolved":
                stats[name]["almost"] += 1
            elif status != "Solved":
                stats[name]["failed"] += 1
            xs[name] = np.asarray(sol.x) if status == "Solved" else None
        base = xs["shipped"]
        for name in names:
            if base is not None and xs[name] is not None:
                stats[name]["dx"] = max(stats[name]["dx"], float(np.max(np.abs(xs[name] - base))))
                stats[name]["dv"] = max(stats[name]["dv"], float(np.max(np.abs(xs[name][inputs] - base[inputs]))))
    return {n: {"failed": s["failed"], "almost_solved": s["almost"], "max_x_diff": s["dx"],
                "max_input_diff": s["dv"], "median_ms": float(np.median(s["times"]) * 1e3),
                "p99_ms": float(np.percentile(s["times"], 99) * 1e3)} for n, s in stats.items()}


def closed_loop(scenario, duration: float) -> dict:
    """Per setting: the certified tube run's figures (module doc), its FHOCP built with the setting's Clarabel
    overrides (``ScpOptions.clarabel_settings``)."""
    import verify
    from tubekit.fhocp.options import ScpOptions
    from tubekit.fhocp.scp import FHOCP
    from tubekit.loop.pipeline import certified_run

    sc = scenario.with_changes(duration=float(duration))
    tight = verify.certify(sc).best_effort_tightening()
    out = {}
    for name, over in SETTINGS.items():
        options = ScpOptions(clarabel_settings=over or None)
        done = certified_run(sc, tight, progress=False,
                             solver_factory=lambda scen, tightening, o=options: FHOCP(scen, tightening, options=o))
        m = done.metrics
        out[name] = {"tracking_rmse": m["tracking_rmse"], "backup_s": m["backup_s"],
                     "candidate_periods": int(done.run.candidate.sum()), "min_clearance": m["min_clearance"],
                     "broken": list(done.broken)}
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=100.0, help="simulated seconds of each recorded run")
    ap.add_argument("--only", nargs="*", help="scenario names (default all)")
    ap.add_argument("--json", type=Path, help="write the rows to this JSON file")
    ap.add_argument("--closed-loop", action="store_true", help="compare whole tube runs instead (module doc)")
    args = ap.parse_args(argv)
    if args.closed_loop:
        for name, sc in _scenarios().items():
            if not args.only or name in args.only:
                print(json.dumps({"scenario": name, "settings": closed_loop(sc, args.duration)}), flush=True)
        return 0
    rows, total = [], 0
    for name, sc in _scenarios().items():
        if args.only and name not in args.only:
            continue
        problems, compiled, inputs = record(sc, args.duration)
        total += len(problems)
        row = {"scenario": name, "problems": len(problems),
               "settings": compare(problems, compiled, inputs)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    summary = {n: {"failed": sum(r["settings"][n]["failed"] for r in rows),
                   "almost_solved": sum(r["settings"][n]["almost_solved"] for r in rows),
                   "max_input_diff": max(r["settings"][n]["max_input_diff"] for r in rows)} for n in SETTINGS}
    print(json.dumps({"problems": total, "summary": summary}), flush=True)
    if args.json:
        from tubekit.jsonable import write_text

        write_text(args.json, json.dumps({"rows": rows, "problems": total, "summary": summary}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
