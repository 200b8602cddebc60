"""Both tiers on the BlueROV2 at 0.2 m/s in 0.1 m/s of current, flown: ``examples/bluerov2_brisk_tracked.toml`` and
its variants, each certified on its own and flown for 60 s.

The variants (of ``--scenario``, default the example): the current steady on its bound along ±x and ±y (each
mirrors the other); the rocks mirrored to the other side of the path or moved 10 m back along it; the simulated
hull at either corner of the coefficient box. Each row reports the tiers certified and kept, the periods without an
accepted plan, the solver plans replaced by the candidate, the backup's time, the smallest clearance, e_d's range
and the tracking RMSE. Nothing is timed.

``--frontier``: which missions of the same shape certify both tiers, with the target's speed, the current (per
axis) and the coefficient box changed (:func:`frontier_cell`; the box widened about von Benzon's values), and how
near the path a rock may lie (:func:`nearest_rock`: the smallest distance from the path at which the certificate
still gives both tiers, with the station-keeping backup and with the hold). Certificates only, nothing flown.

Usage: ``python benchmarks/brisk_tracked.py [--scenario FILE] [--duration 60] [--only NAME ...] [--frontier]``
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "examples" / "bluerov2_brisk_tracked.toml"

__all__ = ["variants", "fly", "frontier_cell", "nearest_rock", "main", "SCENARIO", "SPEEDS", "CURRENTS", "SPREADS",
           "ROCK_DISTANCES", "SURGE_ROOM"]

#: The frontier's target speeds (m/s), currents (m/s per axis), coefficient boxes (± fraction of von Benzon's
#: values) and the rock's distances from the path (m).
SPEEDS = (0.2, 0.25, 0.3)
CURRENTS = (0.1, 0.125, 0.15)
SPREADS = (0.1, 0.15, 0.2)
#: The frontier's surge limit above the target's speed plus the current (m/s; the example: 0.2 + 0.1 + 0.05).
SURGE_ROOM = 0.05
ROCK_DISTANCES = (22.0, 18.0, 15.0, 12.0, 10.0, 8.0, 6.0, 4.0, 3.0)


def _corner(scenario, end: int):
    """``scenario`` with its simulated hull at the lower (0) or upper (1) end of every coefficient interval (a thrust
    tied to the drag by the top speed is derived from the corner, not taken from X_max's interval)."""
    params = scenario.plant.params
    corner = {k: params.interval(k)[end] for k in params.free_fields}
    return scenario.with_changes(plant=dataclasses.replace(scenario.plant, truth=tuple(corner.items())))


def variants(path: Path = SCENARIO) -> dict:
    """The scenario at ``path`` and its variants (module doc), by name; the rocks are moved from where it has
    them."""
    from tubekit.scenario import Obstacle, load_scenario
    base = load_scenario(path)
    steady = {"disturbance.amplitude": (0.0, 0.0, 0.0)}
    c = max(base.disturbance.amplitude[:2])  # the steady current: the scenario's own horizontal bound, on an axis
    moved = lambda f: base.with_changes(obstacles=tuple(Obstacle(center=f(o.center), radius=o.radius)
                                                        for o in base.obstacles))
    return {
        "as shipped": base,
        "steady +x": base.with_changes(**steady, **{"disturbance.constant": (c, 0.0, 0.0)}),
        "steady -x": base.with_changes(**steady, **{"disturbance.constant": (-c, 0.0, 0.0)}),
        "steady +y": base.with_changes(**steady, **{"disturbance.constant": (0.0, c, 0.0)}),
        "steady -y": base.with_changes(**steady, **{"disturbance.constant": (0.0, -c, 0.0)}),
        "rocks mirrored": moved(lambda c: (c[0], -c[1], c[2])),
        "rocks moved along": moved(lambda c: (c[0] - 10.0, c[1], c[2])),
        "hull at the lower corner": _corner(base, 0),
        "hull at the upper corner": _corner(base, 1),
    }


def fly(name: str, scenario, duration: float) -> dict:
    """Certify ``scenario`` on its own, fly it for ``duration`` s, and measure the row of the module doc."""
    import tubekit
    import verify
    cert = verify.certify(scenario)
    row = {"variant": name, "certified": [cert.tiers.safe, cert.tiers.tracking],
           "failed": [c.condition for c in cert.failures]}
    if not cert.tiers.safe:
        return row
    run = tubekit.simulate(scenario, cert, duration=duration, progress=False)
    promises = tubekit.check_promises(run)
    m = run.metrics
    row.update(kept=m["outcome"], broken=[p.name for p in promises if p.given and not p.ok],
               replaced=m["replaced_steps"], steps=m["steps"], backup_s=m["backup_s"],
               clearance=round(m["min_clearance"], 3), e_d=[round(float(np.nanmin(run.errors[:, 0])), 3),
                                                          round(float(np.nanmax(run.errors[:, 0])), 3)],
               rmse=round(m["tracking_rmse"], 3))
    plan = [p for p in promises if p.name == "plan_available"]
    if plan:
        row["plan_available"] = plan[0].detail.split(";")[0]
    return row


def _widened(scenario, spread: float):
    """``scenario`` with every interval of its vehicle box widened to ± ``spread`` about its midpoint."""
    overrides = []
    for key, value in scenario.plant.overrides:
        if isinstance(value, tuple) and len(value) == 2:
            mid = (value[0] + value[1]) / 2
            value = tuple(sorted((mid * (1 - spread), mid * (1 + spread))))
        overrides.append((key, value))
    return scenario.with_changes(plant=dataclasses.replace(scenario.plant, overrides=tuple(overrides), truth=()))


def _verdict(cert) -> str:
    """``both``, ``safe; tracking: ...`` or the first failed conditions."""
    names = [c.condition for c in cert.failures]
    if cert.certified:
        return "both"
    if cert.tiers.safe:
        return "safe; tracking: " + ", ".join(names[:3])
    return ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")


def frontier_cell(speed: float, current: float, spread: float = 0.1, backup: str | None = None) -> str:
    """The verdict of the example with the target at ``speed`` (m/s), the current ``current`` (m/s per axis), the
    coefficient box ± ``spread`` and u_max = speed + current + :data:`SURGE_ROOM`; the start stays 6 m behind,
    under way at the target's speed. ``backup``: ``controller.backup`` (None: the example's)."""
    import verify
    from tubekit.scenario import load_scenario
    sc = load_scenario(SCENARIO)
    sc = sc.with_changes(**{"trajectory.direction_velocity": (speed, 0.0, 0.0), "limits.initial": (speed, 0.0, 0.0),
                            "disturbance.amplitude": (current, current, current),
                            "limits.u_max": round(speed + current + SURGE_ROOM, 6)})
    if backup is not None:
        sc = sc.with_changes(**{"controller.backup": backup})
    return _verdict(verify.certify(_widened(sc, spread)))


def nearest_rock(backup: str) -> tuple[float | None, str]:
    """(the smallest of :data:`ROCK_DISTANCES` at which one rock beside the path keeps both tiers, the verdict at
    the next distance) with the backup ``backup`` (``station_keeping``, ``hold`` with the pier example's
    thrusters, sway's share 30 %, or ``none``)."""
    import verify
    from tubekit.scenario import Obstacle, load_scenario
    sc = load_scenario(SCENARIO).with_changes(**{"controller.backup": backup})
    if backup == "hold":
        sc = sc.with_changes(plant=load_scenario(ROOT / "examples" / "bluerov2_pier.toml").plant)
    best, after = None, "none tried"
    for distance in ROCK_DISTANCES:
        cert = verify.certify(sc.with_changes(obstacles=(Obstacle(center=(8.0, distance, 0.0), radius=0.4),)))
        if not cert.certified:
            return best, f"{distance:g} m: {_verdict(cert)}"
        best = distance
    return best, after


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=60.0, help="seconds flown per variant")
    ap.add_argument("--only", nargs="+", default=None, help="variant names to fly")
    ap.add_argument("--scenario", type=Path, default=SCENARIO, help="the scenario whose variants are flown")
    ap.add_argument("--frontier", action="store_true", help="the speed x current x box table and the nearest rock")
    ap.add_argument("--backup", default=None, help="controller.backup for the frontier's table (default: the example's)")
    args = ap.parse_args(argv)
    if args.frontier:
        for spread in SPREADS:
            print(f"box +-{spread:g}: | speed \\ current | " + " | ".join(f"{c:g}" for c in CURRENTS) + " |")
            for speed in SPEEDS:
                print(f"| {speed:g} | " + " | ".join(frontier_cell(speed, c, spread, args.backup) for c in CURRENTS) + " |",
                      flush=True)
        for backup in ("station_keeping", "hold", "none"):
            print(backup, nearest_rock(backup), flush=True)
        return 0
    for name, scenario in variants(args.scenario).items():
        if args.only and name not in args.only:
            continue
        print(fly(name, scenario, args.duration), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
