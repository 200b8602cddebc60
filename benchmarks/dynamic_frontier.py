"""Which (u_max, current) pairs certify on the dynamic plant: the frontier of ``examples/bluerov2_slow.toml``.

For each surge limit u_max and current amplitude (per axis) of a grid, the shipped dynamic scenario with those two
numbers changed is certified (``verify.certify``; the BlueROV2 Heavy at von Benzon's values ±2 %, everything else as
shipped), and the table says ``both`` (both tiers certified) or the first failed conditions. Nothing is timed.

``--spread F`` certifies every cell over von Benzon's values ±F (a fraction) instead of ±2 %; ``--spread published``
over the bundled vehicle's own box, the published spread between identifications (von Benzon ↔ Einarsson).
``--bandwidth W`` runs the velocity loop at W rad/s (``loop_bandwidth``; the bundled file's 10).

Usage: ``python benchmarks/dynamic_frontier.py [--u-max 0.2 0.3 ...] [--current 0.02 0.04 ...] [--spread F|published]
[--bandwidth W]`` (about 1-4 s per cell).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from tubekit.scenario import load_scenario

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_slow.toml"
U_MAX = (0.2, 0.25, 0.3, 0.35, 0.4)
CURRENT = (0.02, 0.03, 0.04, 0.05, 0.06, 0.08, 0.1)


sys.path.insert(0, str(Path(__file__).resolve().parent))
from dynamic_gap import VON_BENZON  # noqa: E402 - the coefficients the shipped scenario's box is centred on


def plant_overrides(spread: str | None) -> tuple | None:
    """The ``[plant.vehicle]`` overrides of ``--spread``: None keeps the scenario's (±2 %), ``"published"`` none
    (the bundled box), a fraction F von Benzon's values ±F."""
    if spread is None:
        return None
    if spread == "published":
        return ()
    f = float(spread)
    return tuple(sorted((k, (v * (1 + f), v * (1 - f)) if (v and f) else v) for k, v in VON_BENZON.items()))


def cell(u_max: float, current: float, spread: str | None = None, bandwidth: float | None = None) -> str:
    """``both`` when the scenario with ``u_max`` (m/s) and the current amplitude ``current`` (m/s per axis)
    certifies both tiers; ``safe`` when the safe tier holds and tracking fails only for the terminal ingredients of
    the rate-limited plans every dynamic design has (``terminal_*``, a row face's ``terminal_rate[...]`` among them:
    the row faces do not fit, ``docs/verify.md`` step 17c), ``safe; tracking: ...`` when tracking fails for more;
    else its first three failed conditions."""
    import verify
    sc = load_scenario(SCENARIO).with_changes(**{"limits.u_max": u_max,
                                                 "disturbance.amplitude": (current, current, current)})
    overrides = plant_overrides(spread)
    if overrides is None:
        overrides = sc.plant.overrides
    if bandwidth is not None:
        overrides = (*(o for o in overrides if o[0] != "loop_bandwidth"), ("loop_bandwidth", float(bandwidth)))
    sc = sc.with_changes(plant=dataclasses.replace(sc.plant, overrides=tuple(overrides)))
    cert = verify.certify(sc)
    if cert.certified:
        return "both"
    names = [c.condition for c in cert.failures]
    rows = any(n.startswith("terminal_rate") for n in names)
    others = [n for n in names if not (rows and n.startswith("terminal_"))]
    if cert.tiers.safe and not others:
        return "safe"
    if cert.tiers.safe:  # tracking refused for more than the rate-limited plans' row faces: say for what
        return "safe; tracking: " + ", ".join(others)
    return ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")


def table(u_values, currents, spread: str | None = None, bandwidth: float | None = None) -> list[str]:
    """The markdown table: one row per u_max, one column per current."""
    lines = ["| u_max (m/s) \\ current (m/s) | " + " | ".join(f"{c:g}" for c in currents) + " |",
             "|---" * (len(currents) + 1) + "|"]
    for u in u_values:
        lines.append(f"| {u:g} | " + " | ".join(cell(u, c, spread, bandwidth) for c in currents) + " |")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--u-max", type=float, nargs="+", default=list(U_MAX))
    parser.add_argument("--current", type=float, nargs="+", default=list(CURRENT))
    parser.add_argument("--spread", help="a fraction F (von Benzon ±F) or 'published' (the bundled box)")
    parser.add_argument("--bandwidth", type=float, help="the velocity loop's bandwidth (rad/s)")
    args = parser.parse_args(argv)
    for line in table(args.u_max, args.current, args.spread, args.bandwidth):
        print(line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
