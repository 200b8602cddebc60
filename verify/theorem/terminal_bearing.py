"""The tracking theorem under a minimum surge: the bearing face of X_f keeps the terminal law's surge above u_min.

The terminal law's surge u = (V_r + λ (d − d*)) / (S(gα/2) cos β̂) follows the target's speed along the line of
sight, V_r = P cos φ, where φ is the *bearing*, the angle from the line of sight to the target's horizontal
velocity (``tubekit.model.terminal_law.bearing``). A target that comes toward the vehicle makes V_r, hence u,
negative, so without more the law cannot respect u >= u_min (``terminal_surge_floor`` refused every design). With
a target whose horizontal speed never drops below P_min > 0 (``Trajectory.horizontal_speed_floor``: a line or a
circle), X_f gets a fourth face |φ| <= φ_f, a cone behind the target, and two things are proved
(:func:`bearing_conditions`, Arb, with :data:`verify.theorem.completion_bounds.FLOAT_SLACK`):

* **the cone is invariant** (``terminal_invariant[bearing]``). The completion starts within the replay's deviation
  D_xy of X_f: its bearing |φ̃| <= Φ_0 = φ_f + asin(D_xy / d_lo). In the line-of-sight frame of that start the
  relative position becomes q' = (q'_x, q'_y) with q'_x in [x_min, x_max] (the radial closing of
  ``verify.theorem.terminal``) and, for φ̃ >= 0, q'_y >= δ P_min sin φ̃ − L_c − A δ²/2: the target's lateral run,
  less the vehicle's lateral chord L_c = δ (P + λ Δ) tan β (the law's surge times tan of the chord's angle) and
  the target's curvature. The line of sight turns toward the target's velocity by θ = atan2(q'_y, q'_x), and the
  velocity itself turns by at most η = A δ / P_min. φ' = φ̃ + η − θ is increasing in φ̃ (δ P <= x_min), so its
  largest value is at Φ_0: Φ_0 + η − atan(y_lo / x_max) <= φ_f with y_lo = δ P_min sin Φ_0 − L_c − A δ²/2 > 0;
  by symmetry the same bounds −φ' from above; the cone is not crossed to the other side
  (``terminal_invariant[bearing_cross]``): η + atan((L_c + A δ²/2) / x_min) <= φ_f.
* **the surge stays above the floor** (``terminal_surge_floor``): over the start set, V_r >= P_min cos Φ_0 and
  d − d* >= −(d* − d_lo + D_xy), and S cos <= 1 divides a positive numerator, so
  u >= P_min cos Φ_0 − λ (d* − d_lo + D_xy) >= u_min + κ̄_u (the plans' surge floor, ``v_bar[surge_floor]``).

:func:`bearing_sets` gives each set of the grid the smallest φ_f that the float version of the first inequality
admits, with narrower heading rooms and smaller radial gains tried too (the lateral chord grows with both). Under
rate-limited plans :func:`bearing_row_sets` composes the face with the row faces of step 17c, which need each set's
gentlest gains. The face also narrows step 17's lateral bound Y to δ P sin(Φ_0 + β) / cos β + ...
(:func:`verify.theorem.completion_bounds.completion_arc`), for every condition that reads Y.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Iterable, Iterator

from flint import arb

from tubekit.model.terminal_law import TerminalLaw

from verify.kernel.intervals import upper
from verify.theorem.completion_bounds import (CompletionArc, TerminalBounds, completion_arc, slack_condition,
                                             start_bearing)
from verify.theorem.design import Condition
from verify.theorem.terminal_rows import GAIN_FACTORS, gentle_law, iter_row_sets

__all__ = ["bearing_conditions", "bearing_sets", "bearing_row_sets", "iter_bearing_sets", "iter_bearing_row_sets",
           "GENTLE_FACTOR", "smallest_bearing", "lateral_chord", "ALPHA_FRACTIONS", "GAIN_FRACTIONS", "BEARING_STEP"]

#: Fractions of each grid set's heading room α_f tried under a surge floor (largest first).
ALPHA_FRACTIONS = (1.0, 0.3, 0.1, 0.05)
#: Fractions of each grid set's radial gain λ tried under a surge floor (largest first).
GAIN_FRACTIONS = (1.0, 0.5, 0.2, 0.1, 0.05)
#: The factor on the smallest gains when they are re-derived under a bearing face (:func:`bearing_row_sets`).
GENTLE_FACTOR = GAIN_FACTORS[0]
#: The grid on which the smallest admissible φ_f is searched (rad).
BEARING_STEP = 0.005


def lateral_chord(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> arb:
    """L_c = δ (P + λ Δ) tan β (m): the most the completion's chord moves the vehicle across its line of sight."""
    return arb(b.dt) * (arb(b.speed_xy) + arb(law.gain_d) * arc.spread) * arc.beta.tan()


def smallest_bearing(b: TerminalBounds, law: TerminalLaw) -> float | None:
    """The smallest φ_f on the :data:`BEARING_STEP` grid below π/2 for which the float version of
    ``terminal_invariant[bearing]`` holds for ``law`` (its other faces as given, the arc's bounds at their
    unfavourable ends); None when none does. The Arb condition decides; this only proposes.

    Found by bisection: over the grid points whose start bearing Φ_0 = φ_f + asin(D_xy / d_lo) is below π/2 the
    inequality's left side less φ_f, asin(D_xy / d_lo) + η − atan((δ P_min sin Φ_0 − L_c − A δ²/2) / x_max), falls
    as φ_f grows (sin Φ_0 rises), so once it holds it holds at every larger φ_f: the first grid point where it
    holds is the one a scan upward finds, after about nine evaluations instead of up to 313."""
    arc = completion_arc(b, law) if b.speed_floor_xy > 0.0 else None
    if arc is None:
        return None
    dt = b.dt
    dev = math.asin(min(1.0, b.dev_xy / law.d_lo))
    loss = upper(lateral_chord(b, law, arc)) + b.accel_xy * dt * dt / 2
    turn, x_max = b.accel_xy * dt / b.speed_floor_xy, upper(arc.x_max)

    def holds(i: int) -> bool:
        phi = i * BEARING_STEP
        start = phi + dev
        lateral = dt * b.speed_floor_xy * math.sin(start) - loss
        return lateral > 0 and start + turn - math.atan(lateral / x_max) <= phi - 1e-6

    end = int(math.pi / 2 / BEARING_STEP)  # the grid is 1 .. end - 1, cut at the first point where Φ_0 reaches π/2
    top = max(1, math.ceil((math.pi / 2 - dev) / BEARING_STEP) - 2)  # a few points before that cut
    while top < end and top * BEARING_STEP + dev < math.pi / 2:
        top += 1
    if top <= 1 or not holds(top - 1):
        return None
    lo, hi = 1, top - 1  # holds(hi)
    while lo < hi:
        mid = (lo + hi) // 2
        if holds(mid):
            hi = mid
        else:
            lo = mid + 1
    return lo * BEARING_STEP


def bearing_sets(b: TerminalBounds, laws: Iterable[TerminalLaw]) -> list[TerminalLaw]:
    """Each set of ``laws`` with narrower heading rooms and smaller radial gains (:data:`ALPHA_FRACTIONS`,
    :data:`GAIN_FRACTIONS`; the turn fraction g recomputed from r̄̄) and its smallest bearing face; sets without
    one are dropped."""
    return list(iter_bearing_sets(b, laws))


def iter_bearing_sets(b: TerminalBounds, laws: Iterable[TerminalLaw]) -> Iterator[TerminalLaw]:
    """:func:`bearing_sets`, each set built when it is asked for."""
    rb, dt = b.v_bar[2], b.dt
    for law in laws:
        for fa in ALPHA_FRACTIONS:
            alpha = law.alpha_max * fa
            a0 = alpha + b.dev_psi + math.asin(min(1.0, b.dev_xy / law.d_lo))
            turn = min(1.0, rb * dt / a0 * (1 - 1e-6))
            for fg in GAIN_FRACTIONS:
                cand = dataclasses.replace(law, alpha_max=alpha, turn=turn, gain_d=law.gain_d * fg)
                phi = smallest_bearing(b, cand)
                if phi is not None:
                    yield dataclasses.replace(cand, bearing_max=phi)


def bearing_row_sets(b: TerminalBounds, laws: Iterable[TerminalLaw]) -> list[TerminalLaw]:
    """Under rate-limited plans, each set of ``laws`` at each heading room of :data:`ALPHA_FRACTIONS` with its
    gentlest invariant gains and row faces (:func:`verify.theorem.terminal_rows.row_sets`: the row faces need the
    smallest gains, which :func:`bearing_sets`' fractions of the grid's gains would break) and its smallest bearing
    face; then the gains re-derived with the lateral bound the face narrows (step 17b) and the face again, first
    when it is no wider. Sets without a face are dropped."""
    return list(iter_bearing_row_sets(b, laws))


def iter_bearing_row_sets(b: TerminalBounds, laws: Iterable[TerminalLaw]) -> Iterator[TerminalLaw]:
    """:func:`bearing_row_sets`, each set built when it is asked for."""
    for law in laws:
        for fa in ALPHA_FRACTIONS:
            for gentle in iter_row_sets(b, [dataclasses.replace(law, alpha_max=law.alpha_max * fa)]):
                phi = smallest_bearing(b, gentle)
                if phi is None:
                    continue
                first = dataclasses.replace(gentle, bearing_max=phi)
                again = _regained(b, first)
                if again is not None:
                    yield again
                yield first


def _regained(b: TerminalBounds, law: TerminalLaw) -> TerminalLaw | None:
    """``law`` (with its bearing face) with its gentlest gains and row faces re-derived under the face's lateral
    bound, and the face re-derived for them; None when that face is wider than ``law``'s (the gains assumed it)."""
    gentler = gentle_law(b, law, GENTLE_FACTOR)
    phi = None if gentler is None else smallest_bearing(b, gentler)
    if phi is None or phi > law.bearing_max:
        return None
    return dataclasses.replace(gentler, bearing_max=phi)


def bearing_conditions(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> list[Condition]:
    """``terminal_invariant[bearing]``, ``terminal_invariant[bearing_cross]`` and ``terminal_surge_floor`` of
    ``law`` (module doc), in Arb, from its completion's bounds ``arc`` (A_0, β, Δ, x_min, x_max). Under a surge
    floor a set without the bearing face fails by name."""
    if not law.has_bearing:
        return [] if b.surge_floor is None else [
            Condition("terminal_surge_floor", "a bearing face |phi| <= phi_f (the target's speed along the line of "
                      "sight keeps the law's surge above u_min + kappa_u)", None, None, False, "this set has none")]
    dt, dxy = arb(b.dt), arb(b.dev_xy)
    p_min, p_max = arb(b.speed_floor_xy), arb(b.speed_xy)
    lam, d_lo, d_star = arb(law.gain_d), arb(law.d_lo), arb(law.d_star)
    chord = lateral_chord(b, law, arc)
    curve = arb(b.accel_xy) * dt * dt / 2
    turn = arb(b.accel_xy) * dt / p_min
    phi_f = arb(law.bearing_max)
    start = start_bearing(b, law)
    lateral = dt * p_min * start.sin() - chord - curve
    valid = bool(start < arb.pi() / 2) and bool(lateral > 0) and bool(dt * p_max <= arc.x_min)
    nxt = start + turn - (lateral / arc.x_max).atan() if valid else arb("inf")
    floor = p_min * start.cos() - lam * (d_star - d_lo + dxy)
    invariant = slack_condition(
        "terminal_invariant[bearing]", "Phi_0 + eta - atan((delta P_min sin Phi_0 - L_c - A delta^2/2) / x_max) <= "
        "phi_f (the cone behind the target is invariant)", nxt, phi_f,
        f"phi_f {law.bearing_max:.4g} rad, P_min {b.speed_floor_xy:.4g} m/s, chord {float(chord.upper()):.4g} m")
    crossing = slack_condition("terminal_invariant[bearing_cross]", "eta + atan((L_c + A delta^2/2) / x_min) <= phi_f",
                               turn + ((chord + curve) / arc.x_min).atan(), phi_f)
    if b.surge_floor is None:
        return [invariant, crossing]
    surge = slack_condition("terminal_surge_floor", "P_min cos Phi_0 - lambda (d* - d_lo + D_xy) >= u_min + kappa_u "
                            "(the law's surge never below the plans' floor)", arb(b.surge_floor), floor,
                            f"floor u_min + kappa_u = {b.surge_floor:.4g} m/s")
    return [invariant, crossing, surge]
