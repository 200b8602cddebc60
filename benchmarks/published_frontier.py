"""REMUS 100 over its whole published box, the thrust tied to the drag: which survey speeds and currents certify.

``examples/remus100_published.toml`` (the bundled box, ``top_speed`` tying each hull's propeller to its own drag,
``docs/verify.md`` section 9 step 7T) with, per cell, the target's speed P along x, the current c per horizontal
axis (5 mm/s in depth), the surge command u in [P − c − 0.13, P + c + 0.1] m/s (the law slows the vehicle by up to
the current, and needs a margin either side) and the yaw-rate limit r_max. A torpedo's terminal set lies far behind
the target, so each cell is certified twice: first with the start ``--probe`` m behind the target, then, when only
where X_f lies refused it (``initial_terminal``), with the start in the middle of the X_f that certificate found.
The rock is put out of the way (1 km off the line): this asks which speeds and currents the vehicle's loop and the
tracking theorem allow, not how near a rock may be (the file's own rock: ``docs/plant.md`` section 4).

``--around``: the shipped file itself with one field changed per row (the surge floor, the yaw-rate limit, the plans'
yaw rate, the heave limit, a trimmed start, the rock nearer, the thrust untied): the conditions that then fail.

Each row prints the tiers (``both``, ``safe``, ``none``), the failed conditions with their numbers, E and where X_f
lies (d range, m; the bearing's bound, rad). Nothing is timed.

Usage: ``python benchmarks/published_frontier.py [--speed 1.0 1.25 1.5] [--current 0.15 0.3] [--r-max 0.0048 0.008]
[--probe 30] [--around]`` (about 10 s per certificate).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import re
import sys
from pathlib import Path

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "remus100_published.toml"
SPEEDS, CURRENTS, R_MAX = (1.0, 1.25, 1.5), (0.15, 0.3), (0.0048, 0.008)

__all__ = ["survey", "certify_cell", "around", "row", "main", "SCENARIO"]


def survey(speed: float, current: float, r_max: float, start: float):
    """The shipped file re-set to one cell of the module doc, the start ``start`` m behind the target."""
    from tubekit import load_scenario
    from tubekit.scenario import Obstacle
    base = load_scenario(SCENARIO)
    return base.with_changes(**{
        "trajectory.direction_velocity": (speed, 0.0, 0.0), "limits.initial": (speed, 0.0, 0.0),
        "disturbance.amplitude": (current, current, 0.005), "limits.u_min": round(speed - current - 0.13, 3),
        "limits.u_max": round(speed + current + 0.1, 3), "limits.r_max": r_max,
        "initial_state": (-start, 0.0, 0.0, 0.0), "obstacles": (Obstacle((30.0 - start, 1000.0, 0.0), 0.5),),
        "workspace": ((-1500.0, -1200.0, -10.0), (900.0, 1200.0, 10.0)), "region.e_d_max": 1200.0})


def _terminal_set(text: str) -> tuple[float, float] | None:
    """(d_lo, d_hi) (m) of the X_f named in a certificate's text, or None."""
    found = re.search(r"X_f d in \[([0-9.]+), ([0-9.]+)\]", text)
    return (float(found.group(1)), float(found.group(2))) if found else None


def certify_cell(speed: float, current: float, r_max: float, probe: float = 30.0):
    """The cell's certificate (module doc): the start ``probe`` m behind, then, if where X_f lies refused it, in the
    middle of the X_f that certificate found."""
    import verify
    cert = verify.certify(survey(speed, current, r_max, probe))
    refused = next((c for c in cert.failures if c.condition == "initial_terminal"), None)
    found = _terminal_set(refused.detail) if refused is not None else None
    if found is not None:
        cert = verify.certify(survey(speed, current, r_max, 0.5 * (found[0] + found[1])))
    return cert


def around() -> dict:
    """The shipped file with one field changed per row (module doc), by name."""
    from tubekit import load_scenario
    from tubekit.scenario import Obstacle
    base = load_scenario(SCENARIO)
    rock = base.obstacles[0]
    untied = tuple((k, v) for k, v in base.plant.overrides if k != "top_speed")
    return {"as shipped": base, "u_min 0.58": base.with_changes(**{"limits.u_min": 0.58}),
            "r_max 0.005": base.with_changes(**{"limits.r_max": 0.005}),
            "yaw rate 0.0015": base.with_changes(**{"limits.rate": (0.05, 0.001, 0.0015)}),
            "w_max 0.005": base.with_changes(**{"limits.w_max": 0.005}),
            "started trimmed": base.with_changes(plant=dataclasses.replace(base.plant, start="trimmed")),
            "rock 160 m off": base.with_changes(obstacles=(Obstacle((rock.center[0], 160.0, 0.0), rock.radius),)),
            "untied": base.with_changes(plant=dataclasses.replace(base.plant, overrides=untied))}


def _number(x: float | None) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{x:.4g}"


def row(cert) -> str:
    """One row's text: tiers, failed conditions with their numbers, E and X_f."""
    tiers = "both" if cert.tiers.tracking else "safe" if cert.tiers.safe else "none"
    failed = "; ".join(f"{c.condition} {_number(c.lhs)} vs {_number(c.rhs)}" for c in cert.failures[:4])
    law = cert.design.terminal
    xf = "" if law is None else (f"X_f d in [{law.d_lo:.4g}, {law.d_hi:.4g}] m"
                                 + (f", bearing <= {law.bearing_max:.3g} rad" if law.has_bearing else ""))
    error = ", ".join(_number(e) for e in cert.velocity_loop.error)
    return f"{tiers} | {failed or '-'} | E = ({error}) | {xf or '-'}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed", type=float, nargs="+", default=list(SPEEDS), help="target speeds (m/s)")
    ap.add_argument("--current", type=float, nargs="+", default=list(CURRENTS), help="current per axis (m/s)")
    ap.add_argument("--r-max", type=float, nargs="+", default=list(R_MAX), help="yaw-rate limits (rad/s)")
    ap.add_argument("--probe", type=float, default=30.0, help="the first start's distance behind the target (m)")
    ap.add_argument("--around", action="store_true", help="the shipped file with one field changed per row")
    args = ap.parse_args(argv)
    if not all(x > 0 and math.isfinite(x) for x in [*args.speed, *args.current, *args.r_max, args.probe]):
        ap.error("--speed, --current, --r-max and --probe take finite numbers > 0")
    import verify
    if args.around:
        for name, scenario in around().items():
            print(f"| {name} | {row(verify.certify(scenario))} |", flush=True)
        return 0
    print("| target (m/s) | current (m/s) | r_max (rad/s) | tiers | failed | E | X_f |")
    print("|---" * 7 + "|")
    for speed in args.speed:
        for current in args.current:
            for r_max in args.r_max:
                cert = certify_cell(speed, current, r_max, args.probe)
                print(f"| {speed:g} | {current:g} | {r_max:g} | {row(cert)} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
