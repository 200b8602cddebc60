"""Shared FHOCP test cases: the paper's scenario, states of a closed-loop run, a stand-in tightening."""

from __future__ import annotations

from tubekit import Tightening, paper_scenario

__all__ = ["SC", "OBSTACLES", "RUN_STATES", "STATES", "tightening"]

SC = paper_scenario()
OBSTACLES = SC.obstacles

# (t, [x, y, z, psi]) from a closed-loop run of the paper's scenario (real-time SCP, current, no
# ancillary feedback). All but t = 2 and t = 25 have an obstacle within the sensing range; around
# t = 12.5 s and t = 37.5 s the target passes through the obstacles at (3, 0, 0) and (-3, 0, 0);
# the states at t = 13, 14, 18, 38, 40 cannot satisfy every constraint (exact penalties active).
RUN_STATES = [
    (2.0, (0.366391, 3.058573, 0.042219, -0.314108)),
    (8.0, (2.408496, 1.684077, 0.002093, -0.791507)),
    (10.0, (2.729238, 1.022535, -0.044875, -0.944917)),
    (11.0, (2.823856, 0.703198, -0.060977, -1.028208)),
    (11.5, (2.816904, 0.627813, -0.071890, -1.095484)),
    (12.0, (2.780420, 0.612101, -0.094783, -1.160212)),
    (12.5, (2.752812, 0.587167, -0.171836, -1.220204)),
    (13.0, (2.724617, 0.552259, -0.360607, -1.437308)),
    (14.0, (2.649950, 0.233913, -0.513972, -1.672372)),
    (18.0, (2.600518, -1.022124, 0.039766, -1.947965)),
    (25.0, (0.598401, -2.953194, -0.044877, -3.067312)),
    (34.0, (-2.569253, -1.390771, 0.061709, -3.996323)),
    (36.0, (-2.820464, -0.810078, 0.048961, -4.283171)),
    (37.0, (-2.876056, -0.650980, 0.039729, -4.449376)),
    (38.0, (-2.871776, -0.723955, 0.181552, -4.792900)),
    (40.0, (-2.810729, -0.116418, 0.600552, -4.887246)),
]

# the states above at t = 2, 8, 10, 11, 12, 25: the obstacle at (3, 0, 0) is within the sensing
# range for every state but the first and the last
STATES = [(t, s) for t, s in RUN_STATES if t in (2.0, 8.0, 10.0, 11.0, 12.0, 25.0)]


def tightening(scenario=SC) -> Tightening:
    """The untightened sets with e_d_min + 5 cm and a 5 cm obstacle margin (no certificate needed); it states both
    tiers, so a backup added to it is enforced as a certified one would be (the terminal rows)."""
    from tubekit.tiers import Tiers
    reg = scenario.region
    return Tightening(v_max=scenario.limits.vector.copy(), e_d_min=scenario.epsilon + 0.05,
                      e_o_max=reg.e_o_max, e_z_max=reg.e_z_max, e_d_max=reg.e_d_max,
                      obstacle_margin=0.05, sigma=0.0, tiers=Tiers(True, True))


def backup_plan():
    """A station-keeping backup (the values verify.backup.design_backup certifies on the paper's bounds):
    safe radius c = 0.8 m, shape 0.45, depth 0.1 m; footprint (1.0, 0.3) m with the 0.2 m vehicle."""
    from tubekit.model.backup import BackupPlan, SafeSet, StationKeeping
    return BackupPlan(StationKeeping(0.2, 0.5, 0.05, 0.3, 0.05), SafeSet(0.8, 0.45, 0.1), handover=(0.35, 0.1))
