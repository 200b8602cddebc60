"""What stands between the BlueROV2 Heavy on the paper's currents and a certificate (issue 22).

Prints, for coefficient boxes from the published spread down to von Benzon's point, the velocity loop's
derived error bound E (``verify.vehicle.bound.velocity_loop_bound``) with the plans' jumps alone and with
the backup's per-tick jumps, the hull's sway bound γ̄, and the resulting ω̄_xy on the paper's currents
against what ``keep_up[u]`` and ``yaw_budget`` allow (``docs/plant.md`` section 4).

Usage: ``python benchmarks/dynamic_gap.py``
"""

from __future__ import annotations

import math

from tubekit.model.vehicles import VEHICLES
from verify.design import hull_sway_bound
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


def boxes():
    """(label, vehicle): the published box, then von Benzon's values ±10 %, ±2 %, and the point."""
    yield "published box", VEHICLES["bluerov2_heavy"]
    for f in (0.1, 0.02, 0.0):
        over = {k: ((v * (1 + f), v * (1 - f)) if (v and f) else v) for k, v in VON_BENZON.items()}
        yield f"von Benzon ±{round(f * 100)}%", VEHICLES["bluerov2_heavy"].with_overrides(over)


def main() -> None:
    """Print the table of docs/plant.md section 4."""
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
