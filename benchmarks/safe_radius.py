"""What the backup's safe radius costs the mission, and how small a station-keeping safe set can be.

Usage::

    python benchmarks/safe_radius.py [--duration S] [--radii R ...] [--only NAME ...] [--json FILE]

**A what-if, not a certificate.** For each scenario the certificate is computed (:func:`verify.certify`), then the
tube run is simulated with the certified tightening whose backup safe set has its radius c replaced by each of
``--radii`` (the shape β capped at c/2; the law, the hand-over and every other number as certified). Only the
terminal condition reads c (the footprint c + r̄ and the sensed region), so the run measures what a backup with that
safe radius would cost the mission; a radius below the certified one is **not certified** and is printed as such.
The runs fix the anchor at the plan's end (reach 0); the certified reach ρ_a the shipped loop uses is printed beside.
Per radius: the tracking RMSE, its ratio to the baseline's (the nominal MPC alone), the laps about the circle's
centre and the seconds the backup ran.

Beside it, two lower bounds on the radius, from the kinematics alone (nothing simulated):

* **this Lyapunov shape**: on the level set V = d + β(1 − cos χ) = c abeam (χ = π/2), the current turns the line
  of sight at up to ω̄_xy/d and pushes outward, so V̇ <= ω̄_xy √(1 + (β/d)²) − β k needs
  β k > ω̄_xy √(1 + (β/d)²) at d = c − β; the smallest c over β (:func:`shape_floor`);
* **physical**: a vehicle abeam of the current drifts while it turns its axis onto it, ∫ ω̄ sin χ dχ / r̄ = ω̄_xy / r̄
  (:func:`physical_floor`): no stop-and-hold backup keeps a smaller set.
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
from tubekit import paper_scenario, simulate
from tubekit.loop.pipeline import certified_run
from tubekit.scenario import Scenario, load_scenario
from tubekit.tightening import Tightening

DEFAULT_RADII = (0.75, 0.6, 0.4, 0.3, 0.2, 0.1, 0.05)


def shape_floor(omega_xy: float, yaw_rate: float) -> tuple[float, float]:
    """(c, β) (m): the smallest level c = d + β with β k > ω̄ √(1 + (β/d)²) (module doc), on a 1 mm grid of β."""
    best = (math.inf, math.nan)
    for beta in np.arange(0.001, 5.0, 0.001):
        ratio = (beta * yaw_rate / omega_xy) ** 2 - 1.0
        if ratio <= 0.0:
            continue
        level = beta + beta / math.sqrt(ratio)
        if level < best[0]:
            best = (float(level), float(beta))
    return best


def physical_floor(omega_xy: float, yaw_rate: float) -> float:
    """ω̄_xy / r̄ (m): the drift of a vehicle abeam of the current while it turns its axis onto it (module doc)."""
    return omega_xy / yaw_rate


def with_radius(tight: Tightening, radius: float) -> Tightening:
    """``tight`` with its backup's safe radius replaced by ``radius`` (m), β capped at radius / 2 and the anchor
    fixed at the plan's end (reach 0: the radius is the whole footprint; a what-if)."""
    safe = tight.backup.safe_set
    safe = dataclasses.replace(safe, level=float(radius), shape=min(safe.shape, 0.5 * float(radius)))
    return dataclasses.replace(tight, backup=dataclasses.replace(tight.backup, safe_set=safe, anchor_reach=0.0))


def measure(name: str, scenario: Scenario, duration: float, radii: tuple[float, ...]) -> dict:
    """The certified radius, the two floors and, per radius, the run's figures (module doc)."""
    scenario = scenario.with_changes(duration=duration)
    cert = verify.certify(scenario)
    tight = cert.best_effort_tightening()
    certified = float(tight.backup.safe_set.level)
    omega, yaw = float(cert.disturbance.omega_xy), float(scenario.limits.r_max)
    base = simulate(scenario, None, progress=False).metrics
    out = {"scenario": name, "tiers": cert.tiers.to_dict(), "certified_radius": certified,
           "anchor_reach": float(tight.backup.anchor_reach),
           "baseline_rmse": base["tracking_rmse"], "runs": []}
    for radius in radii:
        m = certified_run(scenario, with_radius(tight, radius), progress=False).metrics
        out["runs"].append({"radius": radius, "certified": radius >= certified,
                            "tracking_rmse": m["tracking_rmse"], "rmse_ratio": m["tracking_rmse"] / base["tracking_rmse"],
                            "encirclements": m.get("encirclements"), "backup_s": m["backup_s"]})
    floor_c, floor_beta = shape_floor(omega, yaw)
    return out | {"omega_xy": omega, "shape_floor": floor_c, "shape_floor_beta": floor_beta,
                  "physical_floor": physical_floor(omega, yaw)}


def scenarios() -> dict[str, Scenario]:
    """Section VI and the shipped ``paper_currents``."""
    return {"section_vi": paper_scenario(),
            "paper_currents": load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=100.0, help="simulated seconds per run (default 100)")
    parser.add_argument("--radii", type=float, nargs="*", default=list(DEFAULT_RADII), help="safe radii c (m)")
    parser.add_argument("--only", nargs="*", help="scenario names to run (default all)")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON")
    args = parser.parse_args(argv)
    rows = []
    for name, sc in scenarios().items():
        if args.only and name not in args.only:
            continue
        row = measure(name, sc, args.duration, tuple(args.radii))
        rows.append(row)
        print(f"{name}: certified radius {row['certified_radius']:.3f} m, anchor reach {row['anchor_reach']:.3f} m "
              f"(the shipped loop: c - reach = {row['certified_radius'] - row['anchor_reach']:.3f} m beside an "
              f"obstacle; the runs below fix the anchor), tiers {row['tiers']}, "
              f"baseline RMSE {row['baseline_rmse']:.3f} m; floors: this shape {row['shape_floor']:.3f} m "
              f"(beta {row['shape_floor_beta']:.3f}), physical {row['physical_floor']:.3f} m", flush=True)
        for r in row["runs"]:
            tag = "certified" if r["certified"] else "NOT certified (what-if)"
            laps = "-" if r["encirclements"] is None else f"{r['encirclements']:.2f}"
            print(f"  c = {r['radius']:.2f} m [{tag}]: RMSE {r['tracking_rmse']:.3f} m ({r['rmse_ratio']:.2f}x), "
                  f"laps {laps}, backup {r['backup_s']:.1f} s", flush=True)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
