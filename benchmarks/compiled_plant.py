"""What compiling the closed loop's glue with numba buys (issue 23): the kinematic plant's RK4, measured.

Usage::

    pip install numba && python benchmarks/compiled_plant.py [--calls 4000]

The kinematic plant's inner loop (:meth:`tubekit.plant.kinematic.Plant._rk4_fused`, already unrolled on
Python floats) is transcribed line by line into an ``@numba.njit`` kernel (:func:`rk4_kernel`, the same
floating-point operations in the same order, no fast-math) and both are called, interleaved, on the same
random (t, x, v) with the closed loop's step (h = 5 ms, 2 substeps). Reported: µs per call of each, their
ratio, the first call's compile time, and whether every result is bit-identical. numba is not a tubekit
dependency (the plant is about 8 % of a closed-loop run, ``python benchmarks/closed_loop.py --profile``);
this measures what it would buy.

A benchmark, not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from tubekit import paper_scenario
from tubekit.plant.kinematic import Plant

__all__ = ["rk4_kernel", "measure", "main"]


def _kernel_source(t, x0, x1, x2, x3, u, w, r, h, n, a0, a1, a2, c0, c1, c2, rate, samp, srate, gain):
    """:meth:`Plant._rk4_fused` on scalars (returns the state and the two disturbance peaks)."""
    sw = gain * u * r
    hh, h6 = 0.5 * h, h / 6.0
    p0, p1 = 0.0, 0.0
    s, c = math.sin(rate * t), math.cos(rate * t)
    e1, e2, e3, es = a0 * s + c0, a1 * c + c1, a2 * s + c2, sw + samp * math.sin(srate * t)
    for _ in range(n):
        tm, te = t + 0.5 * h, t + h
        d1, d2, d3, vs = e1, e2, e3, es
        s, c = math.sin(rate * tm), math.cos(rate * tm)
        m1, m2, m3, ms = a0 * s + c0, a1 * c + c1, a2 * s + c2, sw + samp * math.sin(srate * tm)
        s, c = math.sin(rate * te), math.cos(rate * te)
        e1, e2, e3, es = a0 * s + c0, a1 * c + c1, a2 * s + c2, sw + samp * math.sin(srate * te)
        sp, cp = math.sin(x3), math.cos(x3)
        o1, o2 = d1 - vs * sp, d2 + vs * cp
        p0, p1 = max(p0, math.hypot(o1, o2)), max(p1, abs(d3))
        k10, k11, k12 = u * cp + o1, u * sp + o2, w + d3
        q3 = x3 + hh * r
        sp, cp = math.sin(q3), math.cos(q3)
        o1, o2 = m1 - ms * sp, m2 + ms * cp
        p0, p1 = max(p0, math.hypot(o1, o2)), max(p1, abs(m3))
        k20, k21, k22 = u * cp + o1, u * sp + o2, w + m3
        k30, k31, k32 = k20, k21, k22
        q3 = x3 + h * r
        sp, cp = math.sin(q3), math.cos(q3)
        o1, o2 = e1 - es * sp, e2 + es * cp
        p0, p1 = max(p0, math.hypot(o1, o2)), max(p1, abs(e3))
        k40, k41, k42 = u * cp + o1, u * sp + o2, w + e3
        x0 = x0 + h6 * (k10 + 2.0 * k20 + 2.0 * k30 + k40)
        x1 = x1 + h6 * (k11 + 2.0 * k21 + 2.0 * k31 + k41)
        x2 = x2 + h6 * (k12 + 2.0 * k22 + 2.0 * k32 + k42)
        x3 = x3 + h6 * (r + 2.0 * r + 2.0 * r + r)
        t += h
    return x0, x1, x2, x3, p0, p1


def rk4_kernel():
    """The compiled kernel (imports numba; ImportError with the install hint when it is missing)."""
    try:
        import numba
    except ImportError as exc:  # a benchmark's optional peer
        raise ImportError("numba is needed for this benchmark: pip install numba") from exc
    return numba.njit(cache=False)(_kernel_source)


def measure(calls: int = 4000, seed: int = 0) -> dict:
    """Interleaved timing of the Python plant step and the compiled kernel on the same random arguments."""
    plant = Plant.of(paper_scenario())
    (a0, a1, a2), (c0, c1, c2) = plant._amplitude, plant._constant
    const = (a0, a1, a2, c0, c1, c2, plant._current_rate, plant._sway_amplitude, plant._sway_rate,
             plant._sway_gain)
    kernel = rk4_kernel()
    t0 = time.perf_counter()
    kernel(0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 0.1, 0.1, 0.005, 2, *const)
    compile_s = time.perf_counter() - t0
    rng = np.random.default_rng(seed)
    args = [(float(t), tuple(rng.normal(size=4)), tuple(rng.uniform(-0.4, 0.4, 3)))
            for t in rng.uniform(0.0, 100.0, calls)]
    identical = all(plant._rk4_fused(t, x, v, 0.005, 2) == kernel(t, *x, *v, 0.005, 2, *const)[:4]
                    for t, x, v in args)
    py, nb = [], []
    for rep in range(6):
        order = ("py", "nb") if rep % 2 == 0 else ("nb", "py")
        for name in order:
            w0 = time.perf_counter()
            if name == "py":
                for t, x, v in args:
                    plant._rk4_fused(t, x, v, 0.005, 2)
            else:
                for t, x, v in args:
                    kernel(t, *x, *v, 0.005, 2, *const)
            (py if name == "py" else nb).append(1e6 * (time.perf_counter() - w0) / calls)
    return {"calls": calls, "python_us": float(np.median(py)), "numba_us": float(np.median(nb)),
            "ratio": float(np.median(py) / np.median(nb)), "compile_s": compile_s, "bit_identical": identical}


def main(argv: list[str] | None = None) -> int:
    """CLI entry point."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=4000, help="random calls per pass (default 4000)")
    args = ap.parse_args(argv)
    print(json.dumps(measure(args.calls), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
