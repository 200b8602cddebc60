"""A pier 3 m from the path at the owners' 0.2 m/s: what the memoryless terminal law needs, and what the loop gives.

Usage::

    python benchmarks/pier_rate.py [--rate 0.05 0.1 0.2 0.3] [--spread 1.0 0.25 0.1 0.05]

``examples/bluerov2_published_brisk.toml`` keeps both tiers with X_f 8.7-14.8 m behind the target, so obstacles must
stand 16 m off its path. Two questions, each answered by ``verify.certify`` on that file with named fields changed
(a study: nothing here is a certificate of a shipped example, and nothing is timed):

1. **The what-if** (:func:`what_if`): the same file on the *kinematic* plant, its disturbance bound ω̄_xy set to a
   value the dynamic loop would have to deliver (the sway table's amplitude: ω̄_xy = 0.1 m/s of current + it), with
   a pier of radius 0.5 m whose surface is ``surface`` m from the path, ``region.e_d_max`` 2.5 m (X_f close behind
   the target), the start 1.8 m behind, r_max 0.3 rad/s, the plans' yaw rate 0.3 rad/s² and their surge rate ``rate_u``
   (m/s²). It isolates
   the terminal law: the kinematic plant has no loop error in yaw (E_r = 0), so it is optimistic there.
2. **The loop** (:func:`dynamic`): the same pier cell on the dynamic plant, the BlueROV2 Heavy's bundled (published)
   box shrunk about its midpoints to ``spread`` (1: the published box), u_max 0.5 m/s: the loop's E, the ω̄_xy it
   gives, and the conditions that fail.

What it shows (``docs/plant.md`` section 4, "A pier 3 m from the path at the owners' speed"): the terminal law holds
the pier once plans may change their surge by 0.3 m/s² (X_f about 1.75-2.3 m behind), but the loop's bound at that
rate is far from the ω̄_xy the what-if assumed even over a twentieth of the published box.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_published_brisk.toml"
RATES = (0.05, 0.1, 0.2, 0.3)
SPREADS = (1.0, 0.25, 0.1, 0.05)
#: The pier's radius (m), its position along the path (m), X_f's room and the start (m behind the target).
PIER_RADIUS, PIER_X, E_D_MAX, START = 0.5, 10.0, 2.5, 1.8
CURRENT = 0.1
#: The plans' yaw rate (rad/s²): the file's 0.12 leaves the yaw rows' rate short even where the surge's suffices.
RATE_R = 0.3

__all__ = ["pier_cell", "what_if", "dynamic", "main"]


def pier_cell(rate_u: float, surface: float = 3.0):
    """The published brisk file with a pier whose surface is ``surface`` m from the path, X_f's room
    :data:`E_D_MAX`, r_max 0.3 rad/s, u_max 0.5 m/s and the plans' rates (``rate_u``, 0.03, :data:`RATE_R`)
    (m/s², m/s², rad/s²)."""
    from tubekit import load_scenario
    from tubekit.scenario import Obstacle

    base = load_scenario(SCENARIO)
    rate = (float(rate_u), base.limits.rate[1], RATE_R)
    return base.with_changes(
        obstacles=(Obstacle((PIER_X, surface + PIER_RADIUS, 0.0), PIER_RADIUS),),
        initial_state=(-START, 0.0, 0.0, 0.0),
        **{"region.e_d_max": E_D_MAX, "limits.r_max": 0.3, "limits.u_max": 0.5, "limits.rate": rate})


def _verdict(cert) -> dict:
    """tiers (both / safe / none), the failed conditions, X_f's band (m) or None."""
    tiers = "both" if cert.tiers.tracking else "safe" if cert.tiers.safe else "none"
    terminal = cert.design.terminal if cert.design is not None else None
    band = None if terminal is None else (float(terminal.d_lo), float(terminal.d_hi))
    return {"tiers": tiers, "failed": [c.condition for c in cert.failures], "x_f": band}


def what_if(rate_u: float, omega_xy: float, surface: float = 3.0) -> dict:
    """The kinematic what-if of the module doc: :func:`pier_cell` on the kinematic plant with ω̄_xy = ``omega_xy``
    (m/s, at least the current's 0.1)."""
    import verify

    if not omega_xy >= CURRENT:
        raise ValueError(f"omega_xy: expected at least the current's {CURRENT} m/s, received {omega_xy!r}")
    scenario = pier_cell(rate_u, surface).with_changes(**{
        "plant.kind": "kinematic", "disturbance.sway.gain": 0.0,
        "disturbance.sway.amplitude": omega_xy - CURRENT, "disturbance.sway.bound": omega_xy - CURRENT})
    return _verdict(verify.certify(scenario))


def dynamic(rate_u: float, spread: float, surface: float = 3.0) -> dict:
    """:func:`pier_cell` on the dynamic plant over the bundled box shrunk to ``spread``: the verdict, the loop's E
    (m/s, m/s, rad/s; inf where it does not close) and ω̄_xy (m/s; None then)."""
    import verify
    from tubekit.model.vehicles import vehicle_params
    from tubekit.scenario import scenario_from_dict

    table = pier_cell(rate_u, surface).to_dict()
    box = vehicle_params("bluerov2_heavy").shrunk(spread).to_dict()
    box["loop_bandwidth"] = 20.0
    table["plant"] = {"kind": "dynamic", "vehicle": {k: v for k, v in box.items() if k != "name"}}
    cert = verify.certify(scenario_from_dict(table))
    loop = cert.velocity_loop
    closed = loop is not None and all(math.isfinite(x) for x in loop.error)
    res = _verdict(cert)
    res["error"] = tuple(float(x) for x in loop.error) if loop is not None else (math.inf,) * 3
    res["omega_xy"] = float(cert.design.problem.omega_xy) if closed and cert.design is not None else None
    return res


def _failed(res: dict) -> str:
    return "both tiers" if res["tiers"] == "both" else ", ".join(res["failed"][:4])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rate", type=float, nargs="+", default=list(RATES), help="plans' surge rates (m/s²)")
    ap.add_argument("--spread", type=float, nargs="+", default=list(SPREADS),
                    help="fractions of the published box (1: the box itself)")
    ap.add_argument("--omega", type=float, nargs="+", default=[0.153, 0.17], help="the what-if's omega_xy (m/s)")
    args = ap.parse_args(argv)
    print("what-if (kinematic plant, E_r = 0): pier surface 3 m from the path")
    for omega in args.omega:
        for rate in args.rate:
            res = what_if(rate, omega)
            band = "" if res["x_f"] is None else f"  X_f d in [{res['x_f'][0]:.2f}, {res['x_f'][1]:.2f}] m"
            print(f"  omega_xy {omega:.3f}  rate_u {rate:.2f}: {_failed(res)}{band}")
    print("the loop (dynamic plant, the bundled box shrunk): the same cell")
    for spread in args.spread:
        for rate in args.rate:
            res = dynamic(rate, spread)
            e = ", ".join(f"{x:.3g}" for x in res["error"])
            omega = "" if res["omega_xy"] is None else f", omega_xy {res['omega_xy']:.3f}"
            print(f"  spread {spread:g}  rate_u {rate:.2f}: E = ({e}){omega}: {_failed(res)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
