"""The pier at the owners' speed: how much of the published coefficient spread each current leaves certified.

Usage::

    python benchmarks/pier_spread.py [--current 0 0.02 0.04 0.06 0.08 0.1] [--steps 6]
                                     [--dt 0.01 --horizon 8 --behind 2.1]

On ``examples/bluerov2_pier_underway.toml`` (the BlueROV2 Heavy at 0.2 m/s, a pier whose surface is 3 m from the
path, a 0.2 s horizon of 25 ms steps, started under way), for each horizontal current per axis (``--current``, m/s;
the vertical stays the file's 0.1 m/s) and each of the plans' rates in :data:`RATES` (slowest first), the largest
share s of the published spread (``PlantSettings.shrunk(s)``: every interval of the bundled vehicle shrunk about its
midpoint to s of its half-width) at which ``verify.certify`` gives both tiers is bisected over [:data:`FLOOR`, 1]
(1 is tried first, then ``--steps`` halvings). A rate is bisected only where it certifies above the best share found
so far. Every share reported was itself certified; the bisection assumes a narrower box is no harder, and the share
is a lower bound of the frontier to within 2^-steps. ``--dt`` (s), ``--horizon`` (steps) and ``--behind`` (m, the
start's distance behind the target) change the file's MPC period, horizon and start for every cell. A study: nothing
timed, nothing shipped.

What it shows (``docs/plant.md`` section 4, "A pier 3 m off in 0.1 m/s of current"): each step of current costs
share of the box, because the loop's error grows with the box and the plans' rates the current asks, and the
surge row of the terminal law pays for both; the whole published spread holds only in still water.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tubekit.scenario import Scenario, load_scenario

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_pier_underway.toml"
#: The plans' rates tried (m/s², m/s², rad/s²), slowest first: a current needs faster plans for X_f's rows.
RATES = ((0.05, 0.03, 0.1), (0.1, 0.03, 0.2), (0.15, 0.03, 0.26), (0.18, 0.03, 0.3), (0.22, 0.03, 0.34))
#: The narrowest share tried: below it a rate is not bisected.
FLOOR = 0.05
#: The currents (m/s per horizontal axis) ``--current`` defaults to.
CURRENTS = (0.0, 0.02, 0.04, 0.06, 0.08, 0.1)

__all__ = ["SCENARIO", "RATES", "FLOOR", "CURRENTS", "at_share", "certified", "largest_share", "main"]


def at_share(share: float, current: float, rates: tuple[float, float, float],
             base: Scenario | None = None) -> Scenario:
    """The pier file with its vehicle's box at ``share`` of the published spread, ``current`` m/s of horizontal
    current per axis (the file's vertical kept) and the plans' ``rates``; its other vehicle overrides kept."""
    base = load_scenario(SCENARIO) if base is None else base
    vertical = base.disturbance.amplitude[2]
    return base.with_changes(plant=base.plant.shrunk(share), **{
        "disturbance.amplitude": (current, current, vertical), "limits.rate": tuple(rates)})


def certified(scenario: Scenario) -> tuple[bool, tuple[float, float, float]]:
    """(both tiers certified, the loop's error E in m/s, m/s, rad/s: inf where its bound did not close)."""
    from verify import certify
    cert = certify(scenario)
    return bool(cert.tiers.safe and cert.tiers.tracking), tuple(float(x) for x in cert.velocity_loop.error)


def largest_share(current: float, steps: int = 6, rates: tuple[tuple[float, float, float], ...] = RATES,
                  base: Scenario | None = None) -> dict:
    """The largest certified share of the published spread at ``current`` over ``rates``: a dict with ``share``
    (0.0 where none at :data:`FLOOR` certifies), ``rates`` and ``error`` (E at that share) of the best."""
    base = load_scenario(SCENARIO) if base is None else base
    best: dict = {"current": current, "share": 0.0, "rates": None, "error": None}
    for rate in rates:
        lo = max(best["share"], FLOOR)
        ok, error = certified(at_share(lo, current, rate, base))
        if not ok:
            continue
        top, top_error = certified(at_share(1.0, current, rate, base))
        if top:
            return {**best, "share": 1.0, "rates": rate, "error": top_error}
        hi = 1.0
        for _ in range(steps):
            mid = 0.5 * (lo + hi)
            ok_mid, error_mid = certified(at_share(mid, current, rate, base))
            lo, hi, error = (mid, hi, error_mid) if ok_mid else (lo, mid, error)
        if lo > best["share"]:
            best = {**best, "share": lo, "rates": rate, "error": error}
    return best


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--current", type=float, nargs="+", default=list(CURRENTS),
                    help="horizontal current per axis (m/s)")
    ap.add_argument("--steps", type=int, default=6, help="halvings of each bisection")
    ap.add_argument("--dt", type=float, default=None, help="the MPC period (s; default: the file's)")
    ap.add_argument("--horizon", type=int, default=None, help="the horizon (steps; default: the file's)")
    ap.add_argument("--behind", type=float, default=None, help="the start behind the target (m; default: the file's)")
    args = ap.parse_args(argv)
    base = load_scenario(SCENARIO)
    changes = {"controller.dt": args.dt, "controller.horizon_steps": args.horizon,
               "initial_state": None if args.behind is None else (-args.behind, 0.0, 0.0, 0.0)}
    base = base.with_changes(**{k: v for k, v in changes.items() if v is not None})
    print(f"{SCENARIO.name}: the largest share of the published spread with both tiers, per current; period "
          f"{base.controller.dt:g} s, {base.controller.horizon_steps} steps, start {-base.initial_state[0]:g} m behind")
    for current in args.current:
        found = largest_share(current, args.steps, base=base)
        if found["rates"] is None:
            print(f"  current {current:.3f} m/s: none at share {FLOOR:g}")
            continue
        e = ", ".join(f"{x:.3f}" for x in found["error"])
        print(f"  current {current:.3f} m/s: share {found['share']:.3f} with plans at {found['rates']}, "
              f"E = ({e})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
