"""How far rate-limited plans are from a tracking tier: the row faces' rate conditions against J, measured.

Under rate-limited plans X_f has row faces |v_{N−1} − κ_f(x_N)| <= S, and the completion's row is within the plans'
jump J = ρ δ of the plan's last when S + K(deviation) <= J per channel (``terminal_rate[u|w|r]``,
:mod:`verify.theorem.terminal_rows`, ``docs/verify.md`` step 17c). This study asks, for a scenario with its plans'
rates scaled, how near the law family comes: the tracking design is certified as usual, the row-faced sets are
searched on a finer grid (X_f's lower end at every twentieth of the free e_d band, narrower widths, every gain factor
of the shipped search), and among the sets whose every other law condition holds (inputs, invariance, region, the
faces' own invariance) it reports the smallest largest ratio (S + K(deviation)) / J over the three channels, and
that set's ratio per channel: below 1 the rate rows are proved. Nothing is timed.

Usage: ``python benchmarks/terminal_rate.py [--scenario FILE] [--rate-scale 1 2 ...]``
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import Iterator

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_slow.toml"
#: The finer grid: X_f's lower end at every twentieth of the free band, and narrower widths.
LOWER_ENDS = tuple(i / 20 for i in range(20))
WIDTHS = (1.0, 0.6, 0.35, 0.2, 0.1, 0.05)
CHANNELS = ("u", "w", "r")

__all__ = ["finer_grid", "study", "main", "SCENARIO", "LOWER_ENDS", "WIDTHS"]


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


def _ratios(conds) -> dict[str, float] | None:
    """(S + K(deviation)) / J per channel from a set's conditions, None when another law condition fails."""
    if any(not c.ok for c in conds if not c.condition.startswith("terminal_rate[")):
        return None
    return {c.condition[len("terminal_rate["):-1]: c.lhs / c.rhs for c in conds
            if c.condition.startswith("terminal_rate[")}


def study(path: Path = SCENARIO, rate_scale: float = 1.0) -> dict:
    """The sets tried, those whose other law conditions hold, and the nearest one's ratios (module doc)."""
    import verify
    from tubekit.scenario import load_scenario
    from verify.theorem.terminal import TERMINAL_PREFIXES, _sets, law_conditions, terminal_bounds

    sc = load_scenario(path)
    if sc.limits.rate is None:
        raise SystemExit(f"{path}: no limits.rate, nothing to ask")
    sc = sc.with_changes(**{"limits.rate": [rate_scale * float(r) for r in sc.limits.rate]})
    cert = verify.certify(sc)
    out: dict = {"scenario": sc.name, "rate_scale": rate_scale, "tiers": [cert.tiers.safe, cert.tiers.tracking],
                 "failed": sorted(c.condition for c in cert.failures if not c.condition.startswith(TERMINAL_PREFIXES))}
    if out["failed"]:
        return out
    b = terminal_bounds(sc, cert.design, cert.region)
    with finer_grid():
        laws = _sets(b)
    ratios = [(r, law) for law in laws if (r := _ratios(law_conditions(b, law))) is not None]
    out.update(sets=len(laws), candidates=len(ratios), jump=list(b.jumps))
    if ratios:
        best, law = min(ratios, key=lambda rl: max(rl[0].values()))
        out.update(best={c: best[c] for c in CHANNELS}, worst=max(best.values()),
                   law={k: round(v, 6) for k, v in law.to_dict().items()})
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", type=Path, default=SCENARIO, help="a scenario with limits.rate")
    ap.add_argument("--rate-scale", type=float, nargs="+", default=[1.0],
                    help="factors on the plans' limits.rate (each re-certified)")
    args = ap.parse_args(argv)
    for scale in args.rate_scale:
        res = study(args.scenario, scale)
        head = f"{res['scenario']}, plans' rates x{scale:g}"
        if res["failed"]:
            print(f"{head}: not certified beyond the terminal ingredients ({', '.join(res['failed'][:4])})")
            continue
        if "best" not in res:
            print(f"{head}: {res['sets']} row-faced sets, none meets the other law conditions")
            continue
        per = ", ".join(f"{c} {res['best'][c]:.3g}x" for c in CHANNELS)
        verdict = "the rate rows are proved" if res["worst"] <= 1.0 else f"short by {res['worst']:.3g}x"
        print(f"{head}: {res['sets']} row-faced sets, {res['candidates']} meet the other law conditions; the nearest "
              f"needs (S + K(deviation)) / J = {per} ({verdict}); J = {', '.join(f'{j:.4g}' for j in res['jump'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
