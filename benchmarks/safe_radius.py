"""What the backup's safe radius costs the mission, and how small a station-keeping safe set can be.

Usage::

    python benchmarks/safe_radius.py [--duration S] [--radii R ...] [--only NAME ...] [--json FILE]
    python benchmarks/safe_radius.py --floors OMEGA YAW SURGE      # the floors alone

**A what-if, not a certificate.** For each scenario the certificate is computed (:func:`verify.certify`), then the
tube run is simulated with the certified tightening whose backup safe set has its radius c replaced by each of
``--radii`` (the shape β capped at c/2; the law, the hand-over and every other number as certified). Only the
terminal condition reads c (the footprint c + r̄ and the sensed region), so the run measures what a backup with that
safe radius would cost the mission; a radius below the certified one is **not certified** and is printed as such.
The runs fix the anchor at the plan's end (reach 0); the certified reach ρ_a the shipped loop uses is printed beside.
Per radius: the tracking RMSE, its ratio to the baseline's (the nominal MPC alone), the laps about the circle's
centre and the seconds the backup ran.

Beside it, three lower bounds on the radius, from the kinematics alone (nothing simulated):

* **this Lyapunov shape**: on the level set V = d + β(1 − cos χ) = c abeam (χ = π/2), the current turns the line
  of sight at up to ω̄_xy/d and pushes outward, so V̇ <= ω̄_xy √(1 + (β/d)²) − β k needs
  β k > ω̄_xy √(1 + (β/d)²) at d = c − β; the smallest c over β (:func:`shape_floor`);
* **any shape of the axis angle**: a set {d <= g(x)} about the anchor, x the angle between the hull's axis and the
  line of sight (so a backup may hold bow or stern on), g largest on the line of sight and smallest abeam, kept
  invariant by some surge |u| <= ū along the axis and yaw |r| <= r̄, in continuous time (no sampling, no hand-over
  margin, no loop error). On its boundary d = g(x), with s = −g'(x) >= 0, the current's worst push gives
  ω̄_xy √(1 + (s/d)²) <= s r̄ + u (cos x − s sin x / d) for the best u; the smallest g for an abeam radius g(π/2)
  integrates the smallest such s from abeam to the line of sight (the condition only gets easier as d grows, so
  the greedy slope gives the smallest g), and the floor minimises g(0) over the abeam radius (> ω̄_xy / r̄)
  (:func:`any_shape_floor`; a necessary condition for every set of this form, whatever the law; the midpoint rule
  with steps of at most 1 mrad and 0.2 mm, converged to well under 1 mm: halving both moves it by < 0.1 mm);
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


def _least_slope(x: float, d: float, surge: float, yaw_rate: float, omega_xy: float) -> float:
    """The smallest s = −g'(x) >= 0 that keeps the boundary point (x, d) of {d <= g(x)} from moving out (module doc):
    surge 0, s r̄ >= ω̄ √(1 + (s/d)²), or the full surge while it closes (s <= d cos x / sin x),
    A s + B >= ω̄ √(1 + (s/d)²) with A = r̄ − ū sin x / d, B = ū cos x: both in closed form (the squared condition's
    smallest root where A s + B >= 0); inf when neither holds."""
    best = omega_xy / math.sqrt(yaw_rate ** 2 - (omega_xy / d) ** 2) if d > omega_xy / yaw_rate else math.inf
    cos_x, sin_x = math.cos(x), math.sin(x)
    lin, const = yaw_rate - surge * sin_x / d, surge * cos_x
    if const >= omega_xy:
        return 0.0
    closes = d * cos_x / sin_x if sin_x > 0.0 else math.inf
    quad, half = lin * lin - (omega_xy / d) ** 2, lin * const
    rest = const * const - omega_xy * omega_xy  # < 0
    if quad == 0.0:
        roots = [-rest / (2.0 * half)] if half else []
    else:
        disc = half * half - quad * rest
        roots = [] if disc < 0.0 else [(-half - math.sqrt(disc)) / quad, (-half + math.sqrt(disc)) / quad]
    for root in sorted(r for r in roots if r >= 0.0 and lin * r + const >= 0.0 and r <= closes):
        return min(best, root)
    return best


def shape_level(abeam: float, surge: float, yaw_rate: float, omega_xy: float, step: float = 1e-3,
                rise: float = 2e-4) -> float:
    """g(0) (m) of the smallest shape with g(π/2) = ``abeam`` (module doc): the least slope integrated from abeam to
    the line of sight by the midpoint rule, each step at most ``step`` rad and ``rise`` m of g (the slope is
    singular at g = ω̄/r̄); inf when some angle admits no slope."""
    x, level = math.pi / 2, float(abeam)
    while x > 0.0:
        slope = _least_slope(x, level, surge, yaw_rate, omega_xy)
        if not math.isfinite(slope):
            return math.inf
        dx = min(step, x, rise / slope if slope > 0.0 else math.inf)
        half = _least_slope(x - 0.5 * dx, level + 0.5 * dx * slope, surge, yaw_rate, omega_xy)
        if not math.isfinite(half):
            return math.inf
        level, x = level + dx * half, x - dx
    return level


def any_shape_floor(omega_xy: float, yaw_rate: float, surge: float) -> tuple[float, float]:
    """(c, abeam radius) (m): the smallest level over every shape of the axis angle and its abeam radius (module
    doc), the abeam radius searched on (ω̄/r̄, ω̄/r̄ + 1 m)."""
    from scipy.optimize import minimize_scalar

    least = omega_xy / yaw_rate
    found = minimize_scalar(lambda a: shape_level(a, surge, yaw_rate, omega_xy, 4e-3, 1e-3),
                            bounds=(least * (1.0 + 1e-9), least + 1.0), method="bounded", options={"xatol": 1e-4})
    return shape_level(float(found.x), surge, yaw_rate, omega_xy), float(found.x)


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
        out["runs"].append({"radius": radius, "certified": radius >= certified, "tracking_rmse": m["tracking_rmse"],
                            "rmse_ratio": m["tracking_rmse"] / base["tracking_rmse"],
                            "encirclements": m.get("encirclements"), "backup_s": m["backup_s"]})
    floor_c, floor_beta = shape_floor(omega, yaw)
    any_c, any_abeam = any_shape_floor(omega, yaw, float(scenario.limits.u_max))
    return out | {"omega_xy": omega, "shape_floor": floor_c, "shape_floor_beta": floor_beta,
                  "any_shape_floor": any_c, "any_shape_abeam": any_abeam, "physical_floor": physical_floor(omega, yaw)}


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
    parser.add_argument("--floors", nargs=3, type=float, metavar=("OMEGA", "YAW", "SURGE"),
                        help="print the three floors for ω̄_xy (m/s), r̄ (rad/s) and ū (m/s) and stop (nothing run)")
    args = parser.parse_args(argv)
    if args.floors:
        omega, yaw, surge = args.floors
        level, beta = shape_floor(omega, yaw)
        any_c, abeam = any_shape_floor(omega, yaw, surge)
        print(f"floors at omega {omega} m/s, yaw rate {yaw} rad/s, surge {surge} m/s: this shape {level:.3f} m "
              f"(beta {beta:.3f}), any shape of the axis angle {any_c:.3f} m (abeam {abeam:.3f} m), physical "
              f"{physical_floor(omega, yaw):.3f} m")
        return 0
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
              f"(beta {row['shape_floor_beta']:.3f}), any shape of the axis angle {row['any_shape_floor']:.3f} m "
              f"(abeam {row['any_shape_abeam']:.3f}), physical {row['physical_floor']:.3f} m", flush=True)
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
