"""Tracking with rate-limited plans: X_f's row faces keep the completion within the plans' jump (step 17c).

Rate-limited plans (``limits.rate``) change v̂ by at most J = ρ δ per period, and the candidate's completion row
must too. The terminal law is memoryless, so its row moves with the state: from one period to the next by what
the replay's deviation and one completion arc move the state, times the law's gains. X_f gets a face per channel,
the plan's last row v_{N−1} against the law's row at the plan's end x_N (both at t_N):

    |v_{N−1} − κ_f(x_N)|_c <= S_c,   c = u, w, r

(:meth:`tubekit.model.terminal_law.TerminalLaw.row_slacks`, checked exactly at acceptance). With the completion
started at x̃ (within the deviation D of x_N) and ended at x' (one arc later, in X_f by step 17):

* ``terminal_rate[c]`` — the completion's row is within J of the plan's last:
  |κ_f(x̃) − v_{N−1}| <= S + |κ_f(x̃) − κ_f(x_N)| <= S + K_c(deviation) <= J_c;
* ``terminal_invariant[row_c]`` — the candidate's own last row κ_f(x̃) meets the face at its end x':
  |κ_f(x̃) − κ_f(x')| <= K_c(arc) <= S_c.

K_c bounds the law's change between two states. With W_α = D_ψ + asin(D_xy / d_lo) (the heading's angle to the
line of sight moved by the deviation), τ = atan(Y / x_min) (the line of sight's turn over the arc, step 17), the
start set's |α| <= A_0, its distances within Δ of d* and the arc's radial bounds (``CompletionArc``):

* yaw, r = −g α / δ: K_r = (g / δ) |Δα|, |Δα| <= W_α (deviation) or g A_0 + τ (the arc turns the heading by
  −g α̃ and the line of sight by τ);
* heave, w = ż_d − λ_z e_z: K_w = λ_z D_z (deviation; the same time) or A_z δ + λ_z (λ_z δ (z_f + D_z) + A_z δ² / 2)
  (the arc: ż_d moves by A_z δ, e_z by the law's fraction and the target's curvature);
* surge, u = N / Den, N = V_r + λ (d − d*), Den = S(g α / 2) cos(α (1 − g / 2)) >= Den_min = S(g A_0 / 2) cos β:
  |ΔN| / Den_min + (P + λ Δ) L |Δα|, with L = sup |d(1/Den)/dα| <= ((g/2)(g A_0 / 2) / 3 + (1 − g/2) sin β) /
  Den_min² (|S'(x)| <= x / 3), |ΔN| <= P asin(D_xy / d_lo) + λ D_xy (deviation: the line of sight turns, d moves)
  or A_xy δ + P τ + λ (λ δ Δ + A_xy δ² / 2 + Y² / (2 x_min)) (the arc: the target's velocity changes by A_xy δ,
  the line of sight turns by τ, and d' = hypot(q'_x, q'_y) is within Y² / (2 x_min) of q'_x). With a bearing face
  (step 17b) V_r = P cos φ moves by at most P |Δφ| sup |sin φ| between the two bearings: the P terms take the
  factor sin Φ_0 (deviation: both bearings within Φ_0) and sin(Φ_0 + τ) (arc), while below π/2.

With the line-of-sight feedforward (step 17e, r = (−g α + δ ω̂) / δ, ω̂ = (P_⊥ − N tan α) / d) the heading's change
over the arc is g A_0 + E (E the residual, not the line of sight's whole turn), K_r adds the feedforward's own change
|Δω̂| (:func:`feedforward_change`), and the surge's denominator S(T/2) cos(α + T/2) moves also with the turn T:
by at most δ |Δω̂| (T_max / 12 + sin β / 2) more.

By induction with step 17, every candidate is rate-limited, ends in X_f with its faces, and a plan exists at every
period. The law's gains are chosen as small as X_f's invariance allows (:func:`gentle_law`): the row's change
grows with them. Each face is as wide as the jump leaves, S = J − K(deviation) less a thousandth of J, never
narrower than K(arc): the plans meet a wide face more easily, and the completion still lands within J. Every
inequality is in Arb with the slack :data:`verify.theorem.completion_bounds.FLOAT_SLACK`.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from typing import Iterable, Iterator

from flint import arb, ctx

from tubekit.model.terminal_law import TerminalLaw

from verify.kernel.intervals import lower, upper
from verify.theorem.design import Condition
from verify.theorem.completion_bounds import CompletionArc, TerminalBounds, completion_arc, in_cone, start_bearing
from verify.theorem.completion_bounds import slack_condition as _cond

__all__ = ["RowChanges", "row_changes", "feedforward_change", "row_conditions", "gentle_law", "row_sets",
           "iter_row_sets", "GAIN_FACTORS"]

#: The smallest invariant gains are tried times these factors (the Arb conditions need a little room).
GAIN_FACTORS = (1.02, 1.1, 1.3)
#: Each smallest gain closes its face by this much more (m or rad) than the deviation needs: the Arb conditions
#: ask a slack of FLOAT_SLACK, and a channel without deviation (no vertical current) would otherwise get gain 0.
GAIN_SLACK = 1e-8
#: The fixed-point rounds of the smallest gains stop once neither gain moves by more than this share of itself.
SETTLED = 1e-12
#: The narrowest face S is the arc's bound times (1 + this) plus twice FLOAT_SLACK.
FACE_INFLATION = 1e-6
#: The widest face leaves this share of J to the rate condition's slack.
FACE_ROOM = 1e-3


@dataclasses.dataclass(frozen=True)
class RowChanges:
    """The law's largest row change per channel (u, w, r; m/s, m/s, rad/s), in Arb: across the replay's
    deviation (same time) and across one completion arc (one period later)."""

    deviation: tuple[arb, arb, arb]
    arc: tuple[arb, arb, arb]


def row_changes(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc) -> RowChanges:
    """:class:`RowChanges` of ``law`` (module doc) on the start set about X_f and its completion arc."""
    dt, g, lam, lam_z = arb(b.dt), arb(law.turn), arb(law.gain_d), arb(law.gain_z)
    dxy, p, a_xy = arb(b.dev_xy), arb(b.speed_xy), arb(b.accel_xy)
    seen = (dxy / arb(law.d_lo)).asin()
    w_alpha = arb(b.dev_psi) + seen
    tau = (arc.lateral / arc.x_min).atan()
    arc_alpha = g * arc.a0 + arc.residual
    den_min = (arc.turn_max / 2).sinc() * arc.beta.cos()
    slope = ((g / 2) * (arc.turn_max / 2) / 3 + (1 - g / 2) * arc.beta.sin()) / (den_min * den_min)
    slope_ff = (arc.turn_max / 12 + arc.beta.sin() / 2) / (den_min * den_min)  # per unit of δ |Δω̂|
    n_max = p + lam * arc.spread
    curve = a_xy * dt * dt / 2
    radial_arc = lam * dt * arc.spread + curve + arc.lateral ** 2 / (2 * arc.x_min)
    share_dev, share_arc = _bearing_shares(b, law, tau)
    n_dev = p * seen * share_dev + lam * dxy
    n_arc = a_xy * dt + p * tau * share_arc + lam * radial_arc
    ff_dev = ff_arc = arb(0)
    if law.los_feedforward:
        ff_dev = feedforward_change(b, law, arc, across=p * seen, closing=n_dev, alpha=w_alpha, distance=dxy,
                                    nearest=arc.start_min)
        ff_arc = feedforward_change(b, law, arc, across=a_xy * dt + p * tau, closing=n_arc, alpha=arc_alpha,
                                    distance=radial_arc, nearest=arb(min(lower(arc.start_min), lower(arc.x_min))))
    u_dev = n_dev / den_min + n_max * slope * w_alpha + n_max * slope_ff * dt * ff_dev
    u_arc = n_arc / den_min + n_max * slope * arc_alpha + n_max * slope_ff * dt * ff_arc
    dz, a_z, z_f = arb(b.dev_z), arb(b.accel_z), arb(law.z_max)
    w_dev = lam_z * dz
    w_arc = a_z * dt + lam_z * (lam_z * dt * (z_f + dz) + a_z * dt * dt / 2)
    return RowChanges(deviation=(u_dev, w_dev, g / dt * w_alpha + ff_dev),
                      arc=(u_arc, w_arc, g / dt * arc_alpha + ff_arc))


def feedforward_change(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc, *, across: arb, closing: arb,
                       alpha: arb, distance: arb, nearest: arb) -> arb:
    """The largest change of the feedforward ω̂ = (P_⊥ − N tan α) / d (rad/s, step 17e) between two states whose
    P_⊥ differ by at most ``across``, N by ``closing``, α by ``alpha``, d by ``distance``, both at least ``nearest``
    from the target, with |P_⊥| <= P, |N| <= N_max = P + λ Δ and |α| <= A_0:

        |Δω̂| <= (ΔP_⊥ + ΔN tan A_0 + N_max sec²(A_0) Δα) / d_min + (P + N_max tan A_0) Δd / d_min²."""
    p, a0 = arb(b.speed_xy), arc.a0
    n_max = p + arb(law.gain_d) * arc.spread
    tan, sec2 = a0.tan(), 1 / a0.cos() ** 2
    return (across + closing * tan + n_max * sec2 * alpha) / nearest + (p + n_max * tan) * distance / nearest ** 2


def _bearing_shares(b: TerminalBounds, law: TerminalLaw, tau: arb) -> tuple[arb, arb]:
    """The shares of P a line-of-sight turn moves V_r = P cos φ by (module doc): |cos φ − cos φ'| <= |φ − φ'|
    sup |sin| between them, so sin Φ_0 across the deviation (both bearings within Φ_0) and sin(Φ_0 + τ) across the
    arc; 1 without a bearing face or past π/2."""
    if not in_cone(b, law):
        return arb(1), arb(1)
    phi0, half = start_bearing(b, law), arb.pi() / 2
    return (phi0.sin() if phi0 < half else arb(1)), ((phi0 + tau).sin() if phi0 + tau < half else arb(1))


def row_conditions(b: TerminalBounds, law: TerminalLaw, arc: CompletionArc,
                   jumps: tuple[float, float, float]) -> list[Condition]:
    """``terminal_rate[u|w|r]`` and ``terminal_invariant[row_u|row_w|row_r]`` (module doc) for the plans' jumps
    J = ``jumps`` (m/s, m/s, rad/s per period)."""
    ch = row_changes(b, law, arc)
    faces = (arb(law.row_u), arb(law.row_w), arb(law.row_r))
    out = []
    for c, face, dev, along, jump in zip("uwr", faces, ch.deviation, ch.arc, jumps):
        out.append(_cond(f"terminal_rate[{c}]", f"S_{c} + K_{c}(deviation) <= J_{c} (the completion's row within "
                         "the plans' jump of the plan's last row)", face + dev, arb(jump)))
        out.append(_cond(f"terminal_invariant[row_{c}]", f"K_{c}(arc) <= S_{c} (the candidate's last row meets the "
                         "face at its end)", along, face))
    return out


#: :func:`_smallest_gains` by its key (:func:`_gains_key`), at most :data:`_GAINS_KEEP` kept: the bearing face's
#: sets of one grid point share it whenever their faces agree (a third of the calls certifying the torpedo AUV).
_GAINS: dict[tuple, tuple[float, float, float] | None] = {}
_GAINS_KEEP = 8192


def _gains_key(b: TerminalBounds, law: TerminalLaw) -> tuple:
    """What :func:`_smallest_gains` reads: the bounds, X_f's set (d_lo, d_hi, d*, α_max, z_max and the bearing
    face), the feedforward flag and the working precision; not the law's own turn and radial gain (each sizing round
    replaces them, :func:`_sized_gains`), nor its depth gain or row faces (neither the sizing nor
    :func:`verify.theorem.completion_bounds.completion_arc` reads them)."""
    return (b, law.d_lo, law.d_hi, law.d_star, law.alpha_max, law.z_max, law.bearing_max, law.los_feedforward,
            ctx.prec)


def _smallest_gains(b: TerminalBounds, law: TerminalLaw) -> tuple[float, float, float] | None:
    """(g, λ, λ_z): the smallest turn and gains (floats) under which X_f of ``law`` is invariant (step 17's
    ``terminal_invariant[d_lo|d_hi|alpha|e_z]``), found by a few fixed-point rounds on the completion's own bounds
    (:func:`verify.theorem.completion_bounds.completion_arc`: Y depends on g and λ); None when the set cannot be
    invariant. A sizing: the Arb conditions decide. Memoised on :func:`_gains_key`."""
    key = _gains_key(b, law)
    if key not in _GAINS:
        if len(_GAINS) >= _GAINS_KEEP:
            del _GAINS[next(iter(_GAINS))]
        _GAINS[key] = _sized_gains(b, law)
    return _GAINS[key]


def _sized_gains(b: TerminalBounds, law: TerminalLaw) -> tuple[float, float, float] | None:
    """:func:`_smallest_gains` without the memo."""
    dt, dxy, curve = b.dt, b.dev_xy, b.accel_xy * b.dt * b.dt / 2
    below = law.d_star - law.d_lo + dxy
    g, lam = 0.01, 0.0
    for _ in range(12):
        before = (g, lam)
        arc = completion_arc(b, _unchecked(law, turn=g, gain_d=lam))
        if arc is None or not arc.x_min > 0:
            return None
        a0, lateral, x_min, x_max = (float(x.mid()) for x in (arc.a0, arc.lateral, arc.x_min, arc.x_max))
        residual = float(arc.residual.mid()) if law.los_feedforward else math.atan(lateral / x_min)
        overshoot = math.hypot(x_max, lateral) - x_max
        lam_lo = (dxy + curve + GAIN_SLACK) / (dt * below)
        lam_hi = (dxy + curve + overshoot + GAIN_SLACK) / (dt * (law.d_hi + dxy - law.d_star))
        lam = max(lam_lo, lam_hi)
        g = (a0 - law.alpha_max + residual + GAIN_SLACK) / a0
        if not (0.0 < g <= 1.0 and lam * dt <= 1.0):
            return None
        if abs(g - before[0]) <= SETTLED * g and abs(lam - before[1]) <= SETTLED * lam:
            break  # settled: the rounds left would move the gains by less than the float slack matters
    lam_z = (b.dev_z + b.accel_z * dt * dt / 2 + GAIN_SLACK) / (dt * (law.z_max + b.dev_z))
    return g, lam, lam_z


def _unchecked(law: TerminalLaw, **fields: float) -> TerminalLaw:
    """``law`` with ``fields`` replaced, not validated again: a trial law the search builds by the thousand and
    never returns (every law it returns is built by :func:`dataclasses.replace`, which validates it)."""
    trial = copy.copy(law)
    for name, value in fields.items():
        object.__setattr__(trial, name, value)
    return trial


def gentle_law(b: TerminalBounds, law: TerminalLaw, factor: float) -> TerminalLaw | None:
    """``law``'s set with its smallest invariant gains times ``factor`` and the row faces S its arc needs
    (module doc); None when the set cannot be invariant or the formulas' premises fail."""
    return _with_gains(b, law, _smallest_gains(b, law), factor)


def _with_gains(b: TerminalBounds, law: TerminalLaw, gains: tuple[float, float, float] | None,
                factor: float) -> TerminalLaw | None:
    """:func:`gentle_law` for the smallest gains ``gains`` already found (None: none)."""
    if gains is None:
        return None
    g, lam, lam_z = (factor * x for x in gains)
    if not (g <= 1.0 and lam * b.dt <= 1.0 and lam_z * b.dt <= 1.0):
        return None
    trial = _unchecked(law, turn=g, gain_d=lam, gain_z=lam_z, row_u=1.0, row_w=1.0, row_r=1.0)
    arc = completion_arc(b, trial)
    if arc is None:
        return None
    changes = row_changes(b, trial, arc)
    jumps = b.jumps if b.jumps is not None else (math.inf,) * 3
    faces = [_face(k_arc, k_dev, jump) for k_arc, k_dev, jump in zip(changes.arc, changes.deviation, jumps)]
    if not all(math.isfinite(s) and s > 0.0 for s in faces):
        return None
    return dataclasses.replace(trial, row_u=faces[0], row_w=faces[1], row_r=faces[2])


def _face(k_arc: arb, k_dev: arb, jump: float) -> float:
    """S for one channel: the widest face the jump leaves, J − K(deviation) less :data:`FACE_ROOM` J (plans meet a
    wide face more easily; the completion still lands within J), never narrower than the arc's K(arc) (then the
    rate condition fails, by name)."""
    tight = upper(k_arc * (1 + arb(FACE_INFLATION))) + 2e-9
    if not math.isfinite(jump):
        return tight
    return max(tight, lower(arb(jump) * (1 - arb(FACE_ROOM)) - k_dev))


def row_sets(b: TerminalBounds, laws: Iterable[TerminalLaw]) -> list[TerminalLaw]:
    """Each set of the grid ``laws`` with gentle gains (:data:`GAIN_FACTORS`) and its row faces, in order."""
    return list(iter_row_sets(b, laws))


def iter_row_sets(b: TerminalBounds, laws: Iterable[TerminalLaw]) -> Iterator[TerminalLaw]:
    """:func:`row_sets`, each set built when it is asked for."""
    for law in laws:
        gains = _smallest_gains(b, law)  # once per set: the factors scale it
        for factor in GAIN_FACTORS:
            gentle = _with_gains(b, law, gains, factor)
            if gentle is not None:
                yield gentle
