"""Closed-loop speed of the tube run on the paper's scenario, and where a tick's time goes.

Usage::

    python benchmarks/closed_loop.py [--duration S] [--repeat K] [--json FILE] [--profile]

``--floor`` adds the solver's floor: one run with every FHOCP step's bare Clarabel time (``solver_time_s``)
summed, and ``floor_realtime_factor`` = simulated seconds / that sum: the real-time factor the loop would
have if everything but Clarabel's own ``solve()`` cost nothing (an upper bound for any compiled glue).

``--profile`` adds one profiled run and its split by part (:data:`PROFILE_PARTS`: FHOCP, arc check, nominal
arcs, logging, sensing, plant, law, saturation, the tick loop's own Python) as shares of that run.

The tightening comes from :func:`verify.certify` on the paper's scenario; certification is done before the
clock starts and is excluded. The run is :func:`tubekit.loop.closed_loop.run_closed_loop` (tube, real-time
FHOCP, the scenario's law) timed as a whole: ``realtime_factor`` = simulated seconds / wall seconds. The
breakdown replays the recorded run's ticks through each part on its own (the law, the plant's
``step_tuple``, saturation) and takes the FHOCP time from the run's own log, so the parts are measured
without timer overhead inside the loop; ``other`` is the remainder (logging, sensing, nominal arc, plan
check, Python glue).
"""

from __future__ import annotations

import argparse
import cProfile
import importlib
import json
import pstats
import sys
import time

import numpy as np

import verify
from tubekit import paper_scenario
from tubekit.model.ancillary import get_law
from tubekit.loop.closed_loop import run_closed_loop, saturate
from tubekit.plant.kinematic import Plant

__all__ = ["measure", "main"]


def _per_call_us(fn, args_list: list[tuple]) -> float:
    """Mean wall time (µs) of ``fn(*args)`` over ``args_list`` (best of 3 passes)."""
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for args in args_list:
            fn(*args)
        best = min(best, time.perf_counter() - t0)
    return 1e6 * best / max(1, len(args_list))


def _breakdown(scenario, res) -> dict:
    """Per-tick cost of the law, the plant step and saturation, replayed on the run's own ticks."""
    law = get_law(scenario.controller.law)
    plant = Plant.of(scenario)
    n = len(res.t) - 1
    idx = np.linspace(0, n - 1, min(n, 4000)).astype(int)
    sig = float(res.sigma)
    law_args = [(res.states[i], res.nominal[i], res.desired[i], sig) for i in idx]
    h, sub = float(res.plant_step_s), int(round(1.0 / (scenario.controller.ancillary_rate_hz * res.plant_step_s)))
    plant_args = [(float(res.t[i]), tuple(res.states[i].tolist()), tuple(res.inputs[i].tolist()), h, sub)
                  for i in idx]
    limits = tuple(float(c) for c in scenario.limits.vector)
    sat_args = [(tuple(res.inputs[i].tolist()), limits) for i in idx]
    ticks = n
    periods = int(scenario.steps)
    law_us = _per_call_us(law, law_args)
    plant_us = _per_call_us(plant.step_tuple, plant_args)
    sat_us = _per_call_us(saturate, sat_args)
    solve_ms = np.asarray(res.solve_ms, dtype=float)
    fhocp_s = float(np.nansum(solve_ms[np.isfinite(solve_ms)])) * 1e-3
    parts_s = {"law": law_us * 1e-6 * ticks, "plant": plant_us * 1e-6 * ticks,
               "saturate": sat_us * 1e-6 * ticks, "fhocp": fhocp_s}
    parts_s["other"] = max(0.0, float(res.wall_s) - sum(parts_s.values()))
    return {"ticks": ticks, "periods": periods, "law_us_per_tick": law_us, "plant_us_per_tick": plant_us,
            "saturate_us_per_tick": sat_us, "fhocp_ms_per_period": 1e3 * fhocp_s / periods,
            "parts_s": parts_s, "parts_share": {k: v / float(res.wall_s) for k, v in parts_s.items()}}


#: The profile's parts: (module path suffix, function) whose cumulative time is the part's (none nests in another).
PROFILE_PARTS = {
    "fhocp": (("tubekit/fhocp/scp.py", "solve"),),
    "arc_check": (("tubekit/loop/closed_loop.py", "accept"),),
    "nominal_arcs": (("tubekit/loop/closed_loop.py", "run_period", "nominal_arc"),),
    "logging": (("tubekit/loop/closed_loop.py", "log_period"), ("tubekit/loop/closed_loop.py", "record_solve")),
    "sensing": (("tubekit/loop/closed_loop.py", "sense"),),
    "plant": (("tubekit/plant/kinematic.py", "step_tuple"), ("tubekit/plant/dynamic.py", "step_tuple")),
    "law": (("tubekit/loop/closed_loop.py", "ancillary"),),
    "saturate": (("tubekit/loop/closed_loop.py", "saturate"),),
    "tick_loop_glue": (("tubekit/loop/closed_loop.py", "run_ticks", None),),
}


def _cumulative(stats: pstats.Stats, spec: tuple) -> float:
    """Cumulative seconds of the function ``spec`` = (file suffix, name) in ``stats``, or of the calls to
    ``spec[2]`` made from that function when ``spec`` has three entries (its own time when ``spec[2]`` is None)."""
    total = 0.0
    for (path, _line, name), (_cc, _nc, _tt, ct, callers) in stats.stats.items():  # type: ignore[attr-defined]
        if len(spec) == 2 and path.endswith(spec[0]) and name == spec[1]:
            total += ct
        elif len(spec) == 3 and spec[2] is None and path.endswith(spec[0]) and name == spec[1]:
            total += _tt
        elif len(spec) == 3 and name == spec[2]:
            total += sum(c[3] for (cp, _cl, cn), c in callers.items() if cp.endswith(spec[0]) and cn == spec[1])
    return total


def profile_breakdown(profiler: cProfile.Profile, total_s: float) -> dict:
    """Shares of the profiled run (s and fraction of ``total_s``) per part of :data:`PROFILE_PARTS`, rest "other"."""
    stats = pstats.Stats(profiler)
    parts = {k: sum(_cumulative(stats, spec) for spec in specs) for k, specs in PROFILE_PARTS.items()}
    parts["other"] = max(0.0, total_s - sum(parts.values()))
    return {"profiled_wall_s": total_s, "parts_s": parts, "parts_share": {k: v / total_s for k, v in parts.items()}}


def _solver_import_s() -> float:
    """Seconds to import the FHOCP package (cvxpy, Clarabel): a once-per-process cost, 0 when already loaded."""
    if "tubekit.fhocp.registry" in sys.modules:
        return 0.0
    i0 = time.perf_counter()
    importlib.import_module("tubekit.fhocp.registry")
    return time.perf_counter() - i0


def measure(duration: float | None = None, profile: bool = False, repeat: int = 3) -> dict:
    """Certify and import the solver package (both untimed, reported), run the tube loop ``repeat`` times
    (timed; the median wall decides ``realtime_factor``) and break the time down; a JSON-ready dict."""
    scenario = paper_scenario()
    if duration is not None:
        from dataclasses import replace
        scenario = replace(scenario, duration=float(duration))
    c0 = time.perf_counter()
    tightening = verify.certify(scenario, law=scenario.controller.law).best_effort_tightening()
    certify_s = time.perf_counter() - c0
    import_s = _solver_import_s()
    walls, res = [], None
    for _ in range(max(1, repeat)):
        w0 = time.perf_counter()
        res = run_closed_loop(scenario, tightening, tube=True, progress=False)
        walls.append(time.perf_counter() - w0)
    wall_s = float(np.median(walls))
    out = {"scenario": scenario.name, "law": res.law, "simulated_s": float(scenario.duration),
           "wall_s": wall_s, "walls_s": walls, "realtime_factor": float(scenario.duration) / wall_s,
           "realtime_factor_with_import": float(scenario.duration) / (wall_s + import_s),
           "solver_import_s_excluded": import_s, "certify_s_excluded": certify_s,
           "kappa_failures": int(res.kappa_failures), "breakdown": _breakdown(scenario, res)}
    if profile:
        profiler = cProfile.Profile()
        p0 = time.perf_counter()
        profiler.enable()
        run_closed_loop(scenario, tightening, tube=True, progress=False)
        profiler.disable()
        pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(25)
        out["profile"] = profile_breakdown(profiler, time.perf_counter() - p0)
    return out


def solver_floor(scenario, tightening) -> dict:
    """One run with the bare Clarabel time of every FHOCP step summed (``--floor``, module doc)."""
    from tubekit.fhocp.registry import make_solver
    total = {"solver_s": 0.0, "step_s": 0.0, "steps": 0}

    class _Timed:
        def __init__(self, inner) -> None:
            self.inner = inner

        def __getattr__(self, name):
            return getattr(self.inner, name)

        def solve(self, *args, **kwargs):
            res = self.inner.solve(*args, **kwargs)
            total["solver_s"] += float(res.solver_time_s)
            total["step_s"] += float(res.solve_time_s)
            total["steps"] += 1
            return res

    w0 = time.perf_counter()
    run_closed_loop(scenario, tightening, tube=True, progress=False,
                    solver_factory=lambda sc, tg: _Timed(make_solver(sc, tg)))
    wall = time.perf_counter() - w0
    sim = float(scenario.duration)
    return {"wall_s": wall, "realtime_factor": sim / wall, "clarabel_solve_s": total["solver_s"],
            "fhocp_step_s": total["step_s"], "steps": total["steps"],
            "clarabel_ms_per_step": 1e3 * total["solver_s"] / max(1, total["steps"]),
            "floor_realtime_factor": sim / total["solver_s"] if total["solver_s"] > 0 else None,
            "glue_budget_ms_per_step_at_100x": 1e3 * (sim / 100.0 - total["solver_s"]) / max(1, total["steps"]),
            "glue_now_ms_per_step": 1e3 * (wall - total["solver_s"]) / max(1, total["steps"])}


def _uncompiled_rollout(s0: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """A plan's rollout as a chain of the model's numpy step (the reference of the compiled rollout)."""
    from tubekit.model.kinematics import unicycle_step

    out = np.empty((len(inputs) + 1, 4))
    out[0] = s0
    for k, v in enumerate(inputs):
        out[k + 1] = unicycle_step(out[k], v, dt)
    return out


def compare_previous(repeat: int = 4, duration: float | None = None) -> dict:
    """Interleaved runs with the uncompiled code paths (RK4 through ``rk4_tuple(plant._rhs)``; the rollout, the
    nominal arc, the plan's arcs, the dynamics residual and the error coordinates through the model's numpy
    formulas) against the compiled ones: wall medians, their ratio, and whether the logs are identical. The
    arc's Jacobian and the bearing error's model stay compiled on both sides (they have no numpy twin)."""
    import contextlib

    from tubekit.loop import plan_check
    from tubekit.model import compiled_arcs
    from tubekit.model.errors import error_coordinates
    from tubekit.model.kinematics import unicycle_step
    from tubekit.plant import kinematic
    scenario = paper_scenario()
    if duration is not None:
        scenario = scenario.with_changes(duration=float(duration))
    tightening = verify.certify(scenario, law=scenario.controller.law).best_effort_tightening()
    _solver_import_s()
    uncompiled = {"rollout": _uncompiled_rollout, "unicycle_steps": unicycle_step, "arc": unicycle_step,
                  "error_coordinates": error_coordinates,
                  "plan_arcs": lambda x0, v, tau: plan_check._plan_arcs_chained(x0, v, tau[-1], len(tau) - 1)}
    compiled = {name: getattr(compiled_arcs, name) for name in uncompiled}
    new_step = kinematic.Plant.step_tuple

    def old_step(self, t, x, v, h, n, sway=0.0):  # the plant protocol's signature (the kinematic plant: sway 0)
        return kinematic.rk4_tuple(self._rhs, t, tuple(x), v, h, n)

    @contextlib.contextmanager
    def previous():
        kinematic.Plant.step_tuple = old_step
        for name, fn in uncompiled.items():
            setattr(compiled_arcs, name, fn)
        try:
            yield
        finally:
            kinematic.Plant.step_tuple = new_step
            for name, fn in compiled.items():
                setattr(compiled_arcs, name, fn)

    walls: dict[str, list[float]] = {"previous": [], "current": []}
    runs: dict = {}
    for rep in range(repeat):
        for name in (("previous", "current") if rep % 2 == 0 else ("current", "previous")):
            with previous() if name == "previous" else contextlib.nullcontext():
                w0 = time.perf_counter()
                runs[name] = run_closed_loop(scenario, tightening, tube=True, progress=False)
                walls[name].append(time.perf_counter() - w0)
    a, b = runs["previous"], runs["current"]
    same = all(np.array_equal(getattr(a, f), getattr(b, f), equal_nan=True)
               for f in ("states", "v_hat", "inputs", "rejected", "plan_slack", "nominal"))
    med = {k: float(np.median(v)) for k, v in walls.items()}
    return {"walls_s": walls, "median_s": med, "previous_over_current": med["previous"] / med["current"],
            "identical_logs": same}


def main(argv: list[str] | None = None) -> int:
    """CLI entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=None, help="simulated seconds (default: the scenario's)")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs; the median wall decides (default 3)")
    parser.add_argument("--json", default=None, help="write the figures to this file")
    parser.add_argument("--profile", action="store_true",
                        help="print a cProfile of the timed run (slows it) and add its breakdown by part")
    parser.add_argument("--floor", action="store_true",
                        help="add one run with the bare Clarabel time summed: the real-time factor's ceiling")
    parser.add_argument("--compare-previous", action="store_true",
                        help="interleave the uncompiled plant step, arcs and errors (numpy, Python) with the compiled ones instead")
    args = parser.parse_args(argv)
    out = compare_previous() if args.compare_previous else measure(args.duration, args.profile, args.repeat)
    if args.floor and not args.compare_previous:
        scenario = paper_scenario()
        tightening = verify.certify(scenario, law=scenario.controller.law).best_effort_tightening()
        out["floor"] = solver_floor(scenario, tightening)
    text = json.dumps(out, indent=2)
    print(text)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            fh.write(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
