"""The vehicle of the velocity loop in Arb: coefficient box, forces n(ν), their gradient, the channels.

The plant is M ν̇ + n(ν; θ) = τ with n(ν) = C(ν)ν + D(ν)ν (``tubekit.plant.dynamic.body_forces``;
``verify`` may not import the plant, so :func:`arb_body_forces` mirrors it in Arb). The true
coefficients θ lie anywhere in the vehicle's box Θ (:func:`hull_balls`: one ball per coefficient,
mass entries from the balls of m, I_zz, x_g and the added masses); the controller's feedforward
uses the nominal vehicle (:func:`nominal_balls`, exact points). n is *linear* in the generalised
coefficients (m11, m22, m24, X_u, X_u|u|, ...): so n(ν; θ̂) − n(ν; θ) = n(ν; θ̂ − θ), which
:func:`channel_mismatch` evaluates with the difference balls, free of the dependency problem.

Channels c ∈ (u, w, r): m_u = m11, n_u = n1; m_w = m33, n_w = n3; yaw with the sway row eliminated
(m22 v̇ + m24 ṙ + n2 = 0): m_r = m44 − m24 m42 / m22, n_r = n4 − (m42 / m22) n2. A vehicle with lateral
thrust (``lateral``: its sway regulated by a loop of its own, M diagonal in sway and yaw, m24 = m42 = 0) has a
fourth channel, sway: m_v = m22, n_v = n2, inserted at index 1, channels (u, v, w, r); its yaw formula is then n4.
"""

from __future__ import annotations

from typing import Mapping, Sequence

from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.vehicle_params import VehicleParams
from verify.kernel.intervals import _abs, enclose, point, upper

__all__ = ["COEFFICIENTS", "MASS_FIELDS", "field_ball", "nominal_params", "hull_balls", "nominal_balls",
           "arb_body_forces", "body_force_gradient", "body_force_hessian", "channel_forces", "channel_hessian",
           "channel_gradient", "channel_masses",
           "channel_mismatch", "channel_mismatch_gradient", "velocity_box", "thrust_floor", "point_time_constant",
           "with_sway", "without_sway", "CHANNELS", "LATERAL_CHANNELS"]

#: Hydrodynamic coefficients of n(ν) (``tubekit.model.vehicles.VehicleParams`` field names).
COEFFICIENTS = ("X_u", "X_uu", "Y_v", "Y_vv", "Y_rr", "Y_uv", "Y_ur_lift", "Z_w", "Z_ww", "Z_uw",
                "N_r", "N_rr", "N_vv", "N_uv_lift", "N_ur_lift")
#: Fields of the mass matrix.
MASS_FIELDS = ("m", "I_zz", "x_g", "X_udot", "Y_vdot", "Z_wdot", "N_rdot", "Y_rdot", "N_vdot")
_ROUND = 2.0 ** -50   # relative: covers the float rounding of a point vehicle's mass entries


def field_ball(params: VehicleParams, name: str) -> arb:
    """The ball of field ``name``: ``params.interval(name)`` (lo == hi for a point)."""
    return enclose(*params.interval(name))


def nominal_params(params: VehicleParams) -> VehicleParams:
    """The controller's point vehicle: ``params.nominal`` (every interval at its midpoint)."""
    return params.nominal


def _mass_balls(f: Mapping[str, arb]) -> dict[str, arb]:
    """m11, m22, m33, m44, m24, m42 from the field balls, widened by the float rounding of a point set."""
    m, xg = f["m"], f["x_g"]
    raw = {"m11": m - f["X_udot"], "m22": m - f["Y_vdot"], "m33": m - f["Z_wdot"], "m44": f["I_zz"] - f["N_rdot"],
           "m24": m * xg - f["Y_rdot"], "m42": m * xg - f["N_vdot"]}
    return {k: v + arb(0, upper(abs(v)) * _ROUND) for k, v in raw.items()}


def hull_balls(params: VehicleParams) -> dict[str, arb]:
    """Balls of every coefficient and mass entry over the vehicle's box Θ (the true plant)."""
    f = {name: field_ball(params, name) for name in COEFFICIENTS + MASS_FIELDS}
    return {**{k: f[k] for k in COEFFICIENTS}, **_mass_balls(f)}


def nominal_balls(params: VehicleParams) -> dict[str, arb]:
    """Exact points of the nominal vehicle (the feedforward n̂, m̂ the plant's controller uses)."""
    nom = nominal_params(params)
    out = {k: point(getattr(nom, k)) for k in COEFFICIENTS}
    out.update(zip(("m11", "m22", "m33", "m44", "m24", "m42"), (point(x) for x in nom.mass_entries)))
    return out


def arb_body_forces(c: Mapping[str, arb], nu: Sequence[arb]) -> tuple[arb, arb, arb, arb]:
    """n(ν) = C(ν)ν + D(ν)ν (N, N, N, N m) in Arb: the mirror of ``tubekit.plant.dynamic.body_forces``.

    ``c`` maps the coefficient names and m11, m22, m24 to balls; ``nu`` = (u, v, w, r) balls. The surge's products
    are factored (u (A v + B r), the Munk moment as (m22 − m11 − N_uv,lift) u v): the same function, but each ball
    enters once, so over a box the enclosure does not charge m22 u v and m11 u v as if they could add.
    """
    u, v, w, r = (arb(x) for x in nu)
    au, av, aw, ar = _abs(u), _abs(v), _abs(w), _abs(r)
    n1 = -(c["m22"] * v + c["m24"] * r) * r - (c["X_u"] + c["X_uu"] * au) * u
    n2 = u * ((c["m11"] - c["Y_ur_lift"]) * r - c["Y_uv"] * v) - (c["Y_v"] + c["Y_vv"] * av) * v - c["Y_rr"] * r * ar
    n3 = -(c["Z_w"] + c["Z_ww"] * aw + c["Z_uw"] * u) * w
    n4 = (u * ((c["m22"] - c["m11"] - c["N_uv_lift"]) * v + (c["m24"] - c["N_ur_lift"]) * r)
          - (c["N_r"] + c["N_rr"] * ar) * r - c["N_vv"] * v * av)
    return n1, n2, n3, n4


def body_force_gradient(c: Mapping[str, arb], nu: Sequence[arb]) -> tuple[tuple[arb, ...], ...]:
    """∂n_i/∂ν_j (rows n1..n4, columns u, v, w, r), by hand from :func:`arb_body_forces` (d(x|x|)/dx = 2|x|)."""
    u, v, w, r = (arb(x) for x in nu)
    au, av, aw, ar = _abs(u), _abs(v), _abs(w), _abs(r)
    m11, m22, m24, zero = c["m11"], c["m22"], c["m24"], arb(0)
    g1 = (-c["X_u"] - 2 * c["X_uu"] * au, -m22 * r, zero, -m22 * v - 2 * m24 * r)
    g2 = (m11 * r - c["Y_uv"] * v - c["Y_ur_lift"] * r, -c["Y_v"] - 2 * c["Y_vv"] * av - c["Y_uv"] * u, zero,
          m11 * u - 2 * c["Y_rr"] * ar - c["Y_ur_lift"] * u)
    g3 = (-c["Z_uw"] * w, zero, -c["Z_w"] - 2 * c["Z_ww"] * aw - c["Z_uw"] * u, zero)
    g4 = ((m22 - m11 - c["N_uv_lift"]) * v + (m24 - c["N_ur_lift"]) * r,
          (m22 - m11 - c["N_uv_lift"]) * u - 2 * c["N_vv"] * av, zero,
          (m24 - c["N_ur_lift"]) * u - c["N_r"] - 2 * c["N_rr"] * ar)
    return g1, g2, g3, g4


def _sign(x: arb) -> arb:
    """d|x|/dx over the ball ``x``: ±1 off zero, [−1, 1] where the ball holds 0 (x|x| has a Lipschitz slope 2|x|)."""
    if x > 0:
        return arb(1)
    if x < 0:
        return arb(-1)
    return arb(0, 1)


def body_force_hessian(c: Mapping[str, arb], nu: Sequence[arb]) -> tuple[tuple[tuple[arb, ...], ...], ...]:
    """∂²n_i/∂ν_j∂ν_k (i: n1..n4; j, k: u, v, w, r) over the box ``nu``, by hand from :func:`body_force_gradient`;
    where a ball holds 0 the |x| terms' second derivative 2 sign(x) is taken as [−2, 2], the Lipschitz constant of
    their slope (what the Taylor remainders of :mod:`verify.vehicle.pi_loop` read)."""
    su, sv, sw, sr = (_sign(arb(x)) for x in nu)
    m11, m22, m24, zero = c["m11"], c["m22"], c["m24"], arb(0)

    def sym(uu: arb, uv: arb, uw: arb, ur: arb, vv: arb, vr: arb, ww: arb, rr: arb) -> tuple[tuple[arb, ...], ...]:
        return ((uu, uv, uw, ur), (uv, vv, zero, vr), (uw, zero, ww, zero), (ur, vr, zero, rr))
    h1 = sym(-2 * c["X_uu"] * su, zero, zero, zero, zero, -m22, zero, -2 * m24)
    h2 = sym(zero, -c["Y_uv"], zero, m11 - c["Y_ur_lift"], -2 * c["Y_vv"] * sv, zero, zero, -2 * c["Y_rr"] * sr)
    h3 = sym(zero, zero, -c["Z_uw"], zero, zero, zero, -2 * c["Z_ww"] * sw, zero)
    h4 = sym(zero, m22 - m11 - c["N_uv_lift"], zero, m24 - c["N_ur_lift"], -2 * c["N_vv"] * sv, zero, zero,
             -2 * c["N_rr"] * sr)
    return h1, h2, h3, h4


#: The commanded channels (u, w, r), and with a sway loop (u, v, w, r): the order of every per-channel tuple.
CHANNELS, LATERAL_CHANNELS = "uwr", "uvwr"


def with_sway(channels: Sequence, sway: object, lateral: bool) -> tuple:
    """Per-channel values (u, w, r), with the sway channel's ``sway`` inserted at index 1 when ``lateral``."""
    return (channels[0], sway, channels[1], channels[2]) if lateral else tuple(channels)


def without_sway(channels: Sequence, lateral: bool) -> tuple:
    """The (u, w, r) entries of per-channel values: the sway channel (index 1) dropped when ``lateral``."""
    return (channels[0], channels[2], channels[3]) if lateral else tuple(channels)


def channel_forces(c: Mapping[str, arb], nu: Sequence[arb], lateral: bool = False) -> tuple[arb, ...]:
    """(n_u, n_w, n_r) = (n1, n3, n4 − (m42/m22) n2) (N, N, N m); ``lateral``: (n_u, n2, n_w, n_r)."""
    n1, n2, n3, n4 = arb_body_forces(c, nu)
    return with_sway((n1, n3, n4 - c["m42"] / c["m22"] * n2), n2, lateral)


def channel_gradient(c: Mapping[str, arb], nu: Sequence[arb], lateral: bool = False) -> tuple[tuple[arb, ...], ...]:
    """∂(n_u, n_w, n_r)/∂(u, v, w, r) (``lateral``: with the sway row ∂n2/∂ν at index 1)."""
    g1, g2, g3, g4 = body_force_gradient(c, nu)
    k = c["m42"] / c["m22"]
    return with_sway((g1, g3, tuple(a - k * b for a, b in zip(g4, g2))), g2, lateral)


def channel_hessian(c: Mapping[str, arb], nu: Sequence[arb],
                    lateral: bool = False) -> tuple[tuple[tuple[arb, ...], ...], ...]:
    """∂²(n_u, n_w, n_r)/∂ν∂ν (4 x 4 each; ``lateral``: with the sway row's at index 1), n_r = n4 − (m42/m22) n2."""
    h1, h2, h3, h4 = body_force_hessian(c, nu)
    k = c["m42"] / c["m22"]
    yaw = tuple(tuple(a - k * b for a, b in zip(r4, r2)) for r4, r2 in zip(h4, h2))
    return with_sway((h1, h3, yaw), h2, lateral)


def channel_masses(c: Mapping[str, arb], lateral: bool = False) -> tuple[arb, ...]:
    """(m_u, m_w, m_r) = (m11, m33, m44 − m24 m42 / m22) (kg, kg, kg m²); ``lateral``: with m22 at index 1."""
    return with_sway((c["m11"], c["m33"], c["m44"] - c["m24"] * c["m42"] / c["m22"]), c["m22"], lateral)


def channel_mismatch(nominal: Mapping[str, arb], hull: Mapping[str, arb], nu: Sequence[arb],
                     lateral: bool = False) -> tuple[arb, ...]:
    """d_c = n̂_c(ν) − n_c(ν; θ) over ν and θ ∈ Θ, by linearity: n(ν; θ̂) − n(ν; θ) = n(ν; θ̂ − θ).

    Yaw: n̂_r − n_r = Δn4 − k̂ Δn2 − (k̂ − k) n2(ν; θ), k = m42/m22. ``lateral``: with Δn2 at index 1.
    """
    delta = {key: nominal[key] - hull[key] for key in nominal}
    d1, d2, d3, d4 = arb_body_forces(delta, nu)
    k_hat, k = nominal["m42"] / nominal["m22"], hull["m42"] / hull["m22"]
    n2 = arb_body_forces(hull, nu)[1]
    return with_sway((d1, d3, d4 - k_hat * d2 - (k_hat - k) * n2), d2, lateral)


def channel_mismatch_gradient(nominal: Mapping[str, arb], hull: Mapping[str, arb],
                              nu: Sequence[arb], lateral: bool = False) -> tuple[tuple[arb, ...], ...]:
    """∂d_c/∂(u, v, w, r) of :func:`channel_mismatch`, by the same linearity (the gradient is linear in θ too)."""
    delta = {key: nominal[key] - hull[key] for key in nominal}
    g1, g2, g3, g4 = body_force_gradient(delta, nu)
    k_hat, k = nominal["m42"] / nominal["m22"], hull["m42"] / hull["m22"]
    t2 = body_force_gradient(hull, nu)[1]
    return with_sway((g1, g3, tuple(a - k_hat * b - (k_hat - k) * t for a, b, t in zip(g4, g2, t2))), g2, lateral)


def velocity_box(u: float, v: float, w: float, r: float) -> tuple[arb, arb, arb, arb]:
    """Balls [−u, u], [−v, v], [−w, w], [−r, r] of the body velocities (m/s, rad/s)."""
    return tuple(enclose(-x, x) for x in (u, v, w, r))


def thrust_floor(params: VehicleParams, u_abs_max: float, u_abs_min: float = 0.0,
                 lateral: bool = False) -> tuple[float, ...]:
    """Smallest (X, Z, N) limit over ``u_abs_min`` <= |u| <= ``u_abs_max`` (m/s) and Θ:
    ``params.thrust_limit_floor`` or the limits (a fin's force grows with u², so a surge floor gives it one);
    ``lateral``: (X, Y, Z, N), Y the smallest lateral limit over Θ (N)."""
    floor = getattr(params, "thrust_limit_floor", None)
    limits = floor(u_abs_max, min(max(u_abs_min, 0.0), u_abs_max)) if callable(floor) else params.thrust_limits
    out = tuple(float(x) for x in limits)
    return with_sway(out, float(params.interval("Y_max")[0]), lateral)


def point_time_constant(params: VehicleParams) -> float:
    """T_thr (s); a thruster lag given as an interval is refused (the loop's matrix A needs a point)."""
    ball = field_ball(params, "thruster_time_constant")
    if ball.rad() != 0:
        raise ConfigError("plant.vehicle.thruster_time_constant", "a number (the velocity-loop bound needs a "
                          "point thruster time constant)", ball.str())
    return float(nominal_params(params).thruster_time_constant)
