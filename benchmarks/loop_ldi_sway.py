"""A what-if of the LDI study: the coupled velocity-loop bound with the sway regulated by its own loop.

Usage::

    python benchmarks/loop_ldi_sway.py

:mod:`loop_ldi` (a study, not in the certificate) bounds the channels u, w, r as polytopic differential inclusions
coupled through the other body accelerations, with the hull's free sway: over wider coefficient boxes its yaw
channel diverges, driven by the sway (the Munk moment and the sway row). A vehicle with lateral thrust regulates its
sway to 0 (``docs/verify.md`` section 9, step 1b), so |v| and |v̇| are small. This script reruns the coupled fixed
point of :func:`loop_ldi.ldi_bound` on ``examples/bluerov2_slow.toml``'s command box with the sway's bound and rate
*assumed* at a few values (what the sway loop's own bound, E_v and its sup|v̇|, would have to give; the certificate
derives them by the small-gain bound, about 0.003-0.005 m/s), beside the free hull's, per coefficient box. Nothing
is timed; every Lyapunov function it uses is proved in Arb as in :mod:`loop_ldi`.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Iterator, Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))
import loop_ldi  # noqa: E402 - the study this what-if reruns

from verify.vehicle.loop_data import loop_data_of  # noqa: E402

__all__ = ["SWAY_CASES", "BOXES", "coupled", "rows", "main"]

#: (|v| bound m/s, |v̇| bound m/s²) assumed for the regulated sway; None: the free hull's (the study's own).
SWAY_CASES: tuple[tuple[float, float] | None, ...] = (None, (0.005, 0.05), (0.01, 0.1))
#: The coefficient boxes of :func:`loop_ldi._boxes` this what-if runs on.
BOXES = ("von Benzon ±10 %", "von Benzon ±20 %", "published box")
V_SLOW, PLANS = (0.3, 0.15, 0.2), (0.003, 0.003, 0.006)


def coupled(params, sway: tuple[float, float] | None) -> "loop_ldi.LdiBound":
    """The coupled LDI bound on :data:`V_SLOW` with the plans' jumps, the sway as ``sway`` assumes (None: the hull)."""
    if sway is None:
        return loop_ldi.study_bound(params, V_SLOW, (0.0, 0.0, 0.0), PLANS)
    loop = loop_data_of(params, V_SLOW, 0.01, 10)
    return loop_ldi.ldi_bound(params, v_max=V_SLOW, k_p=loop.k_p, k_i=loop.k_i, lag=loop.lag, tick=0.01, ticks=10,
                              jump_tick=(0.0, 0.0, 0.0), jump_period=PLANS,
                              sway_bound=lambda u, r: sway[0], sway_rate=lambda box, gamma, accel: sway[1])


def rows(boxes: Sequence[str] = BOXES, cases=SWAY_CASES) -> Iterator[tuple[str, object, "loop_ldi.LdiBound"]]:
    """(box label, sway case, bound) for every box and case."""
    vehicles = dict(loop_ldi._boxes())
    for label in boxes:
        for case in cases:
            yield label, case, coupled(vehicles[label], case)


def main() -> int:
    print(f"coupled LDI fixed point on V = {V_SLOW}, plan jumps {PLANS} per period, h = 0.01 s, delta = 0.1 s")
    for label, case, b in rows():
        sway = "the hull's free sway" if case is None else f"sway regulated: |v| <= {case[0]}, |vdot| <= {case[1]}"
        result = f"E = {[round(x, 4) for x in b.error]}" if b.closed else f"open ({b.why})"
        print(f"  {label:18s} {sway:48s} {result}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
