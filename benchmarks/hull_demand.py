"""What a command box asks of the hull itself: the rudder and the propeller needed to follow an admissible command.

A certificate on the dynamic plant proves that the loop never saturates (``loop_saturation[X|Z|N]``) under *every*
command the plans and the tube may give: any surge in [u_min, u_max], any yaw rate in [−r_max, r_max], each
changing by at most the plans' rates. If one point hull of the coefficient box needs more than its own actuator to
follow one such command exactly, no loop bound, however sharp, can certify that command box over that box: the
velocity loop is not what stands in the way, the hull is. This study measures that need; it proves nothing.

**The rudder.** At a constant surge u (the surge floor, where a fin is weakest) the yaw command holds −r_max until
the sway has settled, then ramps to +r_max at the plans' yaw rate ρ_r and holds there. A hull that follows it
exactly has r(t) as commanded, its sway from the sway row with no lateral force and its yaw moment from the yaw row
(``tubekit.plant.dynamic``: M ν̇ + n(ν) = τ, w = 0, u̇ = 0):

    m22 v̇ = −n2(ν) − m24 ṙ,          N(t) = m42 v̇ + m44 ṙ + n4(ν),

integrated by ``scipy.integrate.solve_ivp`` from the steady sway at −r_max (the root of n2 = 0,
``benchmarks/steady_turn.py``). The need is the largest |N(t)| at the solver's points and at the ramp's two ends
(a witness time, so a lower bound on the sup), against the hull's rudder |N_uuδr| u² δ_max. It is evaluated at each
corner of the box's intervals among :data:`YAW_FIELDS` (the mass and inertia entries, the sway and yaw damping, the
rudder; the bundled REMUS 100: 2^10 corners), the other coefficients at their midpoints.

**The propeller.** At the instant a surge command ramping at ρ_u reaches u_max on a straight run the hull needs
X = m11 ρ_u + n1(u_max, 0, 0, 0) = m11 ρ_u + |X_u| u_max + |X_uu| u_max², against its thrust: X_max, or with a top
speed s tied to its drag (``[plant.vehicle] top_speed``, ``docs/verify.md`` section 9 step 7T) |X_u| s + |X_uu| s²
at the slowest top speed. The worst corner of (m, X_udot, X_u, X_uu, X_max) is found the same way.

``--simulate``: the closed loop itself (:class:`tubekit.plant.dynamic.DynamicPlant`, saturation and all) at the
corner that needs most, under the same yaw command: the largest |r_c − r| and the time its rudder spends at its
limit (a run that saturates is a counterexample to ``loop_saturation[N]`` for that command box and box).

Usage: ``python benchmarks/hull_demand.py [--vehicle remus100] [--u-min 1.07] [--u-max 1.9] [--r-max 0.1]
[--rate 0.3 0.005 0.1] [--top-speed 2.497] [--simulate]`` (about 30 s for the corners; ``--simulate`` a second more).
Nothing is timed.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

__all__ = ["YawDemand", "yaw_demand", "surge_demand", "corner_points", "worst_yaw", "simulated_ramp", "YAW_FIELDS",
           "SURGE_FIELDS", "main"]

#: The box's coefficients that enter the sway and yaw rows and the rudder (the yaw demand's corners).
YAW_FIELDS = ("m", "I_zz", "X_udot", "Y_vdot", "Y_rdot", "N_rdot", "Y_v", "Y_vv", "Y_rr", "N_r", "N_vv", "N_rr",
              "N_uudr")
#: The coefficients of the surge demand: the mass, the drag and the thrust.
SURGE_FIELDS = ("m", "X_udot", "X_u", "X_uu", "X_max")
#: Seconds the yaw command holds −r_max before the ramp (the sway settles) and +r_max after it.
HOLD_BEFORE, HOLD_AFTER = 60.0, 60.0


@dataclass(frozen=True)
class YawDemand:
    """The yaw moment a hull needs to follow the ramp exactly (module doc).

    Attributes
    ----------
    peak : float
        The largest |N(t)| found (N m).
    at : float
        Its time from the ramp's start (s).
    rudder : float
        The hull's rudder moment |N_uuδr| u² δ_max at the surge (N m).
    steady : float
        |N| after the hold at +r_max (N m): the steady turn's share of the need.
    """

    peak: float
    at: float
    rudder: float
    steady: float

    @property
    def share(self) -> float:
        """peak / rudder: above 1 the rudder cannot follow the command."""
        return self.peak / self.rudder


def _rows(params, u: float, v: float, r: float) -> tuple[float, float]:
    """(n2, n4) of ``tubekit.plant.dynamic.body_forces`` at (u, v, 0, r) (N, N m)."""
    from tubekit.plant.dynamic import body_forces

    forces = body_forces(params, (u, v, 0.0, r))
    return forces[1], forces[3]


def yaw_demand(params, u: float, r_max: float, yaw_rate: float) -> YawDemand:
    """The need of the point hull ``params`` at surge ``u`` (m/s) for the yaw command −r_max → +r_max at
    ``yaw_rate`` (rad/s, rad/s²), each end held (module doc)."""
    from scipy.integrate import solve_ivp

    from steady_turn import steady_sway

    _, m22, _, m44, m24, m42 = params.mass_entries
    ramp = 2.0 * r_max / yaw_rate
    # the two phases, each with its own (r(t), ṙ): the ramp from −r_max at ρ_r on [0, ramp], then the hold at +r_max
    phases = ((0.0, ramp, lambda t: -r_max + yaw_rate * t, yaw_rate), (ramp, ramp + HOLD_AFTER, lambda t: r_max, 0.0))

    def moment(v: float, r: float, r_dot: float) -> float:
        n2, n4 = _rows(params, u, v, r)
        return m42 * (-(n2 + m24 * r_dot) / m22) + m44 * r_dot + n4

    v0, best, held = steady_sway(params, u, -r_max), (0.0, 0.0), 0.0
    for start, stop, yaw, r_dot in phases:
        sol = solve_ivp(lambda t, y, yaw=yaw, r_dot=r_dot: [-(_rows(params, u, y[0], yaw(t))[0] + m24 * r_dot) / m22],
                        (start, stop), [v0], rtol=1e-10, atol=1e-12)
        for t, v in zip(sol.t, sol.y[0]):  # each point a witness, the phase's ends included
            best = max(best, (abs(moment(float(v), yaw(t), r_dot)), float(t)))
        v0 = float(sol.y[0][-1])
        held = abs(moment(v0, yaw(stop), r_dot))
    rudder = abs(params.N_uudr) * u * u * params.fin_max
    return YawDemand(peak=best[0], at=best[1], rudder=float(rudder), steady=float(held))


def surge_demand(params, u_max: float, surge_rate: float, top_speed: float = 0.0) -> tuple[float, float]:
    """(need, thrust) (N) of the point hull ``params`` reaching ``u_max`` (m/s) at ``surge_rate`` (m/s²) on a
    straight run: m11 ρ_u + n1(u_max, 0, 0, 0), against X_max or, with ``top_speed`` s > 0, the thrust tied to
    its drag, |X_u| s + |X_uu| s² (module doc)."""
    from tubekit.plant.dynamic import body_forces

    need = params.mass_entries[0] * surge_rate + body_forces(params, (u_max, 0.0, 0.0, 0.0))[0]
    thrust = abs(params.X_u) * top_speed + abs(params.X_uu) * top_speed ** 2 if top_speed > 0.0 else params.X_max
    return need, thrust


def corner_points(box, fields: tuple[str, ...]) -> list:
    """Every corner of ``box`` over its intervals among ``fields`` (point hulls, the rest at midpoints)."""
    names = [n for n in fields if n in box.free_fields]
    return [box.with_point({n: box.interval(n)[e] for n, e in zip(names, ends)})
            for ends in itertools.product((0, 1), repeat=len(names))]


def worst_yaw(box, u: float, r_max: float, yaw_rate: float) -> tuple[object, YawDemand]:
    """The corner of ``box`` (over :data:`YAW_FIELDS`) whose :func:`yaw_demand` takes the largest share of its
    rudder, and that demand."""
    rows = [(p, yaw_demand(p, u, r_max, yaw_rate)) for p in corner_points(box, YAW_FIELDS)]
    return max(rows, key=lambda row: row[1].share)


def simulated_ramp(params, u: float, r_max: float, yaw_rate: float, tick: float = 0.01, period: float = 0.1,
                   holds: tuple[float, float] = (HOLD_BEFORE, HOLD_AFTER)) -> tuple[float, float]:
    """(max |r_c − r| (rad/s), seconds the rudder is at its limit) of the closed loop on the point hull ``params``
    (its bundled loop gains), surge command ``u`` held, the yaw command of :func:`yaw_demand` stepped every
    ``period`` s, from ``holds[0]`` s before the ramp (settling at −r_max) to ``holds[1]`` s after it."""
    from remus_frontier import still_water_scenario

    from tubekit.plant.dynamic import DynamicPlant

    plant = DynamicPlant(still_water_scenario(params), params=params)
    pose, command, t = (0.0, 0.0, 0.0, 0.0), [u, 0.0, -r_max], 0.0
    worst, saturated = 0.0, 0.0
    settle = int(round(holds[0] / period))
    for k in range(settle + int(round((2.0 * r_max / yaw_rate + holds[1]) / period))):
        if k >= settle:
            command[2] = min(r_max, command[2] + yaw_rate * period)
        for _ in range(int(round(period / tick))):
            pose = plant.step_tuple(t, pose, tuple(command), tick, 1)
            t += tick
            nu = plant.state
            if k >= settle:
                worst = max(worst, abs(command[2] - nu[3]))
                saturated += tick if plant.thrust_command(nu[:4], command, nu[7:10])[1][2] else 0.0
    return worst, saturated


def _check_args(args: argparse.Namespace, ap: argparse.ArgumentParser) -> None:
    if not (math.isfinite(args.u_min) and 0.0 < args.u_min <= args.u_max and math.isfinite(args.u_max)):
        ap.error(f"--u-min, --u-max: expected 0 < u_min <= u_max (m/s), got {args.u_min}, {args.u_max}")
    if not (math.isfinite(args.r_max) and args.r_max > 0.0):
        ap.error(f"--r-max: expected a positive yaw rate (rad/s), got {args.r_max}")
    if not all(math.isfinite(x) and x > 0.0 for x in args.rate):
        ap.error(f"--rate: expected three positive rates (m/s², m/s², rad/s²), got {args.rate}")
    if not (math.isfinite(args.top_speed) and args.top_speed >= 0.0):
        ap.error(f"--top-speed: expected 0 (X_max as given) or a top speed > 0 (m/s), got {args.top_speed}")


def main(argv: list[str] | None = None) -> int:
    from tubekit.model.vehicles import vehicle_params

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vehicle", default="remus100", help="a bundled vehicle with fins")
    ap.add_argument("--u-min", type=float, default=1.07, help="the surge floor (m/s): the rudder's weakest surge")
    ap.add_argument("--u-max", type=float, default=1.9, help="the surge limit (m/s)")
    ap.add_argument("--r-max", type=float, default=0.1, help="the yaw-rate limit (rad/s)")
    ap.add_argument("--rate", type=float, nargs=3, default=[0.3, 0.005, 0.1], help="the plans' rates")
    ap.add_argument("--top-speed", type=float, default=2.497, help="thrust tied to the drag at this top speed "
                    "(m/s; 0: the box's X_max)")
    ap.add_argument("--simulate", action="store_true", help="fly the neediest corner's closed loop")
    args = ap.parse_args(argv)
    _check_args(args, ap)
    box = vehicle_params(args.vehicle)
    if box.actuation != "fins":
        ap.error(f"--vehicle: expected a vehicle with fins, got {args.vehicle!r} ({box.actuation})")
    corner, yaw = worst_yaw(box, args.u_min, args.r_max, args.rate[2])
    mid = yaw_demand(box.nominal, args.u_min, args.r_max, args.rate[2])
    print(f"{args.vehicle}: yaw -{args.r_max:g} -> +{args.r_max:g} rad/s at {args.rate[2]:g} rad/s^2, surge "
          f"{args.u_min:g} m/s; surge to {args.u_max:g} m/s at {args.rate[0]:g} m/s^2")
    print(f"  rudder, neediest of {len(corner_points(box, YAW_FIELDS))} corners: {yaw.peak:.4g} N m at "
          f"t = {yaw.at:.3g} s against its {yaw.rudder:.4g} ({yaw.share:.3f} of it; held at +r_max "
          f"{yaw.steady:.4g})")
    print(f"  rudder, midpoint hull: {mid.peak:.4g} against {mid.rudder:.4g} ({mid.share:.3f}; held {mid.steady:.4g})")
    surges = [(p, *surge_demand(p, args.u_max, args.rate[0], args.top_speed))
              for p in corner_points(box, SURGE_FIELDS)]
    _, need, thrust = max(surges, key=lambda row: row[1] / row[2])
    print(f"  propeller, neediest corner: {need:.4g} N against its {thrust:.4g} ({need / thrust:.3f} of it)")
    if args.simulate:
        error, saturated = simulated_ramp(corner, args.u_min, args.r_max, args.rate[2])
        print(f"  flown (neediest corner, closed loop): |r_c - r| <= {error:.4g} rad/s, rudder at its limit for "
              f"{saturated:.3g} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
