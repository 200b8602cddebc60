"""Where a vehicle that must keep moving certifies at survey speed, the velocity loop aside: the kinematic frontier.

The survey target of the torpedo issue is a line at >= 1 m/s in >= 0.3 m/s of current, with a minimum surge, the
loiter backup, ε <= 3 m and an obstacle within 5 m of the path. REMUS 100's velocity loop does not close there
(``benchmarks/remus_frontier.py``); this study asks what the rest of the theorem gives on the kinematic plant (the
paper's model, no velocity loop): the minimum-surge tube, the loiter's certified safe set, and the tracking tier
through the terminal set's bearing face (``docs/verify.md`` steps 13e, 17b). For each target speed P and current
amplitude c (per horizontal axis; 0.05 m/s in depth) ``examples/keep_moving_tracked.toml`` is re-set to a survey:
a line at P along x, u_min ``--u-min``, u_max ``--u-max``, r_max ``--r-max``, ε ``--epsilon``, e_d <= ε + 5 m, the start
2 m behind the target's ε, and one obstacle (radius 0.5 m) whose centre is ``--offset`` m off the path, at
x = ``--rock-x`` m (default 40 m ahead of the target's start; with a start far behind, put it where the vehicle
passes within the run's 60 s, or it never stands in the vehicle's way).
Each cell prints the tiers (``both``, ``safe``, or the first failed conditions) and the loiter's certified radius.
Nothing is timed.

``--backup none``: no backup law (``docs/verify.md`` step 13g); the completion's footprint is then X_f's own, the
sector behind the target that its bearing face allows (step 17b), with no loiter about its end.

``--rate RU RW RR``: plans limited to these rates (``limits.rate``; a vehicle whose velocity loop is inside the
theorem needs them, ``docs/verify.md`` step 17c), the terminal set then with its row faces and its bearing face
together (``verify.theorem.terminal_bearing.bearing_row_sets``); ``--start``: the start's distance behind the target.

``--clearing``: under each cell refused by ``path_clearance``, the refused footprint's sector and the largest
half-angle or reach that would clear the obstacle (:func:`clearing`).

``--nearest TOP``: under each cell, the nearest the obstacle may stand to the path with both tiers certified, on a
grid of ``--nearest-step`` m in [0, TOP] (:func:`nearest`: a bisection, the obstacle being no harder to keep clear
the farther it stands; "none" when it does not certify at TOP either). Each step is one certificate.

``--vehicle NAME``: the dynamic plant instead (``[plant] kind = "dynamic"``, the bundled vehicle's box shrunk about
its midpoint to ``--spread`` of its half-widths, :meth:`tubekit.model.vehicle_params.VehicleParams.shrunk`; 0: the
midpoint, 1: the published box), with ``--w-max`` and the vertical current ``--current-z``: the velocity loop's
bound then enters every cell. ``--yaw-bandwidth W``: its yaw loop at W rad/s (``yaw_loop_bandwidth``; the other
channels keep the vehicle's ``loop_bandwidth``); ``--heave-bandwidth W``: its heave loop likewise.

Usage: ``python benchmarks/survey_frontier.py [--speed 0.6 1.0 1.5] [--current 0.1 0.2 0.3] [--offset 5 30]
[--backup none] [--rate 0.5 0.5 1.0] [--start 7] [--e-d-max 60] [--sensing 150] [--vehicle remus100 --spread 0
--w-max 0.015 --current-z 0.005 --yaw-bandwidth 10] [--nearest 40 --nearest-step 0.5]`` (about a second per cell;
a few on the dynamic plant).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "keep_moving_tracked.toml"
SPEEDS = (0.6, 1.0, 1.5)
CURRENTS = (0.1, 0.2, 0.3)
OFFSETS = (5.0, 30.0)

__all__ = ["survey", "cell", "clearing", "nearest", "main"]


def survey(speed: float, current: float, offset: float, *, u_min: float = 0.5, u_max: float = 2.0,
           r_max: float = 0.2, epsilon: float = 3.0, backup: str = "loiter",
           rate: tuple[float, float, float] | None = None, start: float | None = None,
           e_d_max: float | None = None, sensing: float = 80.0, vehicle: str | None = None,
           spread: float = 0.0, w_max: float | None = None, current_z: float = 0.05, yaw_bandwidth: float = 0.0,
           heave_bandwidth: float = 0.0, rock_x: float = 40.0):
    """The survey scenario of the module doc (a :class:`tubekit.scenario.Scenario`), with ``controller.backup``
    ``backup`` (the loiter, or ``none``: the safe tier as the tracking tier's corollary). ``rate``: the plans'
    rate limit (m/s², m/s², rad/s²; ``limits.rate``), the command before t = 0 then the target's speed ahead;
    ``start``: the start's distance behind the target (m; default ε + 2); ``e_d_max``: ``region.e_d_max`` (m;
    default ε + 5); ``sensing``: ``sensing_range`` (m); ``vehicle``: a bundled vehicle's name for the dynamic plant,
    its box shrunk to ``spread`` (module doc); ``w_max``: ``limits.w_max`` (m/s; default the example's);
    ``current_z``: the vertical current's amplitude (m/s); ``yaw_bandwidth``, ``heave_bandwidth``: the vehicle's
    ``yaw_loop_bandwidth``, ``heave_loop_bandwidth`` (rad/s; 0: its ``loop_bandwidth``); ``rock_x``: the obstacle's
    position along the path (m; the target starts at 0, the vehicle ``start`` behind it: a rock must lie where the
    vehicle passes within the run's 60 s to stand in its way)."""
    from tubekit import load_scenario
    from tubekit.model.trajectory import Line
    from tubekit.scenario import Obstacle

    behind = epsilon + 2.0 if start is None else start
    limits = {} if rate is None else {"limits.rate": tuple(rate), "limits.initial": (speed, 0.0, 0.0)}
    if w_max is not None:
        limits["limits.w_max"] = w_max
    scenario = load_scenario(SCENARIO).with_changes(
        name="survey", trajectory=Line(start=(0.0, 0.0, 0.0), direction_velocity=(speed, 0.0, 0.0)),
        obstacles=(Obstacle((rock_x, offset, 0.0), 0.5),), epsilon=epsilon, duration=60.0, sensing_range=sensing,
        workspace=((-100.0, -100.0, -10.0), (300.0, 100.0, 10.0)), initial_state=(-behind, 0.0, 0.0, 0.0),
        **{"limits.u_max": u_max, "limits.u_min": u_min, "limits.r_max": r_max, "controller.backup": backup,
           "disturbance.amplitude": (current, current, current_z),
           "region.e_d_max": epsilon + 5.0 if e_d_max is None else e_d_max}, **limits)
    if vehicle is None:
        return scenario
    from tubekit.model.vehicles import vehicle_params
    from tubekit.scenario import scenario_from_dict

    table = scenario.to_dict()
    box = vehicle_params(vehicle).shrunk(spread).to_dict()
    box["yaw_loop_bandwidth"], box["heave_loop_bandwidth"] = yaw_bandwidth, heave_bandwidth
    table["plant"] = {"kind": "dynamic", "vehicle": {k: v for k, v in box.items() if k != "name"}}
    return scenario_from_dict(table)


def cell(speed: float, current: float, offset: float, **limits: float | str | tuple[float, float, float] | None
         ) -> dict:
    """The verdict of one cell: ``tiers`` (both / safe / none), the failed conditions, the loiter's radius (m) and
    the yaw-rate error the tracking design assumes (rad/s; 0 on the kinematic plant)."""
    import verify

    cert = verify.certify(survey(speed, current, offset, **limits))
    tiers = "both" if cert.tiers.tracking else "safe" if cert.tiers.safe else "none"
    loiter = cert.backup is not None and cert.backup.law.kind == "loiter"
    radius = cert.backup.safe_set.radius if loiter else None
    return {"tiers": tiers, "failed": [c.condition for c in cert.failures], "loiter_radius": radius,
            "yaw_error": float(cert.design.problem.yaw_rate_error)}


def clearing(speed: float, current: float, offset: float, **limits: float | str | tuple[float, float, float] | None
             ) -> dict | None:
    """Where a cell fails ``path_clearance``, what its terminal set's footprint would have to lose: the last
    footprint the search measured and refused (the narrowest set's, the one the certificate reports), its half-angle
    ``cone`` (rad), sector ``reach`` (m), ``ball`` and ``arc_pad`` (m, the pads about the arc's sector), the largest
    half-angle at that reach (``clearing_cone``) and the largest reach at that half-angle (``clearing_reach``) that
    clear every obstacle (bisected to 1e-6 of each with :func:`verify.theorem.path_clearance.path_clearance`, the
    search's own check), the ``shortfall`` (m) and the condition's ``detail``. None when no footprint was refused."""
    import dataclasses

    import verify
    import verify.theorem.terminal as terminal
    from verify.theorem.path_clearance import horizon_end, path_clearance

    sc = survey(speed, current, offset, **limits)
    refused = []
    measured = terminal.path_clearance

    def recorded(scenario, foot, t_end, **how):
        out = measured(scenario, foot, t_end, **how)
        if not all(c.ok for c in out):
            refused.append((foot, out))
        return out
    terminal.path_clearance = recorded  # a study's probe, restored below
    try:
        verify.certify(sc)
    finally:
        terminal.path_clearance = measured
    if not refused:
        return None
    foot, conds = refused[-1]
    t_end = horizon_end(sc)

    def clears(**fields: float) -> bool:
        return all(c.ok for c in path_clearance(sc, dataclasses.replace(foot, **fields), t_end))

    def scaled(share: float) -> dict:
        return {"cone_reach": share * foot.cone_reach, "reach": foot.reach - (1 - share) * foot.cone_reach,
                "cone_outer": share * foot.cone_outer, "outer": foot.outer - (1 - share) * foot.cone_outer}
    return {"cone": foot.cone, "reach": foot.cone_reach, "ball": foot.ball, "arc_pad": foot.reach - foot.cone_reach,
            "shortfall": -min(c.lhs for c in conds if not c.ok),
            "detail": next(c.detail for c in conds if not c.ok),
            "clearing_cone": _largest(lambda x: clears(cone=x), foot.cone),
            "clearing_reach": _largest(lambda x: clears(**scaled(x)), 1.0) * foot.cone_reach}


def nearest(speed: float, current: float, top: float, step: float = 0.5,
            **limits: float | str | tuple[float, float, float] | None) -> float | None:
    """The smallest obstacle offset (m) on the grid k ``step``, k >= 0, up to ``top``, at which :func:`cell` gives
    both tiers; None when ``top`` does not (then no offset of the grid does). The obstacle moves straight away from
    the path, so every footprint that cleared it still clears it and the search's first set is kept: both tiers at
    one offset hold at every farther one, and a bisection over the grid finds the edge."""
    if not (step > 0.0 and top >= 0.0):
        raise ValueError(f"nearest: need step > 0 and top >= 0, got step {step}, top {top}")
    return _smallest(lambda offset: cell(speed, current, offset, **limits)["tiers"] == "both", top, step)


def _smallest(holds: Callable[[float], bool], top: float, step: float) -> float | None:
    """The smallest x = k ``step`` <= ``top`` with ``holds(x)``, for ``holds`` monotone (false below, true above);
    None when ``holds(top)`` is false. About log2(top / step) + 1 calls."""
    last = int(top / step + 1e-9)
    if not holds(last * step):
        return None
    lo, hi = 0, last  # holds at hi
    while lo < hi:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if holds(mid * step) else (mid + 1, hi)
    return hi * step


def _largest(holds: Callable[[float], bool], top: float) -> float:
    """The largest x in [0, ``top``] with ``holds(x)`` (holds is monotone: true below, false above), to 1e-6 of top."""
    lo, hi = 0.0, top
    while hi - lo > 1e-6 * top:
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if holds(mid) else (lo, mid)
    return lo


def _text(res: dict) -> str:
    notes = "" if res["loiter_radius"] is None else f" (loiter {res['loiter_radius']:.3g} m)"
    notes += f" (E_r {res['yaw_error']:.3g} rad/s)" if res["yaw_error"] > 0 else ""
    if res["tiers"] == "both":
        return "both" + notes
    head = "safe; tracking: " if res["tiers"] == "safe" else ""
    return head + ", ".join(res["failed"][:3]) + notes


def _clearing_text(speed: float, current: float, res: dict | None) -> str:
    where = f"  {speed:g} m/s in {current:g} m/s: "
    if res is None:
        return where + "no footprint refused by path_clearance"
    return (where + f"X_f's sector {res['cone']:.3g} rad, {res['reach']:.3g} m, short by {res['shortfall']:.3g} m; "
            f"it clears with a half-angle <= {res['clearing_cone']:.4g} rad at that reach, or a reach <= "
            f"{res['clearing_reach']:.4g} m at that half-angle")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed", type=float, nargs="+", default=list(SPEEDS), help="target speeds (m/s)")
    ap.add_argument("--current", type=float, nargs="+", default=list(CURRENTS), help="current per axis (m/s)")
    ap.add_argument("--offset", type=float, nargs="+", default=list(OFFSETS), help="obstacle off the path (m)")
    ap.add_argument("--u-min", type=float, default=0.5)
    ap.add_argument("--u-max", type=float, default=2.0)
    ap.add_argument("--r-max", type=float, default=0.2)
    ap.add_argument("--epsilon", type=float, default=3.0)
    ap.add_argument("--backup", default="loiter", help="controller.backup: loiter (default) or none")
    ap.add_argument("--rate", type=float, nargs=3, default=None, help="the plans' rate limit (m/s², m/s², rad/s²)")
    ap.add_argument("--start", type=float, default=None, help="the start's distance behind the target (m)")
    ap.add_argument("--e-d-max", type=float, default=None, help="region.e_d_max (m; default epsilon + 5)")
    ap.add_argument("--sensing", type=float, default=80.0, help="sensing_range (m)")
    ap.add_argument("--vehicle", default=None, help="the dynamic plant with this bundled vehicle (e.g. remus100)")
    ap.add_argument("--spread", type=float, default=0.0, help="its box shrunk to this fraction (0: the midpoint)")
    ap.add_argument("--w-max", type=float, default=None, help="limits.w_max (m/s)")
    ap.add_argument("--current-z", type=float, default=0.05, help="the vertical current's amplitude (m/s)")
    ap.add_argument("--yaw-bandwidth", type=float, default=0.0,
                    help="plant.vehicle.yaw_loop_bandwidth (rad/s; 0: the vehicle's loop_bandwidth)")
    ap.add_argument("--heave-bandwidth", type=float, default=0.0,
                    help="plant.vehicle.heave_loop_bandwidth (rad/s; 0: the vehicle's loop_bandwidth)")
    ap.add_argument("--rock-x", type=float, default=40.0,
                    help="the obstacle's position along the path (m; the target starts at 0)")
    ap.add_argument("--clearing", action="store_true",
                    help="under each cell refused by path_clearance, what its X_f's footprint would have to lose")
    ap.add_argument("--nearest", type=float, default=None, metavar="TOP",
                    help="under each cell, the nearest offset (m, up to TOP) with both tiers")
    ap.add_argument("--nearest-step", type=float, default=0.5, help="the grid of --nearest (m)")
    args = ap.parse_args(argv)
    if args.nearest is not None and not (args.nearest >= 0.0 and args.nearest_step > 0.0):
        ap.error("--nearest needs TOP >= 0 and --nearest-step > 0")
    limits = {"u_min": args.u_min, "u_max": args.u_max, "r_max": args.r_max, "epsilon": args.epsilon,
              "backup": args.backup, "rate": args.rate, "start": args.start, "e_d_max": args.e_d_max,
              "sensing": args.sensing, "vehicle": args.vehicle, "spread": args.spread, "w_max": args.w_max,
              "current_z": args.current_z, "yaw_bandwidth": args.yaw_bandwidth,
              "heave_bandwidth": args.heave_bandwidth, "rock_x": args.rock_x}
    for offset in args.offset:
        print(f"obstacle {offset:g} m off the path at x = {args.rock_x:g} m; u_min {args.u_min:g}, "
              f"u_max {args.u_max:g} m/s, "
              f"r_max {args.r_max:g} rad/s, epsilon {args.epsilon:g} m, backup {args.backup}, "
              f"plans' rate {args.rate or 'none'}, start {args.start or args.epsilon + 2.0:g} m behind, "
              f"e_d_max {args.e_d_max or args.epsilon + 5.0:g} m, sensing {args.sensing:g} m"
              + ("" if args.vehicle is None else f"; dynamic plant: {args.vehicle}, box x{args.spread:g}, "
                 f"w_max {args.w_max}, vertical current {args.current_z:g} m/s, yaw loop "
                 f"{args.yaw_bandwidth or 'as the others'} rad/s"))
        print("| target (m/s) \\ current (m/s) | " + " | ".join(f"{c:g}" for c in args.current) + " |")
        print("|---" * (len(args.current) + 1) + "|")
        for speed in args.speed:
            cells = [cell(speed, c, offset, **limits) for c in args.current]
            print(f"| {speed:g} | " + " | ".join(_text(res) for res in cells) + " |")
            for c, res in zip(args.current, cells):
                if args.clearing and any(name.startswith("path_clearance") for name in res["failed"]):
                    print(_clearing_text(speed, c, clearing(speed, c, offset, **limits)))
                if args.nearest is not None:
                    edge = nearest(speed, c, args.nearest, args.nearest_step, **limits)
                    print(f"  {speed:g} m/s in {c:g} m/s: both tiers with the obstacle "
                          + (f"{edge:g} m off the path or farther" if edge is not None else
                             f"nowhere up to {args.nearest:g} m off the path"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
