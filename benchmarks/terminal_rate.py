"""Why rate-limited plans get no tracking tier: the terminal law's rows move more per period than J allows.

The tracking theorem (``verify.theorem.terminal``) completes the shifted candidate with one row of a memoryless
terminal law κ_f(x) and refuses plans with a rate limit (``terminal_rate``): the completion's row would have to be
within J = ρ δ of the plan's last. This what-if asks whether that could be proved for the law family as it is.

For a scenario (default ``examples/bluerov2_slow.toml``) the tracking design is certified as usual and the law
family of :func:`verify.theorem.terminal.design_terminal` is searched on a finer grid (X_f's lower end anywhere in
the free e_d band, narrower widths; everything else as shipped). For every set whose own conditions all hold
(inputs, invariance, region: ``law_conditions``), two lower bounds of how far one period's replay deviation alone
(D_xy, D_ψ of the certified one-period tube) moves the law's row, at a state of X_f with d = d_lo:

* yaw: r = −g α / δ, and the deviation turns α by D_ψ + atan(D_xy / d_lo):
  |Δr| >= g (D_ψ + atan(D_xy / d_lo)) / δ;
* surge: u = (V_r + λ (d − d*)) / (S cos) with S cos <= 1, and the deviation moves d by D_xy: |Δu| >= λ D_xy.

Where both exceed J for every invariant set, no plan check can make the memoryless law's completion meet the rate
rows: the candidate would need a law that keeps the last command as a state. Nothing is timed.

Usage: ``python benchmarks/terminal_rate.py [--scenario FILE]``
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from pathlib import Path
from typing import Iterator

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_slow.toml"
#: The finer grid: X_f's lower end at every twentieth of the free band, and narrower widths.
LOWER_ENDS = tuple(i / 20 for i in range(20))
WIDTHS = (1.0, 0.6, 0.35, 0.2, 0.1, 0.05)


@contextlib.contextmanager
def finer_grid() -> Iterator[None]:
    """``verify.theorem.terminal``'s grid replaced by :data:`LOWER_ENDS`, :data:`WIDTHS` (restored after)."""
    import verify.theorem.terminal as terminal
    saved = terminal.LOWER_ENDS, terminal.WIDTHS
    terminal.LOWER_ENDS, terminal.WIDTHS = LOWER_ENDS, WIDTHS
    try:
        yield
    finally:
        terminal.LOWER_ENDS, terminal.WIDTHS = saved


def study(path: Path = SCENARIO) -> dict:
    """The sets tried, the invariant ones and the smallest deviation-only row changes against J (module doc)."""
    import verify
    from tubekit.scenario import load_scenario
    from verify.theorem.terminal import _sets, law_conditions, terminal_bounds

    sc = load_scenario(path)
    if sc.limits.rate is None:
        raise SystemExit(f"{path}: no limits.rate, nothing to ask")
    cert = verify.certify(sc)
    b = terminal_bounds(sc, cert.design, cert.region)
    with finer_grid():
        laws = _sets(b)
    invariant = [law for law in laws if all(c.ok for c in law_conditions(b, law))]
    jump = [float(r) * b.dt for r in sc.limits.rate]
    yaw = [law.turn * (b.dev_psi + math.atan(b.dev_xy / law.d_lo)) / b.dt for law in invariant]
    surge = [law.gain_d * b.dev_xy for law in invariant]
    return {"scenario": sc.name, "sets": len(laws), "invariant": len(invariant), "jump": jump,
            "deviation": {"xy": b.dev_xy, "psi": b.dev_psi},
            "d_lo_range": [min((law.d_lo for law in invariant), default=math.nan),
                           max((law.d_lo for law in invariant), default=math.nan)],
            "least_yaw_change": min(yaw, default=math.nan), "least_surge_change": min(surge, default=math.nan)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", type=Path, default=SCENARIO, help="a scenario with limits.rate")
    args = ap.parse_args(argv)
    res = study(args.scenario)
    j = res["jump"]
    print(f"{res['scenario']}: {res['sets']} sets of the finer grid, {res['invariant']} meet every law condition "
          f"(d_lo {res['d_lo_range'][0]:.3f}-{res['d_lo_range'][1]:.3f} m); one period's replay deviation "
          f"D_xy = {res['deviation']['xy']:.4g} m, D_psi = {res['deviation']['psi']:.4g} rad")
    print(f"  least yaw-row change from the deviation alone: {res['least_yaw_change']:.4g} rad/s "
          f"against J_r = {j[2]:.4g} ({res['least_yaw_change'] / j[2]:.2f}x)")
    print(f"  least surge-row change from the deviation alone: {res['least_surge_change']:.4g} m/s "
          f"against J_u = {j[0]:.4g} ({res['least_surge_change'] / j[0]:.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
