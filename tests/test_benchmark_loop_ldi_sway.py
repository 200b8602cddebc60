"""benchmarks/loop_ldi_sway.py: the coupled LDI what-if with the sway regulated."""

from __future__ import annotations

import math

from .scripts import load_script


def test_a_regulated_sway_closes_the_coupled_bound_where_the_free_hulls_does_not(monkeypatch):
    """Property: on von Benzon's values ±10 % the coupled LDI diverges in yaw with the hull's free sway (the
    study's own, tests/test_benchmark_loop_ldi.py) and closes, inside its cap, once the sway's bound and rate are
    those of a regulated sway (0.005 m/s, 0.05 m/s²)."""
    mod = load_script("benchmarks/loop_ldi_sway.py", "bench_loop_ldi_sway")
    monkeypatch.setattr(mod.loop_ldi, "CAP_FRACTIONS", (0.25,))            # one cap: fewer SDPs
    [(label, case, bound)] = list(mod.rows(boxes=("von Benzon ±10 %",), cases=((0.005, 0.05),)))
    assert bound.closed and all(0.0 < e < c for e, c in zip(bound.error, bound.cap)), bound.why
    free = mod.coupled(dict(mod.loop_ldi._boxes())[label], None)
    assert not free.closed and free.error == (math.inf,) * 3 and "E_r" in free.why
