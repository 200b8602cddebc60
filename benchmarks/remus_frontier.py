"""Where REMUS 100's velocity loop closes under a minimum surge: the frontier of a torpedo AUV at survey speed.

For each surge limit ū of a grid (with the minimum surge u_min = ū / 2, yaw rates up to ``--r-max``, heave up to
``--w-max``, plans rate-limited to ``--rate``) and each coefficient box (the midpoint of Prestero ↔ Fossen, that
box shrunk about its midpoint to a fraction of its half-widths, and the published box itself), the velocity
loop's bound is evaluated for the plans' jumps alone (``verify.vehicle.bound.velocity_loop_bound`` with
``surge_floor`` = u_min: the fins' authority over u >= u_min − E_u). A backup only adds jumps, so a cell whose loop
does not close here cannot certify with any backup. Each cell prints E (m/s, m/s, rad/s), the propeller's and the
fins' need against their floor (X, Z, N) and the loop's conditions that fail, or why the fixed point diverged (its
first-round growth and channel). Nothing is timed.

``--simulate`` adds what the vehicle does (no bound): the plant as simulated
(:class:`tubekit.plant.dynamic.DynamicPlant`) at the box's midpoint and at three random points of each box, no
current, the surge command held at ū and a yaw command sweeping ±``--r-max`` at the yaw rate limit for 60 s; the
largest loop errors |u_c − u|, |r_c − r|, the sway |v| and the rudder's largest share of its moment at the current
surge are printed.

Usage: ``python benchmarks/remus_frontier.py [--u-max 0.6 1.0 ...] [--spread 0 0.05 1] [--r-max R] [--w-max W]
[--rate RU RW RR] [--u-min U] [--yaw-bandwidth W] [--heave-bandwidth W] [--simulate]`` (``--u-min``: the surge
floor, default ū / 2; ``--yaw-bandwidth``, ``--heave-bandwidth``: those loops' bandwidths, rad/s, default the
vehicle's; well under a second per cell, about 20 s per simulated cell).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import re

import numpy as np

from tubekit.model.vehicles import vehicle_params
from tubekit.model.vehicle_params import VehicleParams
from tubekit.plant.dynamic import DynamicPlant
from tubekit.scenario import Scenario, scenario_from_dict
from verify.vehicle.bound import velocity_loop_bound

U_MAX = (0.6, 0.8, 1.0, 1.5, 2.0)
SPREADS = (0.0, 0.05, 1.0)
TICK, PERIOD = 0.01, 0.1


def cell(params: VehicleParams, u_max: float, r_max: float, w_max: float, rate: tuple[float, float, float],
         u_min: float | None = None) -> str:
    """One cell of the table (module doc); ``u_min`` None: ū / 2."""
    jumps = tuple(r * PERIOD for r in rate)
    floor = u_max / 2 if u_min is None else u_min
    bound = velocity_loop_bound(params, v_max=(u_max, w_max, r_max), tick=TICK, period=PERIOD,
                                jump_tick=(0.0, 0.0, 0.0), jump_period=jumps, first_command=(floor + jumps[0],
                                                                                             jumps[1], jumps[2]),
                                surge_floor=floor)
    by_name = {c.condition: c for c in bound.conditions}
    if not by_name["loop_fixed_point"].ok:
        growth = re.search(r"multiplied the bounds by up to ([0-9.e+]+) \((.*?)\)", by_name["loop_fixed_point"].detail)
        return "diverges" + (f" (x{growth.group(1)}, {growth.group(2)})" if growth else "")
    saturation = {ch: by_name[f"loop_saturation[{ch}]"] for ch in ("X", "Z", "N")}
    fins = "; ".join(f"{ch} need {c.lhs:.3g} vs {c.rhs:.3g}" for ch, c in saturation.items())
    verdict = "**closes, fins hold**" if all(c.ok for c in bound.conditions) else \
        "short: " + ", ".join(c.condition for c in bound.conditions if not c.ok)
    return f"E = ({bound.error[0]:.3f}, {bound.error[1]:.3f}, {bound.error[2]:.3f}); {fins}; {verdict}"


def still_water_scenario(params: VehicleParams) -> Scenario:
    """A dynamic-plant scenario of the vehicle ``params`` (a box or a point) in still water: no current, no sway
    disturbance, every other setting the default (what the simulated rows fly)."""
    return scenario_from_dict({"plant": {"kind": "dynamic", "vehicle": {
        k: v for k, v in params.to_dict().items() if k != "name"}},
        "disturbance": {"amplitude": [0.0, 0.0, 0.0], "sway": {"gain": 0.0, "bound": 0.0}}})


def simulated(params: VehicleParams, u_max: float, r_max: float, yaw_rate: float, seed: int | None,
              seconds: float = 60.0) -> tuple[float, float, float, float]:
    """(max |u_c − u|, max |r_c − r|, max |v|, max |N| / (|N_uuδr| u² δ_max)) (m/s, rad/s, m/s, the share of the
    rudder's moment at the current surge) of the plant at ``params``' midpoint (``seed`` None) or a random point of
    its box, surge command ``u_max``, yaw command sweeping ±``r_max`` at ``yaw_rate`` (rad/s²), reversing every
    15 s, no current (module doc)."""
    scenario = still_water_scenario(params)
    box = scenario.plant.params
    truth = box.nominal if seed is None else box.sample(np.random.default_rng(seed))
    plant = DynamicPlant(scenario, params=truth)
    pose, command, t, goal, worst = (0.0, 0.0, 0.0, 0.0), [u_max, 0.0, 0.0], 0.0, r_max, [0.0, 0.0, 0.0, 0.0]
    rudder = abs(truth.N_uudr) * truth.fin_max  # N m per (m/s)²
    for k in range(int(round(seconds / PERIOD))):
        if k % 150 == 0:
            goal = -goal
        command[2] += max(-yaw_rate * PERIOD, min(yaw_rate * PERIOD, goal - command[2]))
        for _ in range(int(round(PERIOD / TICK))):
            pose = plant.step_tuple(t, pose, tuple(command), TICK, 1)
            t += TICK
            nu = plant.state
            worst = [max(worst[0], abs(command[0] - nu[0])), max(worst[1], abs(command[2] - nu[3])),
                     max(worst[2], abs(nu[1])), max(worst[3], abs(nu[6]) / (rudder * nu[0] ** 2))]
    return worst[0], worst[1], worst[2], worst[3]


def simulated_rows(u_values, spreads, r_max: float, yaw_rate: float,
                   bandwidths: dict[str, float] | None = None) -> list[str]:
    """``--simulate``'s rows: the largest errors over the midpoint and three random points of each box (``bandwidths``
    as in :func:`table`)."""
    base = dataclasses.replace(vehicle_params("remus100"), **(bandwidths or {}))
    rows = [f"simulated: yaw command ±{r_max:g} rad/s at {yaw_rate:g} rad/s², 60 s, no current"]
    for f in spreads:
        params = base.shrunk(f)
        for u in u_values:
            runs = [simulated(params, u, r_max, yaw_rate, seed) for seed in ([None] if f == 0 else [None, 0, 1, 2])]
            worst = [max(r[i] for r in runs) for i in range(4)]
            rows.append(f"{f:>14g} | u_max {u:4.2f} | |u_c - u| <= {worst[0]:.4f} m/s, |r_c - r| <= {worst[1]:.4f} "
                        f"rad/s, |v| <= {worst[2]:.4f} m/s, rudder <= {worst[3]:.2f} of its moment")
    return rows


def table(u_values, spreads, r_max: float, w_max: float, rate, u_min: float | None = None,
          bandwidths: dict[str, float] | None = None) -> list[str]:
    """The rows (module doc), one per (box, ū); ``u_min`` None: ū / 2; ``bandwidths``: per-channel loop bandwidths
    (``VehicleParams`` field → rad/s) over the vehicle's own."""
    base = dataclasses.replace(vehicle_params("remus100"), **(bandwidths or {}))
    floor = "u_max / 2" if u_min is None else f"{u_min:g} m/s"
    rows = [f"REMUS 100, u_min = {floor}, |r| <= {r_max:g} rad/s, |w| <= {w_max:g} m/s, rate {list(rate)}"]
    for f in spreads:
        params = base.shrunk(f)
        label = "midpoint" if f == 0 else "published box" if f == 1 else f"box x{f:g}"
        for u in u_values:
            rows.append(f"{label:>14} | u_max {u:4.2f} | {cell(params, u, r_max, w_max, rate, u_min)}")
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--u-max", type=float, nargs="+", default=list(U_MAX))
    parser.add_argument("--spread", type=float, nargs="+", default=list(SPREADS),
                        help="fractions of the published half-widths (0: the midpoint, 1: the published box)")
    parser.add_argument("--r-max", type=float, default=0.1)
    parser.add_argument("--w-max", type=float, default=0.02)
    parser.add_argument("--rate", type=float, nargs=3, default=[0.05, 0.01, 0.02])
    parser.add_argument("--u-min", type=float, default=None, help="the surge floor (m/s; default u_max / 2)")
    parser.add_argument("--simulate", action="store_true", help="add the simulated plant's errors (no bound)")
    parser.add_argument("--yaw-bandwidth", type=float, default=None, help="the yaw loop's bandwidth (rad/s)")
    parser.add_argument("--heave-bandwidth", type=float, default=None, help="the heave loop's bandwidth (rad/s)")
    args = parser.parse_args(argv)
    if not all(math.isfinite(x) and x > 0 for x in [*args.u_max, args.r_max, args.w_max, *args.rate]):
        parser.error("speeds and rates must be finite and > 0")
    if args.u_min is not None and not (math.isfinite(args.u_min) and 0 < args.u_min < min(args.u_max)):
        parser.error("--u-min must be finite, > 0 and below every --u-max")
    given = (("yaw", args.yaw_bandwidth), ("heave", args.heave_bandwidth))
    bandwidths = {f"{name}_loop_bandwidth": value for name, value in given if value is not None}
    if not all(math.isfinite(x) and x > 0 for x in bandwidths.values()):
        parser.error("bandwidths must be finite and > 0")
    print("\n".join(table(args.u_max, args.spread, args.r_max, args.w_max, tuple(args.rate), args.u_min, bandwidths)))
    if args.simulate:
        print("\n".join(simulated_rows(args.u_max, args.spread, args.r_max, args.rate[2], bandwidths)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
