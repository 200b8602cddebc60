"""How the dynamic fixed point's first assumption decides the backup's safe set (a study; nothing is timed).

:func:`verify.vehicle.compose.solve_dynamic` starts from E_a = ``_INFLATE`` x the plans-only loop bound (1.25) and
raises it by 5 % per round until the derived E is below it; the backup is designed at each round's E_a (the gentle
search: the smallest certified safe set whose command rate keeps E below E_a). Every start that closes is a valid
certificate, but the path decides which backup it ends with. This script certifies a scenario with the start set
to each of a few values and prints, per start, the safe tier, the backup's safe radius and omega_bar_xy.

Usage: ``python benchmarks/fixed_point_start.py [SCENARIO ...] [--starts 1.25 1.5 ...]`` (default the shipped
BlueROV2 examples bluerov2_slow and bluerov2_current; about 1-5 s per cell).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Sequence

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SCENARIOS = (EXAMPLES / "bluerov2_slow.toml", EXAMPLES / "bluerov2_current.toml")
STARTS = (1.25, 1.35, 1.5, 1.65, 1.8)

__all__ = ["cell", "main", "STARTS", "SCENARIOS"]


def cell(path: Path, start: float) -> tuple[bool, float, float, list[str]]:
    """(safe tier, the backup's safe radius in m, omega_bar_xy in m/s, failed conditions) of ``path`` certified with
    the fixed point started at ``start`` x the plans-only bound and no other start (the module's restored after)."""
    import verify
    import verify.vehicle.compose as compose
    from tubekit.scenario import load_scenario
    before, restarts = compose._INFLATE, compose.FIXED_POINT_RESTARTS
    compose._INFLATE, compose.FIXED_POINT_RESTARTS = float(start), ()  # this one start only
    compose._SOLVED.clear()
    try:
        cert = verify.certify(load_scenario(path))
    finally:
        compose._INFLATE, compose.FIXED_POINT_RESTARTS = before, restarts
        compose._SOLVED.clear()
    return (bool(cert.tiers.safe), float(cert.backup.safe_set.level), float(cert.disturbance.omega_xy),
            [c.condition for c in cert.failures])


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenarios", nargs="*", type=Path, default=list(SCENARIOS))
    parser.add_argument("--starts", type=float, nargs="+", default=list(STARTS))
    args = parser.parse_args(argv)
    print("| scenario | start (x plans-only E) | safe tier | safe radius (m) | omega_bar_xy (m/s) |")
    print("|---|---|---|---|---|")
    for path in args.scenarios:
        for start in args.starts:
            safe, radius, omega, _ = cell(path, start)
            print(f"| {path.name} | {start:g} | {'certified' if safe else 'no'} | {radius:g} | {omega:.3f} |",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
