"""The hold law's proof (:class:`tubekit.model.hold.Hold`): a disc about the anchor, proved in Arb.

The law is held over each tick h (the ancillary rate). Along the plant the horizontal position obeys
ṗ_xy = R(ψ)(u + ε_u, v + ε_v) + δ_xy, where (u, v) is the held command and ‖R(ψ)(ε_u, ε_v) + δ_xy‖ <= ω̄_xy
(ω̄_xy holds the current, E_u and the sway loop's error E_v). With Δ = p_xy − p*_xy, ρ = |Δ|, σ the blend's weight
at the tick (module doc of :mod:`tubekit.model.hold`), q_k = −min(k ρ_k, s) Δ_k / ρ_k the velocity asked for at
the tick's start and |ψ̇| <= Y while the command is held, for 0 <= t <= h:

    Δ(t) = Δ_k + t σ q_k + σ ∫(Rot(ψ(τ) − ψ_k) − I) q_k dτ + ∫(1 − σ) R(ψ)(u_h, 0) dτ + ∫ η dτ,

and ‖Rot(θ) − I‖ <= |θ| <= Y τ, so (with k h <= 1: the tick does not overshoot the anchor)

    ρ(t) <= G_σ(ρ_k, t) = ρ_k − t σ m(ρ_k) (1 − Y t / 2) + t ((1 − σ) ū + ω̄_xy),   m(ρ) = min(k ρ, s).

G_σ(·, h) is nondecreasing in ρ (``backup_tick``: k h <= 1), decreasing in σ, and convex in t, so the largest
ρ within a tick is at one of its ends. **Ramp** (``backup_ramp``): from the hand-over's ρ_0 <= H the sequence
ρ_{j+1} = G_{σ_j}(ρ_j, h) with σ_j = (j h − 1e-9 s) / t_r (rounded down) bounds ρ at every tick of the ramp,
computed in Arb with Y = max(r̄, r_t) + E_r; every term must stay <= c. **After the ramp** (``backup_level_set``):
σ = 1 and Y = r_t + E_r; min(k c, s)(1 − Y h / 2) > ω̄_xy gives G_1(c, h) < c, so ρ_k <= c implies ρ <= c over the
tick (monotone in ρ) and forever. **Depth** is the same comparison with e_z, the heave law −w_b sat(e_z / z_0), no
rotation and ω̄_z, ū replaced by w̄ (``backup_depth_ramp``, ``backup_depth_level``; ``backup_tick``:
w_b h / z_0 <= 1). The safe set is the disc {ρ <= c, |e_z| <= Z}: ``SafeSet(level=c, shape=0, depth=Z)``; its
footprint needs no heading.

**The command's rate** (:func:`hold_command_rate`): the body-frame law b = R(ψ)ᵀ q changes at most at
k |ṗ| + |ψ̇| s (the projection onto the disc |q| <= s is 1-Lipschitz), weighted by the blend's σ; the blend adds
|b − v_h| / t_r per channel; the yaw law r_t sat(v / v_t) and the heave law (Lipschitz w_b / z_0 in z) follow. The
sway command starts at 0 at the hand-over (σ = 0) and a plan is accepted only when the last sway command is within
the law's ``release`` of 0 (:func:`tubekit.loop.plan_check.check_sway`): the sway channel's jump per period is
max(release, its per-tick change).

Steps of the protocol: :meth:`HoldProof.design` — :func:`design_hold` (a grid: the smallest certified disc whose
command the velocity loop follows); :meth:`HoldProof.certify` — :func:`certify_hold`; :meth:`HoldProof.command_rate`,
:meth:`HoldProof.tick_change`, :meth:`HoldProof.sway_change` — :func:`hold_command_rate`. Importing this module
registers :data:`HOLD_PROOF`.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupLaw, SafeSet
from tubekit.model.hold import Hold
from tubekit.validation import positive
from verify.backup.proof import checked_bounds
from verify.backup.protocol import BackupCertificate, Fits, register_backup_proof
from verify.kernel.intervals import upper
from verify.theorem.design import Condition

__all__ = ["HoldProof", "HOLD_PROOF", "certify_hold", "design_hold", "hold_command_rate", "hold_reach",
           "SPEED_FRACTIONS", "GAINS", "RAMPS", "HEAVE_BANDS", "TURN_SHARE", "TURN_BAND", "RELEASE", "LEVEL_STEP",
           "MAX_FITS"]

#: The design grid (:func:`design_hold`): speed fractions of ū, position gains k (1/s), ramps t_r (s).
SPEED_FRACTIONS = (0.6, 0.8, 1.0)
GAINS = (0.05, 0.1, 0.2, 0.4)
RAMPS = (4.0, 8.0, 12.0, 16.0, 24.0)
#: z_0 (m) of the designed heave law; the fraction of r̄ the turn toward the pull may use (r_t), its band v_t (m/s);
#: the sway command (m/s) below which a plan may take over (the jump to 0 the loop is charged).
HEAVE_BANDS = (0.5, 1.0, 2.0)
TURN_SHARE = 0.1
TURN_BAND = 0.02
RELEASE = 0.003
#: The safe disc's radius and depth band are rounded up to this grid (m).
LEVEL_STEP = 0.05
#: Slack (s) on the time since the hand-over at the j-th tick (the loop's clock is a float): σ_j >= (j h − 1e-9)/t_r.
TIME_SLACK = 1e-9
#: A design tries the velocity loop (``fits``) on at most this many candidates, smallest disc first (a work unit).
MAX_FITS = 180


def _law_of(law: BackupLaw) -> Hold:
    if not isinstance(law, Hold):
        raise ConfigError("backup.kind", f"a {Hold.kind} law", getattr(law, "kind", type(law).__name__))
    return law


def _ramp_ticks(law: Hold, tick: float) -> int:
    """Ticks whose blend weight may be below 1: j h < t_r for j = 0 .. n − 1 (one more for rounding)."""
    return int(math.ceil(law.ramp / tick)) + 1


def hold_reach(start: float, *, gain: float, cap: float, contraction_slack: float, push: float, rest: float,
               ramp: float, tick: float) -> float:
    """The largest ρ (m) over the ramp (its end included) of the comparison sequence ρ_{j+1} = G_{σ_j}(ρ_j, h) (module doc)
    from ``start``, in Arb: m(ρ) = min(``gain`` ρ, ``cap``), the rotation's factor (1 − Y h / 2) =
    ``contraction_slack``, the disturbance ``push`` (ω̄), the hand-over command's part ``rest`` (ū or w̄) weighted by
    1 − σ_j, σ_j = (j h − :data:`TIME_SLACK`) / t_r rounded down (at least 0). The same routine bounds the depth
    error (``gain`` w_b / z_0, ``cap`` w_b).

    ρ − hσ m(ρ) f = max(ρ (1 − hσ k f), ρ − hσ s f) (f >= 0), so each step is the larger of two balls with no
    dependency on ρ's own width."""
    h, k, s, fac = arb(tick), arb(gain), arb(cap), arb(contraction_slack)
    w, u, t_r = arb(push), arb(rest), arb(ramp)
    rho = arb(start)
    top = rho
    for j in range(int(math.ceil(ramp / tick)) + 1):
        sigma = (arb(j) * h - arb(TIME_SLACK)) / t_r  # the loop's elapsed time, rounded, is at least j h − 1e-9 s
        if sigma >= 1:
            break
        sigma = sigma if sigma >= 0 else arb(0)
        step = h * sigma * fac
        rho = _max_ball(rho * (1 - step * k), rho - step * s) + h * ((1 - sigma) * u + w)
        top = _max_ball(top, rho)
    return upper(top)


def _min_ball(a: arb, b: arb) -> arb:
    """A ball containing min(x, y) for every x in ``a``, y in ``b``."""
    if a <= b:
        return a
    if b <= a:
        return b
    return a.union(b)


def _max_ball(a: arb, b: arb) -> arb:
    """A ball containing max(x, y) for every x in ``a``, y in ``b``."""
    if a >= b:
        return a
    if b >= a:
        return b
    return a.union(b)


def _turn_rates(law: Hold, limits: tuple[float, float, float], yaw_err: float) -> tuple[arb, arb]:
    """(Y during the ramp, Y after it) (rad/s): bounds of |ψ̇| while a command is held, max(r̄, r_t) + E_r and
    r_t + E_r."""
    turn = arb(law.turn)
    ramp = _max_ball(arb(limits[2]), turn) + arb(yaw_err)
    return ramp, turn + arb(yaw_err)


def _reaches(law: Hold, dist: tuple[float, float], limits: tuple[float, float, float], tick: float,
             handover: tuple[float, float], yaw_err: float) -> tuple[float, float]:
    """(horizontal, depth) largest values (m) of the ramp's comparison sequences."""
    y_ramp, _ = _turn_rates(law, limits, yaw_err)
    fac = 1 - y_ramp * arb(tick) / 2
    xy = hold_reach(handover[0], gain=law.gain, cap=law.speed, contraction_slack=max(0.0, float(fac.lower())),
                    push=dist[0], rest=limits[0], ramp=law.ramp, tick=tick)
    z = hold_reach(handover[1], gain=law.heave / law.heave_band, cap=law.heave, contraction_slack=1.0, push=dist[1],
                   rest=limits[1], ramp=law.ramp, tick=tick)
    return xy, z


def _level_margin(law: Hold, level: float, omega_xy: float, limits: tuple[float, float, float], tick: float,
                  yaw_err: float) -> float:
    """A float <= min(k c, s)(1 − Y h / 2) − ω̄_xy after the ramp (m/s): > 0 proves G_1(c, h) < c."""
    _, y_post = _turn_rates(law, limits, yaw_err)
    pull = _min_ball(arb(law.gain) * arb(level), arb(law.speed))
    return float((pull * (1 - y_post * arb(tick) / 2) - arb(omega_xy)).lower())


def _depth_margin(law: Hold, depth: float, omega_z: float) -> float:
    """A float <= w_b min(Z / z_0, 1) − ω̄_z (m/s): > 0 proves the depth band invariant after the ramp."""
    pull = _min_ball(arb(law.heave) * arb(depth) / arb(law.heave_band), arb(law.heave))
    return float((pull - arb(omega_z)).lower())


def _conditions(law: Hold, safe: SafeSet, dist: tuple[float, float], limits: tuple[float, float, float],
                tick: float, handover: tuple[float, float], yaw_err: float) -> tuple[Condition, ...]:
    """Every inequality of the theorem (module doc), with both numbers."""
    top_xy, top_z = _reaches(law, dist, limits, tick, handover, yaw_err)
    y_ramp, _ = _turn_rates(law, limits, yaw_err)
    stiff = max(upper(arb(law.gain) * arb(tick)), upper(arb(law.heave) * arb(tick) / arb(law.heave_band)),
                upper(y_ramp * arb(tick) / 2))
    level = _level_margin(law, safe.level, dist[0], limits, tick, yaw_err)
    depth = _depth_margin(law, safe.depth, dist[1])
    return (
        Condition("backup_inputs", "s <= u_max, w_b <= w_max, r_t <= r_max", max(
            law.speed / limits[0], law.heave / limits[1], law.turn / limits[2]), 1.0,
            law.within(*limits), "largest ratio"),
        Condition("backup_tick", "k h <= 1, w_b h / z_0 <= 1, Y h / 2 <= 1 (a tick does not overshoot)", stiff, 1.0,
                  stiff <= 1.0),
        Condition("backup_level_set", "min(k c, s)(1 − Y h / 2) − ω̄_xy > 0 after the ramp", level, 0.0, level > 0.0),
        Condition("backup_ramp", "the ramp's comparison sequence from the hand-over stays <= c", top_xy,
                  safe.level, top_xy <= safe.level, f"hand-over within {handover[0]:.4g} m"),
        Condition("backup_depth_level", "w_b min(Z / z_0, 1) − ω̄_z > 0 after the ramp", depth, 0.0, depth > 0.0),
        Condition("backup_depth_ramp", "the ramp's depth sequence from the hand-over stays <= Z", top_z, safe.depth,
                  top_z <= safe.depth, f"hand-over within {handover[1]:.4g} m"),
    )


def certify_hold(law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                 limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                 yaw_rate_error: float = 0.0) -> BackupCertificate:
    """Prove (or refute, naming each failed inequality) that the disc ``safe`` is invariant under the hold ``law``
    held at the tick h (s) against ω̄_xy, ω̄_z (m/s) and E_r (rad/s), from every hand-over within ``handover``
    (m, m)."""
    hold = _law_of(law)
    if not isinstance(safe, SafeSet) or safe.shape != 0.0:
        raise ConfigError("backup.safe_set", "a SafeSet with shape 0 (the hold law's disc)", safe)
    wxy, wz, h, e_r, hand = checked_bounds(omega_xy, omega_z, tick, yaw_rate_error, handover)
    lim = tuple(positive(f"limits[{i}]", x) for i, x in enumerate(limits))
    conditions = _conditions(hold, safe, (wxy, wz), lim, h, hand, e_r)
    margin = next(c.lhs for c in conditions if c.condition == "backup_level_set")
    return BackupCertificate(law=hold, safe_set=safe, omega_xy=wxy, omega_z=wz, tick=h, rate_bound=-margin,
                             rate_sampled=-margin, boxes=_ramp_ticks(hold, h), conditions=conditions,
                             handover=hand, yaw_rate_error=e_r)


def hold_command_rate(law: BackupLaw, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float],
                      loop_error: tuple[float, float, float], tick: float | None = None
                      ) -> tuple[float, float, float, float]:
    """Upper bounds on |u̇|, |ẇ|, |ṙ|, |v̇| of the command along the plant (m/s², m/s², rad/s², m/s²), the ramp's
    blend included (module doc): the change of the held command from one tick h (s, ``tick``) to the next is at
    most h times these.

    With σ the blend's weight (σ_j held over a tick, σ(t) <= σ_j + h/t_r along it), the command is
    (1 − σ) v_h + σ b, b = R(ψ)ᵀ q; |ṗ| <= (1 − σ_j) ū + σ_j s + ω̄_xy and |ψ̇| <= (1 − σ_j) r̄ + σ_j r_t + E_r, so
    σ(t) |ḃ| <= k (c ū + s + ω̄_xy) + s (c r̄ + r_t + E_r) with c = 1/4 + h/t_r (σ (1 − σ) <= 1/4; without ``tick``
    c = 1/2, which holds for h <= t_r/4), and the blend adds |b − v_h| / t_r. The yaw law r_t sat(v / v_t) is
    Lipschitz r_t / v_t in the sway command. The heave: σ (w_b / z_0)(c w̄ + w_b + ω̄_z)."""
    hold = _law_of(law)
    lim = tuple(arb(x) for x in limits)
    s, k, blend, turn = arb(hold.speed), arb(hold.gain), 1 / arb(hold.ramp), arb(hold.turn)
    c = arb(0.5) if tick is None else arb(1) / 4 + arb(positive("tick", tick)) * blend
    body = k * (c * lim[0] + s + arb(omega_xy)) + s * (c * lim[2] + turn + arb(loop_error[2]))
    slope = turn / arb(hold.turn_band)
    heave_b, band = arb(hold.heave), arb(hold.heave_band)
    heave = blend * (heave_b + lim[1]) + heave_b / band * (c * lim[1] + heave_b + arb(omega_z))
    return (upper(blend * (s + lim[0]) + body), upper(heave), upper(blend * (turn + lim[2]) + slope * body),
            upper(blend * s + body))


def _tick_changes(law: BackupLaw, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float],
                  loop_error: tuple[float, float, float], tick: float) -> tuple[float, float, float, float]:
    """:func:`hold_command_rate` × h (m/s, m/s, rad/s, m/s per tick), rounded up."""
    rates = hold_command_rate(law, omega_xy=omega_xy, omega_z=omega_z, limits=limits, loop_error=loop_error,
                              tick=tick)
    return tuple(upper(arb(r) * arb(tick)) for r in rates)


def _screen_reach(start: float, gain: np.ndarray, cap: np.ndarray, fac: np.ndarray, push: float, rest: float,
                  ramp: np.ndarray, tick: float) -> np.ndarray:
    """Float screen of :func:`hold_reach` for many laws at once (largest ρ over the ramp, m): it only orders the
    design's candidates; each chosen one is proved by :func:`certify_hold`."""
    rho = np.full(gain.shape, float(start))
    top = rho.copy()
    for j in range(int(math.ceil(float(ramp.max()) / tick)) + 1):
        sigma = np.minimum(1.0, j * tick / ramp)
        live = sigma < 1.0
        if not live.any():
            break
        step = tick * sigma * fac
        nxt = np.maximum(rho * (1 - step * gain), rho - step * cap) + tick * ((1 - sigma) * rest + push)
        rho = np.where(live, nxt, rho)
        top = np.maximum(top, rho)
    return top


def _grid_up(x: float) -> float:
    """``x`` rounded up to the :data:`LEVEL_STEP` grid (m), with 1e-9 of room."""
    return math.ceil(x * (1 + 1e-9) / LEVEL_STEP - 1e-9) * LEVEL_STEP if math.isfinite(x) else math.inf


def _candidates(omega: tuple[float, float], limits: tuple[float, float, float], tick: float,
                handover: tuple[float, float], yaw_err: float) -> list[tuple[float, float, Hold]]:
    """(c, Z, law) of every grid law that can hold against ω̄ (module doc), smallest disc first."""
    laws = [Hold(gain=k, speed=f * limits[0], heave=limits[1], heave_band=z0, ramp=t_r, turn=TURN_SHARE * limits[2],
                 turn_band=TURN_BAND, release=RELEASE)
            for f, k, t_r, z0 in itertools.product(SPEED_FRACTIONS, GAINS, RAMPS, HEAVE_BANDS)]
    k = np.array([law.gain for law in laws])
    cap = np.array([law.speed for law in laws])
    ramp = np.array([law.ramp for law in laws])
    band = np.array([law.heave_band for law in laws])
    y_ramp = np.maximum(limits[2], [law.turn for law in laws]) + yaw_err
    y_post = np.array([law.turn for law in laws]) + yaw_err
    top_xy = _screen_reach(handover[0], k, cap, 1 - y_ramp * tick / 2, omega[0], limits[0], ramp, tick)
    heave = limits[1]
    top_z = _screen_reach(handover[1], heave / band, np.full(k.shape, heave), np.ones(k.shape), omega[1], limits[1],
                          ramp, tick)
    out = []
    for i, law in enumerate(laws):
        hold = law.speed * (1 - y_post[i] * tick / 2)
        if hold <= omega[0] or heave <= omega[1]:
            continue
        level = _grid_up(max(top_xy[i], omega[0] / (law.gain * (1 - y_post[i] * tick / 2))))
        depth = _grid_up(max(top_z[i], law.heave_band * omega[1] / heave))
        out.append((level, depth, law))
    out.sort(key=lambda c: (c[0], c[1], c[2].ramp, c[2].gain))
    return out


def design_hold(*, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
                handover: tuple[float, float] = (0.0, 0.0), yaw_rate_error: float = 0.0,
                fits: Fits | None = None) -> BackupCertificate:
    """The certified hold law with the smallest disc on a fixed grid (deterministic): speeds s = f ū
    (:data:`SPEED_FRACTIONS`), gains :data:`GAINS`, ramps :data:`RAMPS`, w_b = w̄, z_0 in :data:`HEAVE_BANDS`,
    r_t = :data:`TURN_SHARE` r̄, v_t = :data:`TURN_BAND`, release :data:`RELEASE`, the disc and band of each from the
    float screen. With ``fits``: the smallest disc
    with a law whose command the velocity loop follows (ratio < 1; among the laws of that disc the smallest ratio),
    else the law with the smallest ratio (the fixed point raises E_a from it). The chosen law is proved by
    :func:`certify_hold` (a step of :data:`LEVEL_STEP` more where the float screen was short); a refuted certificate
    is returned when it does not certify."""
    wxy, wz, h, e_r, hand = checked_bounds(omega_xy, omega_z, tick, yaw_rate_error, handover)
    lim = tuple(positive(f"limits[{i}]", x) for i, x in enumerate(limits))
    candidates = _candidates((wxy, wz), lim, h, hand, e_r)
    if not candidates:  # no grid speed holds against ω̄: the fastest law, refuted by name
        law = Hold(gain=GAINS[-1], speed=lim[0], heave=lim[1], heave_band=HEAVE_BANDS[0], ramp=RAMPS[0],
                   turn=TURN_SHARE * lim[2], turn_band=TURN_BAND, release=RELEASE)
        candidates = [(max(hand[0], LEVEL_STEP), max(hand[1], LEVEL_STEP), law)]
    chosen = _gentlest(candidates, fits)
    cert = None
    for extra in (0.0, LEVEL_STEP):
        level, depth, law = chosen
        cert = certify_hold(law, SafeSet(level=level + extra, shape=0.0, depth=depth + extra), omega_xy=wxy,
                            omega_z=wz, limits=lim, tick=h, handover=hand, yaw_rate_error=e_r)
        if cert.certified:
            break
    return cert


def _gentlest(candidates: list[tuple[float, float, Hold]], fits: Fits | None) -> tuple[float, float, Hold]:
    """The first disc (in the candidates' order) with a law of ratio < 1, its smallest-ratio law; else the smallest
    disc whose loop bound closes, else the gentlest law (the first candidate without ``fits``). At most
    :data:`MAX_FITS` ratios are evaluated (a law's command rate does not depend on its disc)."""
    if fits is None:
        return candidates[0]
    # when no law's loop bound closes, the gentlest (the slowest command): the failure it names is the real limit
    best = min(candidates, key=lambda c: (-c[2].ramp, c[2].gain, c[2].speed, -c[2].heave_band))
    best_ratio = math.inf
    for _, group in itertools.groupby(candidates[:MAX_FITS], key=lambda c: c[0]):
        rated = [(fits(law, SafeSet(level=level, shape=0.0, depth=depth)), i, (level, depth, law))
                 for i, (level, depth, law) in enumerate(group)]
        ratio, _, pick = min(rated, key=lambda r: (r[0], r[1]))
        if math.isfinite(ratio) and not math.isfinite(best_ratio):
            best, best_ratio = pick, ratio
        if ratio < 1.0:
            return pick
    return best


class HoldProof:
    """The proof of ``kind = "hold"`` (module doc); a stateless object."""

    kind: str = Hold.kind

    def design(self, *, omega_xy: float, omega_z: float, limits: tuple[float, float, float], tick: float,
               handover: tuple[float, float], yaw_rate_error: float = 0.0, smooth: bool = False,
               fits: Fits | None = None, surge_floor: float | None = None) -> BackupCertificate:
        """:func:`design_hold` (the law is rate-bounded by construction: ``smooth`` is not read; nor is
        ``surge_floor``: the law stops)."""
        return design_hold(omega_xy=omega_xy, omega_z=omega_z, limits=limits, tick=tick, handover=handover,
                           yaw_rate_error=yaw_rate_error, fits=fits)

    def certify(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                limits: tuple[float, float, float], tick: float, handover: tuple[float, float] = (0.0, 0.0),
                yaw_rate_error: float = 0.0) -> BackupCertificate:
        """:func:`certify_hold` (ConfigError when ``law`` is not a Hold)."""
        return certify_hold(law, safe, omega_xy=omega_xy, omega_z=omega_z, limits=limits, tick=tick,
                            handover=handover, yaw_rate_error=yaw_rate_error)

    def command_rate(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                     limits: tuple[float, float, float],
                     loop_error: tuple[float, float, float]) -> tuple[float, float, float]:
        """(u, w, r) of :func:`hold_command_rate` (m/s², m/s², rad/s²)."""
        u, w, r, _ = hold_command_rate(law, omega_xy=omega_xy, omega_z=omega_z, limits=limits,
                                       loop_error=loop_error)
        return u, w, r

    def tick_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> tuple[float, float, float]:
        """(u, w, r) of :func:`hold_command_rate` × h (m/s, m/s, rad/s per tick)."""
        u, w, r, _ = _tick_changes(law, omega_xy=omega_xy, omega_z=omega_z, limits=limits, loop_error=loop_error,
                                   tick=tick)
        return u, w, r

    def sway_change(self, law: BackupLaw, safe: SafeSet, *, omega_xy: float, omega_z: float,
                    limits: tuple[float, float, float], loop_error: tuple[float, float, float],
                    tick: float) -> float:
        """The sway command's change per tick (m/s): |v̇| of :func:`hold_command_rate` × h."""
        return _tick_changes(law, omega_xy=omega_xy, omega_z=omega_z, limits=limits, loop_error=loop_error,
                             tick=tick)[3]

    def summary_lines(self, cert: BackupCertificate) -> list[str]:
        """The hold law's lines: verdict, disc, gains, hold margin."""
        s, law = cert.safe_set, _law_of(cert.law)
        head = "certified" if cert.certified else "NOT certified: " + ", ".join(c.condition for c in cert.failures)
        return [f"backup (hold, lateral thrust): {head}",
                f"  safe set: a disc of radius {s.radius:.3f} m about the anchor, depth band ±{s.depth:.3f} m (any "
                "heading)",
                f"  law: k {law.gain:g} 1/s, speed s {law.speed:g} m/s, turn r_t {law.turn:.4g} rad/s below "
                f"v_t {law.turn_band:g} m/s, release {law.release:g} m/s, w_b {law.heave:g} m/s, "
                f"z_0 {law.heave_band:g} m, ramp t_r {law.ramp:g} s; against ω̄_xy {cert.omega_xy:.4g} m/s, "
                f"ω̄_z {cert.omega_z:.4g} m/s, E_r {cert.yaw_rate_error:.4g} rad/s",
                f"  hold margin min(k c, s)(1 − Y h/2) − ω̄_xy >= {-cert.rate_bound:.4g} m/s"]


#: The registered hold proof.
HOLD_PROOF = register_backup_proof(HoldProof())
