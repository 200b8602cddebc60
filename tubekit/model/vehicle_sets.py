"""The shipped vehicles: REMUS 100 (fins and propeller) and BlueROV2 Heavy (eight T200 thrusters).

Both carry the published spread as intervals where two sources disagree (``docs/plant.md``,
section 3, lists each parameter beside its published values and says which was chosen).

* :data:`REMUS100`: the defaults of :class:`~tubekit.model.vehicle_params.VehicleParams`
  (Prestero 2001 and Fossen's MSS ``remus100.m``), actuation ``"fins"``.
* :data:`BLUEROV2_HEAVY`: von Benzon et al. (2022) / Wu (2018) and Einarsson & Lipenitis
  (2020) for the hydrodynamics; thrust limits from the Blue Robotics T200 datasheet and the
  Heavy configuration's thruster geometry (:func:`bluerov2_heavy_limits`), actuation ``"thrusters"``.
"""

from __future__ import annotations

import math

from tubekit.model.vehicle_params import VehicleParams

__all__ = ["REMUS100", "BLUEROV2_HEAVY", "VEHICLES", "bluerov2_heavy_limits", "bluerov2_heavy_sway_limit",
           "T200_REVERSE_KGF_16V", "HEAVY_HORIZONTAL_POSITION", "HEAVY_SURGE_SHARE", "HEAVY_SWAY_SHARE",
           "STANDARD_GRAVITY"]

STANDARD_GRAVITY = 9.80665   # m/s², kgf -> N
#: Blue Robotics T200 datasheet: maximum reverse thrust at 16 V (kgf). Reverse is the weaker
#: direction; a symmetric limit must use it.
T200_REVERSE_KGF_16V = 4.1
#: |x|, |y| (m) of the four vectored horizontal thrusters (45°) of the Heavy configuration
#: (von Benzon et al. 2022 thruster configuration, after Wu 2018).
HEAVY_HORIZONTAL_POSITION = (0.156, 0.111)
#: Share of each horizontal thruster's thrust given to surge (a design choice); :data:`HEAVY_SWAY_SHARE` to sway, the
#: rest (0.25) to yaw.
HEAVY_SURGE_SHARE = 0.65
#: Share of each horizontal thruster's thrust given to sway: the lateral force the sway loop regulates with.
HEAVY_SWAY_SHARE = 0.10


def bluerov2_heavy_limits(thrust_kgf: float = T200_REVERSE_KGF_16V, surge_share: float = HEAVY_SURGE_SHARE,
                          sway_share: float = HEAVY_SWAY_SHARE) -> tuple[float, float, float]:
    """(X_max, Z_max, N_max) in N, N, N m of the BlueROV2 Heavy with per-thruster thrust ``thrust_kgf``.

    Four vertical thrusters give Z_max = 4T. Each of the four horizontal thrusters at 45°
    gives surge T cos 45°, sway T sin 45° and yaw moment T d, d = (|x| + |y|) sin 45° (m). With
    the allocation f_i = X/(4 cos 45°) ± Y/(4 sin 45°) ± N/(4 d), |f_i| <= T for every
    |X| <= s_X·4T cos 45°, |Y| <= s_Y·4T sin 45°, |N| <= (1 − s_X − s_Y)·4T d (s_X = ``surge_share``,
    s_Y = ``sway_share``, :func:`bluerov2_heavy_sway_limit`): the box of limits is producible.
    """
    if not (0.0 <= surge_share and 0.0 <= sway_share and surge_share + sway_share <= 1.0):
        raise ValueError(f"bluerov2_heavy_limits: shares >= 0 with surge + sway <= 1, received {surge_share}, "
                         f"{sway_share}")
    thrust = thrust_kgf * STANDARD_GRAVITY
    c = math.cos(math.pi / 4)
    arm = (HEAVY_HORIZONTAL_POSITION[0] + HEAVY_HORIZONTAL_POSITION[1]) * math.sin(math.pi / 4)
    return surge_share * 4 * thrust * c, 4 * thrust, (1 - surge_share - sway_share) * 4 * thrust * arm


def bluerov2_heavy_sway_limit(thrust_kgf: float = T200_REVERSE_KGF_16V, sway_share: float = HEAVY_SWAY_SHARE) -> float:
    """Y_max (N): the lateral force s_Y·4T sin 45° the Heavy's box reserves (:func:`bluerov2_heavy_limits`)."""
    return sway_share * 4 * thrust_kgf * STANDARD_GRAVITY * math.sin(math.pi / 4)


#: REMUS 100 (Prestero 2001; Fossen's MSS remus100.m): fins and propeller, intervals where they disagree.
REMUS100 = VehicleParams()

_X, _Z, _N = bluerov2_heavy_limits()
_Y = bluerov2_heavy_sway_limit()

#: BlueROV2 Heavy: von Benzon et al. 2022 (= Wu 2018) against Einarsson & Lipenitis 2020 (intervals).
BLUEROV2_HEAVY = VehicleParams(
    m=13.5, I_zz=0.37, x_g=0.0,                                    # kg, kg m², m (von Benzon)
    X_udot=(-6.36, -2.6), Y_vdot=(-18.5, -7.12), Z_wdot=(-18.69, -13.3), N_rdot=(-0.28, -0.2215),
    Y_rdot=0.0, N_vdot=0.0,
    X_u=(-13.7, -0.09), Y_v=(-0.26, 0.0), Z_w=(-33.0, -0.19), N_r=(-4.64, 0.0),
    X_uu=(-141.0, -34.96), Y_vv=(-217.0, -103.25), Y_rr=0.0, Z_ww=(-190.0, -74.23), N_vv=0.0,
    N_rr=(-1.5, -0.43),
    Y_uv=0.0, Y_ur_lift=0.0, Z_uw=0.0, N_uv_lift=0.0, N_ur_lift=0.0,  # a box frame: no lift identified
    # rounded down: a limit the certificate reads must be producible (round(4T, 2) = 160.83 > 4T = 160.829 N)
    X_max=math.floor(_X * 100) / 100, Z_max=math.floor(_Z * 100) / 100, N_max=math.floor(_N * 1000) / 1000,
    Y_max=math.floor(_Y * 100) / 100,                              # N, lateral: the sway loop's force
    Z_uuds=0.0, N_uudr=0.0, fin_max=0.0,
    thruster_time_constant=0.05,                                   # s, assumption (T200 ESC + motor)
    loop_bandwidth=10.0,                                           # rad/s, ω_b T_thr = 0.5 as REMUS
    actuation="thrusters",
)

#: Shipped parameter sets by name.
VEHICLES: dict[str, VehicleParams] = {"remus100": REMUS100, "bluerov2_heavy": BLUEROV2_HEAVY}
