"""An obstacle near the path: what the memoryless terminal law asks of the plans' rates, and what the loop charges.

Usage::

    python benchmarks/obstacle_rate.py --mission pier [--rate 0.05 0.1 0.2 0.3] [--spread 1.0 0.25 0.1 0.05]
    python benchmarks/obstacle_rate.py --mission rock [--rate 0.004 0.01 0.02]

Two missions of the vehicles' owners, each a shipped file with an obstacle near the target's path (:data:`MISSIONS`):

* ``pier``: ``examples/bluerov2_published_brisk.toml`` (0.2 m/s in 0.1 m/s of current) with a pier of radius 0.5 m
  whose surface is 3 m from the path, X_f's room 2.5 m, the start 1.8 m behind, r_max 0.3 rad/s, u_max 0.5 m/s;
  the plans' rates (ρ, 0.03, 0.3) with ρ the surge's (``--rate``);
* ``rock``: ``examples/remus100_survey.toml`` (1.25 m/s in 0.15 m/s) with a rock of radius 0.5 m whose surface is
  5 m from the path where the vehicle passes it, X_f's room 20 m, the start 15 m behind, r_max 0.05 rad/s; the
  plans' rates (0.1, 0.005, ρ) with ρ the yaw's.

Each cell is answered twice by ``verify.certify`` (a study: nothing here certifies a shipped example; nothing timed):

1. **the what-if** (:func:`what_if`): on the *kinematic* plant, its ω̄_xy set to a value the dynamic loop would have
   to deliver (the sway table's amplitude on top of the file's current), no yaw-rate error. It isolates the
   terminal law of ``docs/verify.md`` step 17.
2. **the loop** (:func:`dynamic`): on the dynamic plant, over the file's own coefficient box or (``spread``) the
   bundled box shrunk about its midpoints: the loop's E, the ω̄_xy it gives, the conditions that fail.

What it shows (``docs/plant.md`` section 4, "What an obstacle near the path asks of the plans' rates"): the law holds
either obstacle once the plans may change their commands fast enough, and the loop's error (BlueROV2) or the
rudder (REMUS 100) is what those rates cost.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

__all__ = ["Mission", "MISSIONS", "cell", "what_if", "dynamic", "main"]


@dataclasses.dataclass(frozen=True)
class Mission:
    """An obstacle near a shipped file's path, and the limits the cell changes.

    scenario : the file; surface, radius, along : the obstacle's surface from the path, its radius and its position
    along the path (m; the target starts at 0); e_d_max, start : X_f's room and the start's distance behind the
    target (m); r_max : rad/s; u_max : m/s (None: the file's); current : the file's horizontal current per axis
    (m/s, the what-if's floor); rates : the plans' rates with ``None`` where ``--rate`` goes (m/s², m/s², rad/s²);
    sweep : the rates ``--rate`` defaults to; omegas : the what-if's ω̄_xy (m/s); spreads : the loop's boxes the
    table shows (fractions of the bundled box; None: the file's own box)."""

    scenario: Path
    surface: float
    radius: float
    along: float
    e_d_max: float
    start: float
    r_max: float
    u_max: float | None
    current: float
    rates: tuple[float | None, float | None, float | None]
    sweep: tuple[float, ...]
    omegas: tuple[float, ...]
    spreads: tuple[float | None, ...]


MISSIONS = {
    "pier": Mission(EXAMPLES / "bluerov2_published_brisk.toml", 3.0, 0.5, 10.0, 2.5, 1.8, 0.3, 0.5, 0.1,
                    (None, 0.03, 0.3), (0.05, 0.1, 0.2, 0.3), (0.153, 0.17), (1.0, 0.25, 0.1, 0.05)),
    "rock": Mission(EXAMPLES / "remus100_survey.toml", 5.0, 0.5, 20.0, 20.0, 15.0, 0.05, None, 0.15,
                    (0.1, 0.005, None), (0.004, 0.01, 0.02), (0.19,), (None,)),
}


def cell(mission: Mission, rate: float):
    """The mission's file with its obstacle, limits and the plans' rates, ``rate`` where the mission sweeps."""
    from tubekit import load_scenario
    from tubekit.scenario import Obstacle

    rates = tuple(float(rate) if r is None else r for r in mission.rates)
    changes = {"region.e_d_max": mission.e_d_max, "limits.r_max": mission.r_max, "limits.rate": rates}
    if mission.u_max is not None:
        changes["limits.u_max"] = mission.u_max
    return load_scenario(mission.scenario).with_changes(
        obstacles=(Obstacle((mission.along, mission.surface + mission.radius, 0.0), mission.radius),),
        initial_state=(-mission.start, 0.0, 0.0, 0.0), **changes)


def _verdict(cert) -> dict:
    """tiers (both / safe / none), the failed conditions, X_f's band (m) or None."""
    tiers = "both" if cert.tiers.tracking else "safe" if cert.tiers.safe else "none"
    terminal = cert.design.terminal if cert.design is not None else None
    band = None if terminal is None else (float(terminal.d_lo), float(terminal.d_hi))
    return {"tiers": tiers, "failed": [c.condition for c in cert.failures], "x_f": band}


def what_if(mission: Mission, rate: float, omega_xy: float) -> dict:
    """The what-if of the module doc: :func:`cell` on the kinematic plant with ω̄_xy = ``omega_xy`` (m/s, at least
    the mission's current)."""
    import verify

    if not omega_xy >= mission.current:
        raise ValueError(f"omega_xy: expected at least the current's {mission.current} m/s, received {omega_xy!r}")
    extra = omega_xy - mission.current
    scenario = cell(mission, rate).with_changes(**{
        "plant.kind": "kinematic", "disturbance.sway.gain": 0.0, "disturbance.sway.amplitude": extra,
        "disturbance.sway.bound": extra})
    return _verdict(verify.certify(scenario))


def dynamic(mission: Mission, rate: float, spread: float | None = None) -> dict:
    """:func:`cell` on the dynamic plant, over the file's box (``spread`` None) or the bundled box shrunk to
    ``spread`` (its loop at 20 rad/s): the verdict, the loop's E (m/s, m/s, rad/s; inf where it does not close),
    ω̄_xy (m/s; None then) and the yaw channel's need and limit (N m)."""
    import verify
    from tubekit.model.vehicles import vehicle_params

    scenario = cell(mission, rate)
    if spread is not None:
        box = {k: v for k, v in vehicle_params(scenario.plant.vehicle).shrunk(spread).to_dict().items() if k != "name"}
        overrides = tuple({**box, "loop_bandwidth": 20.0}.items())
        scenario = scenario.with_changes(plant=dataclasses.replace(scenario.plant, overrides=overrides))
    cert = verify.certify(scenario)
    loop = cert.velocity_loop
    closed = loop is not None and all(math.isfinite(x) for x in loop.error)
    res = _verdict(cert)
    res["error"] = tuple(float(x) for x in loop.error) if loop is not None else (math.inf,) * 3
    res["omega_xy"] = float(cert.design.problem.omega_xy) if closed and cert.design is not None else None
    res["yaw_moment"] = (float(loop.thrust_peak[2]), float(loop.thrust_floor[2])) if closed else None
    return res


def _failed(res: dict) -> str:
    return "both tiers" if res["tiers"] == "both" else ", ".join(res["failed"][:4])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mission", choices=sorted(MISSIONS), default="pier")
    ap.add_argument("--rate", type=float, nargs="+", default=None, help="the swept plan rate (the mission's default)")
    ap.add_argument("--spread", type=float, nargs="+", default=None,
                    help="fractions of the bundled box for the loop (default: the mission's)")
    args = ap.parse_args(argv)
    mission = MISSIONS[args.mission]
    rates = args.rate or list(mission.sweep)
    spreads = args.spread or list(mission.spreads)
    print(f"{args.mission}: obstacle surface {mission.surface:g} m from the path; what-if on the kinematic plant")
    for omega in mission.omegas:
        for rate in rates:
            res = what_if(mission, rate, omega)
            band = "" if res["x_f"] is None else f"  X_f d in [{res['x_f'][0]:.2f}, {res['x_f'][1]:.2f}] m"
            print(f"  omega_xy {omega:.3f}  rate {rate:g}: {_failed(res)}{band}")
    print("the loop (dynamic plant): the same cells")
    for spread in spreads:
        for rate in rates:
            res = dynamic(mission, rate, spread)
            e = ", ".join(f"{x:.3g}" for x in res["error"])
            omega = "" if res["omega_xy"] is None else f", omega_xy {res['omega_xy']:.3f}"
            moment = "" if res["yaw_moment"] is None else f", yaw moment {res['yaw_moment'][0]:.3g} of " \
                f"{res['yaw_moment'][1]:.3g} N m"
            box = "the file's box" if spread is None else f"spread {spread:g}"
            print(f"  {box}  rate {rate:g}: E = ({e}){omega}{moment}: {_failed(res)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
