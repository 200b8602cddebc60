"""What the compiled period buys the FHOCP step: the numba routines against the numpy functions they replaced,
alternated in one process.

Usage::

    python benchmarks/compiled_period.py [--duration 100] [--rounds 4] [--json FILE]

The numpy functions the compiled routines of :mod:`tubekit.model.compiled_arcs` replaced (the rollout, the
step's Jacobian and the bearing error's model as they were in commit 9a08e00; the error coordinates and the
exact step of :mod:`tubekit.model`) are put back in their place for every other round (:func:`numpy_kernels`),
and benchmark v2's round robin (``benchmarks/fhocp.py``: every method at every state of a closed loop of
Section VI, the order rotated per state) is replayed with fresh solvers each round. Both sides run in the
same process on the same states, so what differs between the rounds is the kernels alone (separate processes
scatter more than the difference). Reported per round: the median whole step of the real-time and the
converged SCP (ms), and whether both sides' plans are the very same floats.

Since the compiled rows (``benchmarks/compiled_step.py``), the SCP's subproblem takes the step's Jacobian and the
bearing error's model inside :func:`tubekit.fhocp.compiled_rows.subproblem_rows`, which calls the compiled routines
directly: the numpy side here swaps them for the public linearisations only, no longer for the step it times.

A benchmark, not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import sys
from pathlib import Path
from types import ModuleType
from typing import Iterator

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import fhocp as v2  # noqa: E402  (the sibling benchmark: its closed loop, methods and replay)

from tubekit import paper_scenario  # noqa: E402
from tubekit.model import compiled_arcs  # noqa: E402
from tubekit.model.errors import error_coordinates  # noqa: E402
from tubekit.model.kinematics import dsinc, sinc, unicycle_step  # noqa: E402

__all__ = ["numpy_rollout", "numpy_step_linearisation", "numpy_eo_linearisation", "swapped", "numpy_kernels",
           "measure", "main"]


def numpy_rollout(s0: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """The vectorised numpy rollout (N+1, 4) the compiled one replaced (cumulative sums of the exact steps)."""
    inputs = np.asarray(inputs, dtype=float)
    out = np.empty((inputs.shape[0] + 1, 4))
    out[0] = s0
    a = (0.5 * dt) * inputs[:, 2]
    out[1:, 3] = dt * inputs[:, 2]
    out[1:, 2] = dt * inputs[:, 1]
    out[:, 2:].cumsum(axis=0, out=out[:, 2:])
    th = out[:-1, 3] + a
    k = (dt * inputs[:, 0]) * sinc(a)
    out[1:, 0] = k * np.cos(th)
    out[1:, 1] = k * np.sin(th)
    out[:, :2].cumsum(axis=0, out=out[:, :2])
    return out


def numpy_step_linearisation(states: np.ndarray, inputs: np.ndarray, dt: float) -> np.ndarray:
    """The numpy rows ``ax, bxu, bxr, cx, ay, byu, byr, cy`` (8, N) the compiled Jacobian replaced."""
    n = inputs.shape[0]
    psi, u, r = states[:n, 3], inputs[:, 0], inputs[:, 2]
    a = 0.5 * dt * r
    sa, dsa = sinc(a), dsinc(a)
    c, s = np.cos(psi + a), np.sin(psi + a)
    out = np.empty((8, n))
    out[1], out[5] = dt * sa * c, dt * sa * s
    dx, dy = u * out[1], u * out[5]
    out[0], out[4] = -dy, dx
    half = 0.5 * dt * dt * u
    out[2], out[6] = half * (dsa * c - sa * s), half * (dsa * s + sa * c)
    out[3], out[7] = dy * psi - out[2] * r, -dx * psi - out[6] * r
    return out


def numpy_eo_linearisation(states: np.ndarray, ref: np.ndarray, floor: float) -> np.ndarray:
    """The numpy rows ``gx, gy, gpsi, h, e_o`` (5, K) the compiled bearing-error model replaced."""
    ex, ey, psi = states[:, 0] - ref[:, 0], states[:, 1] - ref[:, 1], states[:, 3]
    ed = np.maximum(np.sqrt(ex * ex + ey * ey), floor)
    cp, sp = np.cos(psi), np.sin(psi)
    out = np.empty((5, states.shape[0]))
    c = ex * cp + ey * sp
    out[4] = (ex * sp - ey * cp) / ed
    cd = c / (ed * ed * ed)
    out[0], out[1], out[2] = ey * cd, -ex * cd, c / ed
    out[3] = out[4] - out[0] * states[:, 0] - out[1] * states[:, 1] - out[2] * psi
    return out


NUMPY = {"rollout": numpy_rollout, "step_linearisation": numpy_step_linearisation,
         "eo_linearisation": numpy_eo_linearisation, "error_coordinates": error_coordinates,
         "unicycle_steps": unicycle_step}


@contextlib.contextmanager
def swapped(module: ModuleType, replacements: dict) -> Iterator[None]:
    """``module``'s attributes named in ``replacements`` replaced by their values, and put back at the end."""
    kept = {name: getattr(module, name) for name in replacements}
    for name, fn in replacements.items():
        setattr(module, name, fn)
    try:
        yield
    finally:
        for name, fn in kept.items():
            setattr(module, name, fn)


def numpy_kernels() -> contextlib.AbstractContextManager:
    """The numpy functions in the compiled routines' place (every caller looks them up at the call)."""
    return swapped(compiled_arcs, NUMPY)


def measure(duration: float = 100.0, rounds: int = 4) -> dict:
    """Alternate the two sides ``rounds`` times each on benchmark v2's round robin; a JSON-ready dict."""
    sc = paper_scenario()
    tg = v2.benchmark_tightening(sc)
    states = v2.closed_loop(sc, tg, duration, v2.DEFAULT_RATE_PENALTY)
    out: dict = {"states": len(states), "rounds": []}
    plans: dict[str, list] = {}
    for k in range(2 * rounds):
        side = ("compiled", "numpy")[(k + k // 2) % 2]  # compiled, numpy, numpy, compiled, ...
        with numpy_kernels() if side == "numpy" else contextlib.nullcontext():
            methods = v2.make_methods(sc, tg, with_casadi=False)
            gc.disable()
            try:
                rec = v2.replay(methods, states)
            finally:
                gc.enable()
            plans.setdefault(side, [methods["scp_realtime"][0].plan_inputs])
        out["rounds"].append({"side": side, **{f"{name}_median_ms": float(1e3 * np.median(rec[name]["step"]))
                                              for name in ("scp_realtime", "scp_converged")}})
    for name in ("scp_realtime", "scp_converged"):
        for side in ("compiled", "numpy"):
            out[f"{name}_{side}_median_ms"] = float(np.median([r[f"{name}_median_ms"] for r in out["rounds"]
                                                               if r["side"] == side]))
    out["same_last_plan"] = bool(np.array_equal(plans["compiled"][0], plans["numpy"][0]))
    return out


def main(argv: list[str] | None = None) -> int:
    """CLI entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=100.0, help="closed-loop seconds (one state per period)")
    parser.add_argument("--rounds", type=int, default=4, help="rounds per side, alternated (default 4)")
    parser.add_argument("--json", default=None, help="write the figures to this file")
    args = parser.parse_args(argv)
    out = measure(args.duration, args.rounds)
    for r in out["rounds"]:
        print(f"{r['side']:9s} real-time {r['scp_realtime_median_ms']:.3f} ms, converged "
              f"{r['scp_converged_median_ms']:.3f} ms")
    print(json.dumps({k: v for k, v in out.items() if k != "rounds"}, indent=2))
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
