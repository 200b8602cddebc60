"""The hold backup on the BlueROV2 Heavy: its disc against station keeping's, runs past a pier, forced backups.

Usage::

    python benchmarks/hold_backup.py [--compare] [--runs] [--forced] [--duration S] [--json FILE]

* ``--compare``: the certificate of each scenario with the hold backup (``controller.backup = "hold"``) and with
  station keeping, every other number the same: the tiers, the safe set's radius, ω̄_xy and E. The scenarios:
  ``examples/bluerov2_pier.toml`` and ``examples/bluerov2_brisk_current.toml`` with the pier example's thrust
  shares (sway 30 %; the bundled 10 % cannot push sideways against 0.1 m/s: ``loop_saturation[Y]``).
* ``--runs``: ``examples/bluerov2_pier.toml`` certified and flown for ``--duration`` seconds (default 60) as
  shipped, with the pier moved about the path (3 m outside the circle at 180°, 270° and 315°, and at the circle's
  centre, 3 m inside every point of it, the start 1 m further out; at 90° the pier would lie within the disc of the
  start: ``backup_initial``) and with a steady current of 0.1 m/s along ±x and ±y (the mirrored
  currents); each variant certified on its own. Per run: the tiers, the safe radius, the periods no plan was
  followed (replaced steps, backup seconds), the smallest clearance and the promises broken.
* ``--forced``: the FHOCP made to fail for 15 s (periods 100–249, the candidate off) on the pier example, at the
  midpoints and at two corners of the coefficient box: the hold law takes over from the moving vehicle; printed are
  the largest distance from the anchor and depth error against the certified disc, whether a plan took over again,
  the largest sway command, and the promises broken (the recursive-feasibility premise fails by construction).

Everything is measured on the certificate or the run; nothing here is timed.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path

import numpy as np

import verify
from tubekit.exceptions import SolverError
from tubekit.fhocp import FHOCP
from tubekit.loop.closed_loop import run_closed_loop
from tubekit.loop.pipeline import certified_run
from tubekit.loop.promises import check_promises
from tubekit.scenario import Obstacle, Scenario, load_scenario

ROOT = Path(__file__).resolve().parents[1]
PIER = ROOT / "examples" / "bluerov2_pier.toml"
BRISK = ROOT / "examples" / "bluerov2_brisk_current.toml"


def with_pier_thrusters(scenario: Scenario) -> Scenario:
    """``scenario`` with the pier example's vehicle (the same box, the thrust shares with sway 30 %)."""
    return scenario.with_changes(plant=load_scenario(PIER).plant)


def certificate_row(name: str, scenario: Scenario) -> dict:
    """Tiers, failed conditions, safe radius (m), ω̄_xy (m/s) and E of the certificate of ``scenario``."""
    cert = verify.certify(scenario)
    loop = cert.velocity_loop
    return {"scenario": name, "backup": scenario.controller.backup, "tiers": cert.tiers.to_dict(),
            "failed": [c.condition for c in cert.failures], "safe_radius": cert.backup.safe_set.level,
            "depth_band": cert.backup.safe_set.depth, "omega_xy": cert.disturbance.omega_xy,
            "loop_error": None if loop is None else list(loop.error), "law": cert.backup.law.to_dict()}


def compare() -> list[dict]:
    """The hold backup against station keeping on both scenarios (module doc)."""
    rows = []
    for name, scenario in (("bluerov2_pier", load_scenario(PIER)),
                           ("bluerov2_brisk_current+sway30", with_pier_thrusters(load_scenario(BRISK)))):
        for backup in ("hold", "station_keeping"):
            rows.append(certificate_row(name, scenario.with_changes(**{"controller.backup": backup})))
    return rows


def variants() -> dict[str, Scenario]:
    """The pier example and its variants (module doc), by name."""
    base = load_scenario(PIER)
    out = {"shipped": base}
    for angle in (180, 270, 315):
        a = math.radians(angle)
        out[f"pier_at_{angle}deg"] = base.with_changes(obstacles=(Obstacle((6.0 * math.cos(a), 6.0 * math.sin(a),
                                                                            0.0), 0.5),))
    # inside the circle, 3 m from every point of the path; the start moved 1 m outward, clear of the pier's disc
    out["pier_at_centre"] = base.with_changes(obstacles=(Obstacle((0.0, 0.0, 0.0), 0.5),),
                                              initial_state=(-1.0, 4.0, 0.2, 0.0))
    for label, current in (("+x", (0.1, 0.0, 0.0)), ("-x", (-0.1, 0.0, 0.0)), ("+y", (0.0, 0.1, 0.0)),
                           ("-y", (0.0, -0.1, 0.0))):
        out[f"steady_{label}"] = base.with_changes(**{"disturbance.amplitude": (0.0, 0.0, 0.0),
                                                      "disturbance.constant": current})
    return out


def run_row(name: str, scenario: Scenario, duration: float) -> dict:
    """Certify and fly ``scenario`` for ``duration`` s: what the run kept and how long it went without a plan."""
    scenario = scenario.with_changes(duration=duration)
    cert = verify.certify(scenario)
    done = certified_run(scenario, cert.best_effort_tightening(), progress=False)
    m = done.metrics
    return {"scenario": name, "tiers": cert.tiers.to_dict(), "safe_radius": cert.backup.safe_set.level,
            "replaced_steps": m["replaced_steps"], "backup_s": m["backup_s"], "min_clearance": m["min_clearance"],
            "tracking_rmse": m["tracking_rmse"], "broken": list(done.broken),
            "premises_failed": [p.name for p in done.promises if p.tier == "premise" and not p.ok]}


class _Failing:
    """The FHOCP, failing at the periods [first, last) (an injected solver error)."""

    first, last = 100, 250

    def __init__(self, scenario: Scenario, tightening) -> None:
        self.inner, self.k = FHOCP(scenario, tightening), 0

    def solve(self, t, state, obstacles, v_last=None):
        self.k += 1
        if self.first <= self.k - 1 < self.last:
            raise SolverError("injected")
        return self.inner.solve(t, state, obstacles, v_last=v_last)


def forced_row(name: str, scenario: Scenario, duration: float = 40.0) -> dict:
    """A 15 s FHOCP failure on ``scenario`` (module doc): the hold law's excursion against its disc."""
    cert = verify.certify(scenario)
    scenario = scenario.with_changes(duration=duration, **{"controller.candidate": False})
    res = run_closed_loop(scenario, tightening=cert.tightening if cert.tightening is not None else
                          cert.best_effort_tightening(), solver_factory=_Failing, progress=False)
    active = np.flatnonzero(res.backup_active[:-1])
    anchor = res.backup_anchor[active]
    dist = np.hypot(res.states[active, 0] - anchor[:, 0], res.states[active, 1] - anchor[:, 1])
    depth = np.abs(res.states[active, 2] - anchor[:, 2])
    promises = check_promises(res)
    return {"scenario": name, "backup_s": res.metrics["backup_s"], "resumed": bool(not res.backup_active[-2]),
            "largest_distance": float(dist.max()), "disc": cert.backup.safe_set.level,
            "largest_depth_error": float(depth.max()), "depth_band": cert.backup.safe_set.depth,
            "largest_sway_command": float(np.abs(res.sway_command).max()),
            "broken": [p.name for p in promises if p.given and not p.ok and p.name != "recursive_feasibility"]}


def corners(scenario: Scenario) -> dict[str, Scenario]:
    """``scenario`` with its truth at the box's midpoints (as shipped), at the lower and at the upper corner."""
    out = {"midpoints": scenario}
    params = scenario.plant.params
    for label, end in (("lower_corner", 0), ("upper_corner", 1)):
        corner = {k: v[end] for k, v in vars(params).items() if not k.startswith("_") and isinstance(v, tuple)
                  and len(v) == 2}
        out[label] = scenario.with_changes(plant=dataclasses.replace(scenario.plant, truth=tuple(corner.items())))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--compare", action="store_true")
    parser.add_argument("--runs", action="store_true")
    parser.add_argument("--forced", action="store_true")
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    if not (args.compare or args.runs or args.forced):
        args.compare = True
    out: dict[str, list[dict]] = {}
    if args.compare:
        out["compare"] = compare()
    if args.runs:
        out["runs"] = [run_row(name, sc, args.duration) for name, sc in variants().items()]
    if args.forced:
        out["forced"] = [forced_row(name, sc) for name, sc in corners(load_scenario(PIER)).items()]
    for section, rows in out.items():
        print(f"== {section}")
        for row in rows:
            print(json.dumps(row, default=float))
    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
