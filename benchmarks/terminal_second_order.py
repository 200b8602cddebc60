"""Would a terminal law that keeps its last command fit? Sizing a rate-limited completion, channel by channel.

The tracking theorem (``verify.theorem.terminal``) completes the shifted candidate with one row of a memoryless
law κ_f(x) and refuses plans with a rate limit (``terminal_rate``). A memoryless law reacts to each period's replay
deviation with its full gain, so its row moves by gain × deviation every period; ``benchmarks/terminal_rate.py``
measures that. A law that keeps the last command as a state and changes it by at most J = ρ δ per period filters
the deviation instead. This study asks how large its terminal set would have to be, before anyone builds the proof.

**Model, per channel and per period** (the candidate's terminal states of consecutive plans): x is the channel's
error at the plan's end (heading: the angle α to the line of sight; radial: d − d*; depth: e_z) and s the last
row's rate of change of x (heading: r minus the line of sight's rate; radial: the target's speed away along the
line of sight minus the closing speed; depth: w − ż_d). Each period the replay moves x by w (|w| <= W, the
certified one-period deviation), the completion changes the command by Δ = −k₁ x̃ − k₂ s (|Δ| <= J, no clip), the
feedforward moves s by m (|m| <= M: the target's acceleration, the line of sight's turn, the other channels), and the
row is held over δ:

    x̃ = x + w,   s' = s + Δ − m,   x' = x̃ + δ s'.

For z = (x, s) this is z' = A z + b_w w + b_m m with A = [[1 − δk₁, δ(1 − k₂)], [−k₁, 1 − k₂]],
b_w = (1 − δk₁, −k₁), b_m = (−δ, −1). For a stable A the smallest set that holds every such sequence (the minimal
robust invariant set, :func:`support_sums`) has the half-widths Σᵢ (W |eᵀAⁱb_w| + M |eᵀAⁱb_m|), and the command's
change over it is bounded the same way (plus k₁ W). :func:`smallest_band` searches the gains (k₁, k₂) for the
narrowest x whose Δ stays within J, so that the law is linear on the set (no saturation).

**What it reads from a certificate** (:func:`channels`, floats, from ``verify.theorem.terminal.terminal_bounds``): W
per channel is the deviation the tracking theorem already uses (D_ψ + asin(D_xy / d) for the heading, D_xy radially,
D_z in depth); M is an estimate, stated in :func:`channels`: the target's acceleration over a period and the line of
sight's turn. The heading is sized first; its band then enters the radial channel in one of two ways
(:func:`radial_with_heading`): with today's terminal surge, divided by cos α, the command moves with the heading
(``radial``: M grows); with a surge that is not divided by it, the closing speed falls short by u (1 − cos α)
(``radial_plain``: W grows). Not a proof: a sizing, so that the theorem a later step would prove (invariant sets in
Arb, the completion's geometry) is known to fit the room R leaves, or known not to.

Usage: ``python benchmarks/terminal_second_order.py [--scenario FILE] [--rate-scale 1 2 ...]``; nothing is timed.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

SCENARIO = Path(__file__).resolve().parent.parent / "examples" / "bluerov2_slow.toml"
#: The gains searched, log-spaced: k₁ (per second: Δ per unit of x) and k₂ (Δ per unit of s, per period).
GAINS_1 = np.geomspace(1e-3, 10.0, 60)
GAINS_2 = np.geomspace(1e-3, 1.5, 60)
#: The sums stop when every remaining term is below this (the spectral radius is below :data:`STABLE`).
TAIL = 1e-13
STABLE = 0.995
MAX_TERMS = 20000

__all__ = ["Band", "support_sums", "smallest_band", "channels", "study", "main"]


@dataclass(frozen=True)
class Band:
    """The narrowest linear completion of one channel: half-widths of x and s over the minimal robust invariant
    set, the largest command change Δ over it, and the gains."""

    x: float
    s: float
    change: float
    k1: float
    k2: float


def support_sums(k1: np.ndarray, k2: np.ndarray, dt: float, w: float, m: float) -> tuple[np.ndarray, ...]:
    """(sup|x|, sup|s|, sup|Δ|) over the minimal robust invariant set of the model (module doc), for arrays of gains
    ``k1``, ``k2`` (any shape); inf where A is not stable (spectral radius >= :data:`STABLE`)."""
    k1, k2 = np.broadcast_arrays(np.asarray(k1, dtype=float), np.asarray(k2, dtype=float))
    a = np.zeros(k1.shape + (2, 2))
    a[..., 0, 0], a[..., 0, 1] = 1 - dt * k1, dt * (1 - k2)
    a[..., 1, 0], a[..., 1, 1] = -k1, 1 - k2
    stable = np.max(np.abs(np.linalg.eigvals(a)), axis=-1) < STABLE
    a00, a01, a10, a11 = a[..., 0, 0], a[..., 0, 1], a[..., 1, 0], a[..., 1, 1]
    w0, w1 = 1 - dt * k1, -k1  # A^i times the deviation's column and the target's column, entry by entry
    m0, m1 = np.full_like(k1, -dt), np.full_like(k1, -1.0)
    x = s = change = np.zeros(k1.shape)
    for _ in range(MAX_TERMS):
        x = x + w * np.abs(w0) + m * np.abs(m0)
        s = s + w * np.abs(w1) + m * np.abs(m1)
        change = change + w * np.abs(-k1 * w0 - k2 * w1) + m * np.abs(-k1 * m0 - k2 * m1)
        w0, w1 = a00 * w0 + a01 * w1, a10 * w0 + a11 * w1
        m0, m1 = a00 * m0 + a01 * m1, a10 * m0 + a11 * m1
        live = stable & (np.maximum(np.abs(w0), np.abs(w1)) + np.maximum(np.abs(m0), np.abs(m1)) > TAIL)
        if not live.any():
            break
    inf = np.where(stable, 0.0, np.inf)
    return x + inf, s + inf, change + k1 * w + inf


def smallest_band(dt: float, w: float, m: float, jump: float) -> Band | None:
    """The gains of :data:`GAINS_1` × :data:`GAINS_2` whose minimal robust invariant set is narrowest in x while
    every command change stays within ``jump`` (J); None when no pair keeps Δ within J."""
    k1, k2 = np.meshgrid(GAINS_1, GAINS_2, indexing="ij")
    x, s, change = support_sums(k1, k2, dt, w, m)
    x = np.where(change <= jump, x, np.inf)
    i = np.unravel_index(int(np.argmin(x)), x.shape)
    if not math.isfinite(x[i]):
        return None
    return Band(x=float(x[i]), s=float(s[i]), change=float(change[i]), k1=float(k1[i]), k2=float(k2[i]))


def channels(b, jumps: tuple[float, float, float], speed_cap: float) -> dict[str, tuple[float, float, float]]:
    """(W, M, J) per channel from a certificate's terminal bounds ``b`` (``TerminalBounds``) and the plans' jumps
    J = ``jumps`` (m/s, m/s, rad/s per period), before the heading
    band's share of the radial channel (see :func:`study`). ``speed_cap``: the surge the terminal set needs, the
    target's speed plus the radial band's correction (m/s). Estimates (module doc), at the middle of the free e_d
    band d_m, with Δθ = asin(D_xy / d_m) + δ (P + u) / d_m the line of sight's turn in a period (the deviation's and
    the relative motion's; the heading's own deviation does not turn it):

    * heading: W = D_ψ + asin(D_xy / d_m); M = (A_xy δ + J_u + (P + u) Δθ) / d_m, the change per period of the line
      of sight's rate;
    * radial: W = D_xy; M = A_xy δ + P Δθ (the target's speed along a turning line of sight);
    * depth: W = D_z; M = A_z δ."""
    dt, j = b.dt, jumps
    d_mid = 0.5 * (b.room_d[0] + b.room_d[1])
    turn = math.asin(min(1.0, b.dev_xy / d_mid)) + dt * (b.speed_xy + speed_cap) / d_mid
    w_psi = b.dev_psi + math.asin(min(1.0, b.dev_xy / d_mid))
    return {"heading": (w_psi, (b.accel_xy * dt + j[0] + (b.speed_xy + speed_cap) * turn) / d_mid, j[2]),
            "radial": (b.dev_xy, b.accel_xy * dt + b.speed_xy * turn, j[0]),
            "depth": (b.dev_z, b.accel_z * dt, j[1])}


def radial_with_heading(w: float, m: float, speed: float, alpha: float, heading_step: float, dt: float,
                        divided: bool) -> tuple[float, float]:
    """The radial channel's (W, M) with the heading band |α| <= ``alpha`` (rad) whose angle moves by at most
    ``heading_step`` (rad) a period. ``divided``: the surge is divided by cos α (today's terminal law), so the
    command moves by u tan α × the heading's step (M grows); else the surge is not, and the closing speed falls
    short by u (1 − cos α) (a deviation of δ u (1 − cos α) a period: W grows)."""
    if divided:
        return w, m + speed * math.tan(alpha) * heading_step
    return w + dt * speed * (1.0 - math.cos(alpha)), m


def _bounds(path: Path, rate_scale: float):
    """(name, the certificate's ``TerminalBounds`` or None, the plans' jumps J per channel, the failed conditions
    besides ``terminal_rate``) for the scenario with its plans' rates × ``rate_scale``."""
    import verify
    from tubekit.scenario import load_scenario
    from verify.theorem.terminal import TERMINAL_PREFIXES, terminal_bounds

    sc = load_scenario(path)
    if sc.limits.rate is None:
        raise SystemExit(f"{path}: no limits.rate, nothing to ask")
    sc = sc.with_changes(**{"limits.rate": [rate_scale * float(r) for r in sc.limits.rate]})
    jumps = tuple(float(j) for j in sc.limits.jump(sc.controller.dt))
    cert = verify.certify(sc)
    failed = sorted(c.condition for c in cert.failures if not c.condition.startswith(TERMINAL_PREFIXES))
    if failed:
        return sc.name, None, jumps, ", ".join(failed[:4])
    return sc.name, terminal_bounds(sc, cert.design, cert.region), jumps, ""


def study(path: Path = SCENARIO, rate_scale: float = 1.0) -> dict:
    """Bands per channel against the room R leaves (module doc), for the scenario with its rates × ``rate_scale``."""
    name, b, jumps, failed = _bounds(path, rate_scale)
    out: dict = {"scenario": name, "rate_scale": rate_scale, "failed": failed}
    if b is None:
        return out
    room = {"heading": math.asin(min(b.room_o, 1.0)), "radial": 0.5 * (b.room_d[1] - b.room_d[0]),
            "depth": b.room_z}
    speed = b.speed_xy + 0.1 * room["radial"]  # the set's own surge: the target's speed and a radial correction
    w_m_j = channels(b, jumps, speed)
    heading = smallest_band(b.dt, *w_m_j["heading"])
    w, m, j = w_m_j["radial"]
    radial_wm = {}
    if heading is not None:
        alpha = min(heading.x + w_m_j["heading"][0], 1.5)
        step = w_m_j["heading"][0] + b.dt * heading.s
        radial_wm = {law: radial_with_heading(w, m, speed, alpha, step, b.dt, law == "radial")
                     for law in ("radial", "radial_plain")}
    depth = smallest_band(b.dt, *w_m_j["depth"])
    out["channels"] = {}
    rows = [("heading", heading, w_m_j["heading"])]
    rows += [(key, smallest_band(b.dt, *wm, j), (*wm, j)) for key, wm in radial_wm.items()]
    rows.append(("depth", depth, w_m_j["depth"]))
    room["radial_plain"] = room["radial"]
    for key, band, (w_c, m_c, j_c) in rows:
        need = None if band is None else band.x + w_c  # the replayed end lies within W of the set
        out["channels"][key] = {"W": w_c, "M": m_c, "J": j_c, "band": None if band is None else band.__dict__,
                                "needed": need, "room": room[key],
                                "fits": need is not None and need < room[key]}
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", type=Path, default=SCENARIO, help="a scenario with limits.rate")
    ap.add_argument("--rate-scale", type=float, nargs="+", default=[1.0, 1.5, 2.0],
                    help="factors on the plans' limits.rate (each re-certified)")
    args = ap.parse_args(argv)
    for scale in args.rate_scale:
        res = study(args.scenario, scale)
        print(f"{res['scenario']}, plans' rates x{scale:g}:", end="")
        if res["failed"]:
            print(f" not certified up to terminal_rate ({res['failed']})")
            continue
        print()
        for key, c in res["channels"].items():
            band = c["band"]
            text = ("no gains keep the change within J" if band is None else
                    f"|x| <= {band['x']:.3g} (+ W = {c['needed']:.3g}) against the room {c['room']:.3g}, "
                    f"|s| <= {band['s']:.3g}, k1 {band['k1']:.3g}, k2 {band['k2']:.3g}")
            print(f"  {key:8s} W {c['W']:.3g}, M {c['M']:.3g}, J {c['J']:.3g}: {text}"
                  f" -> {'fits' if c['fits'] else 'does not fit'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
