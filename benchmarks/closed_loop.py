"""Closed-loop speed of the tube run on the paper's scenario, and where a tick's time goes.

Usage::

    python benchmarks/closed_loop.py [--duration S] [--json FILE] [--profile]

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


def measure(duration: float | None = None, profile: bool = False) -> dict:
    """Certify (untimed), run the tube loop (timed) and break the time down; returns a JSON-ready dict."""
    scenario = paper_scenario()
    if duration is not None:
        from dataclasses import replace
        scenario = replace(scenario, duration=float(duration))
    c0 = time.perf_counter()
    tightening = verify.certify(scenario, law=scenario.controller.law).best_effort_tightening()
    certify_s = time.perf_counter() - c0
    profiler = cProfile.Profile() if profile else None
    w0 = time.perf_counter()
    if profiler is not None:
        profiler.enable()
    res = run_closed_loop(scenario, tightening, tube=True, progress=False)
    if profiler is not None:
        profiler.disable()
    wall_s = time.perf_counter() - w0
    out = {"scenario": scenario.name, "law": res.law, "simulated_s": float(scenario.duration),
           "wall_s": wall_s, "realtime_factor": float(scenario.duration) / wall_s, "certify_s_excluded": certify_s,
           "kappa_failures": int(res.kappa_failures), "breakdown": _breakdown(scenario, res)}
    if profiler is not None:
        pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(25)
    return out


def main(argv: list[str] | None = None) -> int:
    """CLI entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=None, help="simulated seconds (default: the scenario's)")
    parser.add_argument("--json", default=None, help="write the figures to this file")
    parser.add_argument("--profile", action="store_true", help="print a cProfile of the timed run (slows it)")
    args = parser.parse_args(argv)
    out = measure(args.duration, args.profile)
    text = json.dumps(out, indent=2)
    print(text)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            fh.write(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
