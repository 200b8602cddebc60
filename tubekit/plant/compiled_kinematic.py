"""The kinematic plant compiled (numba): its RK4 under the modelled current and sway, and its ω at the logged ticks.

:func:`rk4_current` integrates ẋ = f(x) v + [δ(t) + v_s (−sin ψ, cos ψ, 0), 0] (eq. 11; the formulas of
:class:`tubekit.plant.kinematic.Plant`) over ``n`` classical RK4 steps with the input held. It performs the
floating-point operations of :func:`tubekit.plant.kinematic.rk4_tuple` applied to ``Plant._rhs`` in the same
order (k3 equals k2 there: ψ's rate is r at every stage, so both stages sit at the same ψ and time; the current
and the wave sway are evaluated once per distinct stage time), so the states and the disturbance's peaks are
bit for bit the same (``tests/test_plant_compiled_kinematic.py``). :func:`omega_at_ticks` is ``Plant.omega`` at
every logged tick (``Plant.omega_series``), the same floats.

Importing this module imports numba (:class:`~tubekit.plant.kinematic.Plant` imports it at its first step); the
machine code is cached (:func:`tubekit.model.jit.routine`).
"""

from __future__ import annotations

import math

import numpy as np

from tubekit.model.jit import routine

__all__ = ["rk4_current", "omega_at_ticks", "current_at", "NO_TABLE"]

Floats2 = tuple[float, float]
Floats3 = tuple[float, float, float]
Floats4 = tuple[float, float, float, float]


#: the table argument of :func:`rk4_current` when the scenario's current and sway apply (no override)
NO_TABLE = np.empty((0, 3))


@routine
def current_at(current: tuple[float, float, float, float, float, float, float], t: float) -> Floats3:
    """δ(t) (m/s) of the packed ``current`` (a_1, a_2, a_3, c_1, c_2, c_3, ω_c) (``Plant._current``'s operations)."""
    a = current[6] * t
    s, c = math.sin(a), math.cos(a)
    return current[0] * s + current[3], current[1] * c + current[4], current[2] * s + current[5]


@routine
def _stage(t: float, current: tuple[float, float, float, float, float, float, float], sway: Floats3,
           table: np.ndarray, period: float) -> Floats4:
    """(δ_1, δ_2, δ_3, v_s) at ``t`` (s): the override's row (no sway) when ``table`` has rows, else the current
    and the sway."""
    if table.shape[0] > 0:
        k = min(int(t / period + 1e-9), table.shape[0] - 1)
        return table[k, 0], table[k, 1], table[k, 2], 0.0
    d1, d2, d3 = current_at(current, t)
    sw, samp, srate = sway
    return d1, d2, d3, sw + samp * math.sin(srate * t)


@routine
def _horizontal(d1: float, d2: float, vs: float, sp: float, cp: float, override: bool) -> Floats2:
    """ω_xy at a stage: δ_xy + v_s (−sin ψ, cos ψ), or the override's δ_xy as it is."""
    if override:
        return d1, d2
    return d1 - vs * sp, d2 + vs * cp


@routine
def rk4_current(t: float, y: Floats4, v: Floats3, h: float, n: int,
                current: tuple[float, float, float, float, float, float, float], sway: Floats3,
                peak: Floats2, table: np.ndarray, period: float) -> tuple[Floats4, Floats2]:
    """``n`` RK4 steps of ``h`` (s) from ``y`` = (x, y, z, ψ) at ``t`` (s) under ``v`` = (u, w, r) held.

    Parameters
    ----------
    current : tuple
        (a_1, a_2, a_3, c_1, c_2, c_3, ω_c): δ(t) = (a_1 sin ω_c t + c_1, a_2 cos ω_c t + c_2, a_3 sin ω_c t + c_3)
        (m/s, rad/s).
    sway : tuple
        (g u r, A_s, ω_s): v_s(t) = g u r + A_s sin ω_s t (m/s, m/s, rad/s).
    peak : tuple
        The largest ‖ω_xy‖ and |ω_z| so far (m/s).
    table, period : array (K, 3), float
        A :class:`~tubekit.plant.base.PiecewiseOmega` override replacing current and sway (ω = ``table[k]``, m/s;
        ``period`` s), or :data:`NO_TABLE` (K = 0) for the scenario's current and sway.

    Returns
    -------
    state (4,) after the steps and the peaks (2,) including every stage evaluated.
    """
    u, w, r = v
    override = table.shape[0] > 0
    x0, x1, x2, x3 = y
    hh, h6 = 0.5 * h, h / 6.0
    p0, p1 = peak
    e1, e2, e3, es = _stage(t, current, sway, table, period)
    for _ in range(n):
        d1, d2, d3, vs = e1, e2, e3, es
        m1, m2, m3, ms = _stage(t + 0.5 * h, current, sway, table, period)
        e1, e2, e3, es = _stage(t + h, current, sway, table, period)
        # k1 at (t, y)
        sp, cp = math.sin(x3), math.cos(x3)
        o1, o2 = _horizontal(d1, d2, vs, sp, cp, override)
        p0, p1 = _peaks(p0, p1, o1, o2, d3)
        k10, k11, k12 = u * cp + o1, u * sp + o2, w + d3
        # k2 = k3 at (t + h/2, ψ + h/2 r)
        q3 = x3 + hh * r
        sp, cp = math.sin(q3), math.cos(q3)
        o1, o2 = _horizontal(m1, m2, ms, sp, cp, override)
        p0, p1 = _peaks(p0, p1, o1, o2, m3)
        k20, k21, k22 = u * cp + o1, u * sp + o2, w + m3
        # k4 at (t + h, ψ + h r)
        q3 = x3 + h * r
        sp, cp = math.sin(q3), math.cos(q3)
        o1, o2 = _horizontal(e1, e2, es, sp, cp, override)
        p0, p1 = _peaks(p0, p1, o1, o2, e3)
        k40, k41, k42 = u * cp + o1, u * sp + o2, w + e3
        x0 = x0 + h6 * (k10 + 2.0 * k20 + 2.0 * k20 + k40)
        x1 = x1 + h6 * (k11 + 2.0 * k21 + 2.0 * k21 + k41)
        x2 = x2 + h6 * (k12 + 2.0 * k22 + 2.0 * k22 + k42)
        x3 = x3 + h6 * (r + 2.0 * r + 2.0 * r + r)
        t += h
    return (x0, x1, x2, x3), (p0, p1)


@routine
def _peaks(p0: float, p1: float, o1: float, o2: float, o3: float) -> Floats2:
    """The peaks (‖ω_xy‖, |ω_z|) with one more evaluation ω = (o1, o2, o3) (a NaN peak stays NaN, as max does)."""
    q = math.sqrt(o1 * o1 + o2 * o2)  # as Plant._rhs (libm's hypot and Python's differ in the last bit)
    if q > p0:
        p0 = q
    if abs(o3) > p1:
        p1 = abs(o3)
    return p0, p1


@routine
def omega_at_ticks(t: np.ndarray, states: np.ndarray, inputs: np.ndarray,
                   current: tuple[float, float, float, float, float, float, float], sway: Floats3,
                   table: np.ndarray, period: float) -> np.ndarray:
    """ω = δ(t) + v_s (−sin ψ, cos ψ, 0) (m/s) at every tick (len(t), 3), or the override's row; NaN where u or r
    is NaN.

    ``current``, ``table`` and ``period`` as :func:`rk4_current` takes them; ``sway`` = (g, A_s, ω_s):
    v_s = g u r + A_s sin ω_s t.
    """
    gain, samp, srate = sway
    override = table.shape[0] > 0
    out = np.full((t.shape[0], 3), np.nan)
    for i in range(t.shape[0]):
        u, r = inputs[i, 0], inputs[i, 2]
        if not (math.isfinite(u) and math.isfinite(r)):
            continue
        d1, d2, d3, vs = _stage(t[i], current, (gain * u * r, samp, srate), table, period)
        psi = states[i, 3]
        out[i, 0], out[i, 1] = _horizontal(d1, d2, vs, math.sin(psi), math.cos(psi), override)
        out[i, 2] = d3
    return out
