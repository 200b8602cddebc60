"""What stands between the BlueROV2 Heavy on the paper's currents and a certificate (issue 22).

Prints, for coefficient boxes from the published spread down to von Benzon's point, the velocity loop's
derived error bound E (``verify.vehicle.bound.velocity_loop_bound``) with the plans' jumps alone and with
the backup's per-tick jumps, the hull's sway bound γ̄, and the resulting ω̄_xy on the paper's currents
against what ``keep_up[u]`` and ``yaw_budget`` allow (``docs/plant.md`` section 4).

``--rates`` adds what the backup's command rate costs: E for per-tick jumps of 0 and (0.003, 0.0013, 0.003)
(the continuous backup's, at safe radii 4.6-5.5 m) on von Benzon's point, on the same point with linear drag
only (no slope variation, no mismatch: the loop's own ramp error), at loop bandwidths 10-25 rad/s, and on
boxes of ±5 % and ±20 %; and, for two favourable variants of the paper's scenario (``favourable_scenario``:
the paper's speeds with a small current; ``slow_scenario``: a slow vehicle box, target and current), the first
round of :func:`verify.vehicle.compose.solve_dynamic`'s fixed point (E assumed, ω̄, the backup designed for it,
its per-tick jumps, E derived: the ratio derived/assumed is how far the fixed point is from closing) and the
certificate's failed conditions.

Usage: ``python benchmarks/dynamic_gap.py [--rates]``
"""

from __future__ import annotations

import math
import sys

from tubekit.model.vehicles import VEHICLES
from verify.theorem.design import hull_sway_bound
from verify.vehicle.bound import velocity_loop_bound

#: von Benzon et al. (2022): the BlueROV2 Heavy's coefficients (kg, kg/s, kg/m; docs/plant.md section 3.2).
VON_BENZON = {"X_udot": -6.36, "Y_vdot": -7.12, "Z_wdot": -18.69, "N_rdot": -0.2215, "X_u": -13.7, "Y_v": 0.0,
              "Z_w": -33.0, "N_r": 0.0, "X_uu": -141.0, "Y_vv": -217.0, "Z_ww": -190.0, "N_rr": -1.5}
V = (0.4, 0.3, 0.5)            # the paper's input box (m/s, m/s, rad/s)
PLAN_JUMPS = (0.01, 0.01, 0.02)  # rate (0.1, 0.1, 0.2) x delta 0.1 s
BACKUP_JUMPS = (0.0035, 0.0016, 0.0069)  # the continuous backup at c = 2.65-3 m (verify.backup.backup_tick_change)
CURRENT_XY = 0.1               # the paper's current amplitude (m/s)
KEEP_UP = 0.4 - 0.1885         # u_max - the circle's speed pi/50 * 3 m (m/s)
YAW_BUDGET = 0.5 * 0.5         # r_max * epsilon (m/s)


def _box(f: float):
    """von Benzon's values ±``f`` (a fraction) on every nonzero coefficient; ``f`` = 0: the point."""
    return VEHICLES["bluerov2_heavy"].with_overrides(
        {k: ((v * (1 + f), v * (1 - f)) if (v and f) else v) for k, v in VON_BENZON.items()})


def boxes():
    """(label, vehicle): the published box, then von Benzon's values ±10 %, ±2 %, and the point."""
    yield "published box", VEHICLES["bluerov2_heavy"]
    for f in (0.1, 0.02, 0.0):
        yield f"von Benzon ±{round(f * 100)}%", _box(f)


#: The continuous backup's per-tick jumps at safe radii 4.6-5.5 m (the candidates the design grid tries on the
#: favourable scenario, refuted there by ``backup_level_set``; ``verify.backup.backup_tick_change``), rounded up.
GENTLE_BACKUP_JUMPS = (0.003, 0.0013, 0.003)
#: The favourable variant's command box (m/s, m/s, rad/s): the paper's with r_max 0.3 (less sway).
FAVOURABLE_V = (0.4, 0.3, 0.3)


def _point(**over: float):
    """von Benzon's point with ``over`` applied (e.g. a loop bandwidth, or linear drag)."""
    return VEHICLES["bluerov2_heavy"].with_overrides({**VON_BENZON, **over})


def rate_rows():
    """(label, E) for the backup's per-tick jumps on the variants of the module doc."""
    linear = {"X_uu": 0.0, "Z_ww": 0.0, "N_rr": 0.0, "X_u": -60.0, "Z_w": -60.0, "N_r": -0.5}
    variants = [("point, bandwidth 10 rad/s", _point()), ("point, linear drag only", _point(**linear))]
    variants += [(f"point, bandwidth {bw:g} rad/s", _point(loop_bandwidth=bw)) for bw in (15.0, 20.0, 25.0)]
    variants += [("von Benzon ±5 %", _box(0.05)), ("von Benzon ±20 %", _box(0.2))]
    for name, params in variants:
        for tick in ((0.0, 0.0, 0.0), GENTLE_BACKUP_JUMPS):
            b = velocity_loop_bound(params, v_max=FAVOURABLE_V, tick=0.01, period=0.1, jump_tick=tick,
                                    jump_period=tuple(max(a, c) for a, c in zip(PLAN_JUMPS, tick)))
            yield f"{name}, per-tick {tick}", b
    held = tuple(10 * j for j in GENTLE_BACKUP_JUMPS)  # the backup's command held for a period instead
    yield (f"point, backup held per period {held}",
           velocity_loop_bound(_point(), v_max=FAVOURABLE_V, tick=0.01, period=0.1, jump_tick=(0.0, 0.0, 0.0),
                               jump_period=held))
    published = VEHICLES["bluerov2_heavy"]
    fixed = {k: 0.5 * sum(getattr(published, k)) for k in ("X_udot", "Y_vdot", "Z_wdot", "N_rdot", "X_u", "Y_v",
                                                           "Z_w", "N_r")}
    yield ("published box, only the quadratic drags as intervals, plans only",
           velocity_loop_bound(published.with_overrides(fixed), v_max=FAVOURABLE_V, tick=0.01, period=0.1,
                               jump_tick=(0.0, 0.0, 0.0), jump_period=PLAN_JUMPS))


def favourable_scenario():
    """The paper's currents scenario made as easy as tried: von Benzon's point (no interval), current amplitude
    0.03 m/s, r_max 0.3 rad/s, ε = 1 m (start 1.5 m from the target)."""
    from tubekit.scenario import load_scenario
    base = load_scenario("examples/bluerov2_currents.toml")
    plant = base.plant.__class__(kind="dynamic", vehicle="bluerov2_heavy", overrides=tuple(VON_BENZON.items()))
    return base.with_changes(name="favourable", plant=plant, epsilon=1.0, initial_state=(-1.5, 3.0, 0.2, 0.0),
                             **{"limits.r_max": FAVOURABLE_V[2], "disturbance.amplitude": (0.03, 0.03, 0.03)})


def slow_scenario():
    """A slow variant: von Benzon's point, V = (0.2, 0.15, 0.2), current amplitude 0.02 m/s, the circle at
    π/120 rad/s (0.079 m/s), ε = 0.75 m (start 1 m from the target)."""
    base = favourable_scenario()
    return base.with_changes(name="slow", epsilon=0.75, initial_state=(-1.0, 3.0, 0.2, 0.0),
                             **{"limits.u_max": 0.2, "limits.w_max": 0.15, "limits.r_max": 0.2,
                                "disturbance.amplitude": (0.02, 0.02, 0.02), "trajectory.rate": math.pi / 120})


def first_round(sc) -> None:
    """Print the first round of the fixed point of ``sc`` (module doc) and the certificate's failures."""
    import verify
    from verify.theorem.gains import gain_bounds
    from verify.kernel.region import Region
    from verify.vehicle import compose  # its private steps, so the round is the certificate's own
    v_max = tuple(float(x) for x in sc.limits.vector)
    plans = velocity_loop_bound(sc.plant.params, v_max=v_max, tick=0.01, period=0.1, jump_tick=(0.0, 0.0, 0.0),
                                jump_period=compose.plan_jumps(sc))
    assumed = tuple(compose._INFLATE * e for e in plans.error)
    sway = compose._first_sway(sc, plans, compose._INFLATE)  # the first assumed sway (None: the free hull's)
    region = Region.from_scenario(sc)
    gains = gain_bounds(sc.controller.law, region)
    dist, _, _, _, backup = compose._tiers_at(sc, region, gains, (0.0,), assumed, sway, compose.plans_only_bound(sc))
    loop = compose._loop_at(sc, backup.law, backup.safe_set, dist, assumed)
    ratio = compose._loop_ratio(loop, assumed, sway)
    law = backup.law
    print(f"{sc.name}: round 1 assumes E = {[round(a, 4) for a in assumed]} -> omega_xy {dist.omega_xy:.4f} "
          f"(gamma {dist.gamma:.4f}); backup u_b {law.surge:.3g} k {law.yaw_rate:.3g} band {law.yaw_band:.3g} "
          f"safe radius {backup.safe_set.level:.3g} m, certified {backup.certified}; derived E = "
          f"{[round(x, 4) for x in loop.error]}: derived/assumed {ratio:.3g}")
    cert = verify.certify(sc, law=sc.controller.law)
    print(f"{sc.name}: certificate failed {[c.condition for c in cert.failures]}")


def rates() -> None:
    """Print the backup-rate table and the favourable variants' first rounds and verdicts."""
    for label, b in rate_rows():
        print(f"{label:58s} E = {[round(x, 4) for x in b.error]}, gamma = {b.sway:.4f}; "
              f"failed {[c.condition for c in b.failures]}")
    for sc in (favourable_scenario(), slow_scenario()):
        first_round(sc)


def main() -> None:
    """Print the table of docs/plant.md section 4 (and, with ``--rates``, the backup-rate table)."""
    if "--rates" in sys.argv[1:]:
        rates()
        return
    for name, params in boxes():
        for tick in ((0.0, 0.0, 0.0), BACKUP_JUMPS):
            b = velocity_loop_bound(params, v_max=V, tick=0.01, period=0.1, jump_tick=tick,
                                    jump_period=tuple(max(a, c) for a, c in zip(PLAN_JUMPS, tick)))
            e = b.error
            wxy = CURRENT_XY + math.hypot(e[0], b.sway) if math.isfinite(e[0]) else math.inf
            print(f"{name:18s} per-tick jumps {tick}: E = {[round(x, 3) for x in e]}, gamma = {b.sway:.3f}, "
                  f"omega_xy = {wxy:.3f} (keep_up allows {KEEP_UP:.3f}, yaw_budget {YAW_BUDGET:.3f}); "
                  f"failed {[c.condition for c in b.failures]}")
    for name in ("remus100", "bluerov2_heavy"):
        p = VEHICLES[name]
        print(f"{name}: gamma over V (E = 0) {float(hull_sway_bound(p, *V[::2]).upper()):.3f} over the box, "
              f"{float(hull_sway_bound(p.nominal, *V[::2]).upper()):.3f} at the nominal point")


if __name__ == "__main__":
    main()
