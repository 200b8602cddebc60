"""Where REMUS 100's velocity loop closes under a minimum surge: the frontier of a torpedo AUV at survey speed.

For each surge limit ū of a grid (with the minimum surge u_min = ū / 2, yaw rates up to ``--r-max``, heave up to
``--w-max``, plans rate-limited to ``--rate``) and each coefficient box (the midpoint of Prestero ↔ Fossen, that
box shrunk about its midpoint to a fraction of its half-widths, and the published box itself), the velocity
loop's bound is evaluated for the plans' jumps alone (``verify.vehicle.bound.velocity_loop_bound`` with
``surge_floor`` = u_min: the fins' authority over u >= u_min − E_u). A backup only adds jumps, so a cell whose loop
does not close here cannot certify with any backup. Each cell prints E (m/s, m/s, rad/s) and the fins' need
against their floor, or why the fixed point diverged (its first-round growth and channel). Nothing is timed.

Usage: ``python benchmarks/remus_frontier.py [--u-max 0.6 1.0 ...] [--spread 0 0.05 1] [--r-max R] [--w-max W]``
(well under a second per cell).
"""

from __future__ import annotations

import argparse
import math
import re

from tubekit.model.vehicles import vehicle_params
from tubekit.model.vehicle_params import VehicleParams
from verify.vehicle.bound import velocity_loop_bound

U_MAX = (0.6, 0.8, 1.0, 1.5, 2.0)
SPREADS = (0.0, 0.05, 1.0)
TICK, PERIOD = 0.01, 0.1


def shrunk(params: VehicleParams, fraction: float) -> VehicleParams:
    """``params`` with every interval shrunk about its midpoint to ``fraction`` of its half-width (0: the midpoint,
    1: the box itself)."""
    table = {}
    for key, value in params.to_dict().items():
        if isinstance(value, (list, tuple)) and len(value) == 2 and all(isinstance(x, float) for x in value):
            mid, half = (value[0] + value[1]) / 2, (value[1] - value[0]) / 2 * fraction
            value = [mid - half, mid + half] if half > 0 else mid
        table[key] = value
    return params.with_overrides({k: v for k, v in table.items() if k != "name"})


def cell(params: VehicleParams, u_max: float, r_max: float, w_max: float, rate: tuple[float, float, float]) -> str:
    """One cell of the table (module doc)."""
    jumps = tuple(r * PERIOD for r in rate)
    bound = velocity_loop_bound(params, v_max=(u_max, w_max, r_max), tick=TICK, period=PERIOD,
                                jump_tick=(0.0, 0.0, 0.0), jump_period=jumps, first_command=(u_max / 2 + jumps[0],
                                                                                             jumps[1], jumps[2]),
                                surge_floor=u_max / 2)
    by_name = {c.condition: c for c in bound.conditions}
    if not by_name["loop_fixed_point"].ok:
        growth = re.search(r"multiplied the bounds by up to ([0-9.e+]+) \((.*?)\)", by_name["loop_fixed_point"].detail)
        return "diverges" + (f" (x{growth.group(1)}, {growth.group(2)})" if growth else "")
    fins = "; ".join(f"{ch} need {by_name[f'loop_saturation[{ch}]'].lhs:.3g} vs {by_name[f'loop_saturation[{ch}]'].rhs:.3g}"
                     for ch in ("Z", "N"))
    return f"E = ({bound.error[0]:.3f}, {bound.error[1]:.3f}, {bound.error[2]:.3f}); {fins}"


def table(u_values, spreads, r_max: float, w_max: float, rate) -> list[str]:
    """The rows (module doc), one per (box, ū)."""
    base = vehicle_params("remus100")
    rows = [f"REMUS 100, u_min = u_max / 2, |r| <= {r_max:g} rad/s, |w| <= {w_max:g} m/s, rate {list(rate)}"]
    for f in spreads:
        params = shrunk(base, f)
        label = "midpoint" if f == 0 else "published box" if f == 1 else f"box x{f:g}"
        for u in u_values:
            rows.append(f"{label:>14} | u_max {u:4.2f} | {cell(params, u, r_max, w_max, rate)}")
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--u-max", type=float, nargs="+", default=list(U_MAX))
    parser.add_argument("--spread", type=float, nargs="+", default=list(SPREADS),
                        help="fractions of the published half-widths (0: the midpoint, 1: the published box)")
    parser.add_argument("--r-max", type=float, default=0.1)
    parser.add_argument("--w-max", type=float, default=0.02)
    parser.add_argument("--rate", type=float, nargs=3, default=[0.05, 0.01, 0.02])
    args = parser.parse_args(argv)
    if not all(math.isfinite(x) and x > 0 for x in [*args.u_max, args.r_max, args.w_max, *args.rate]):
        parser.error("speeds and rates must be finite and > 0")
    print("\n".join(table(args.u_max, args.spread, args.r_max, args.w_max, tuple(args.rate))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
