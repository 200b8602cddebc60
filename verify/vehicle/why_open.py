"""Why the velocity loop's bound did not close: each channel's own small-gain loop and the coupling between them.

:func:`own_gains` splits a channel's own loop gain into its three parts (the drag mismatch's slope, the nominal
drag's slope over V + E, the added-mass interval) in the decomposition where they add up to least
(:mod:`verify.vehicle.bound`'s second, or the third's worst cell, :mod:`verify.vehicle.cells`); :func:`open_cause`
turns the first round's growth and those gains into the root cause an owner can act on.
"""

from __future__ import annotations

import math
from typing import Sequence

from flint import arb

from verify.kernel.intervals import upper
from verify.vehicle.cells import cell_own_gains
from verify.vehicle.loop_data import LoopData
from verify.vehicle.model import channel_gradient, channel_mismatch_gradient, velocity_box
from verify.vehicle.pi_loop import free_why_open

__all__ = ["own_gains", "open_cause"]


def own_gains(loop: LoopData, error: Sequence[float]) -> tuple[tuple[float, float, float], ...]:
    """Per channel, the three parts of its own small-gain loop over the box |y_c| <= V_c + E_c (``error``), in the
    decomposition where they add up to least: the second (module doc) or, in its worst cell, the third
    (:func:`verify.vehicle.cells.cell_own_gains`). sup μ × the L1 gain to ẏ of (the mismatch's own slope — in a cell
    its residual about δ_k —, the nominal drag's slope variation sup|∂n̂_c/∂y_c/m̂_c − λ_c|, the mass mismatch
    sup|1 − 1/μ| — in a cell |1 − μ_k/μ|), each per unit Ŷ_c (dimensionless). A channel whose parts add up to 1 or
    more cannot close whatever the others do."""
    box, gamma = loop.box(error)
    if not math.isfinite(gamma):
        return tuple((math.inf,) * 3 for _ in loop.names)
    nu = velocity_box(box[0], gamma, box[1], box[2])
    grads = channel_gradient(loop.nominal, nu, loop.lateral)
    d_grad = channel_mismatch_gradient(loop.nominal, loop.hull, nu, loop.lateral)
    out = []
    for c in range(len(loop.names)):
        own, mu = loop.own[c], loop.m_hat[c] / loop.m_true[c]
        _, _, h_rate, h_drag, _ = loop.gain_balls[c][3]
        drag_slope = abs(grads[c][own] / loop.m_hat[c] - arb(loop.slope[c]))
        parts = tuple(upper(mu * x) for x in (h_rate * abs(d_grad[c][own]) / loop.m_hat[c], h_drag * drag_slope,
                                              loop.mass_gain_balls[c][3] * abs(1 - 1 / mu)))
        in_cells = cell_own_gains(loop, c, nu, drag_slope)
        out.append(parts if in_cells is None or sum(parts) <= sum(in_cells) else in_cells)
    return tuple(out)


#: What the fixed point bounds, per channel, in the order of :func:`computed_bounds`' rows.
_QUANTITIES = ("sup|e|", "sup|a|", "sup|z|", "sup|ydot|")


def open_cause(loop: LoopData, found: bool, stop: str, growth: list | None, first_box: Sequence[float] = ()) -> str:
    """The root cause of a fixed point that did not close (empty when it closed), in words an owner can act on: a
    channel whose own loop gain (:func:`own_gains`, at the first round's box) is 1 or more, with its three parts,
    else the coupling between the channels."""
    if found or growth is None:
        return ""
    head = f"diverged ({stop})"
    if loop.free is not None:
        return free_why_open(loop, head)
    knobs = ("a narrower coefficient box, a smaller V, smaller command jumps (a gentler backup, a lower plan rate) "
             "or a faster loop (plant.vehicle.loop_bandwidth, where the thrusters' lag and limits allow it) lower it")
    rising = [(growth[c][o], c, o) for c in range(len(growth)) for o in range(4) if math.isfinite(growth[c][o])]
    if rising:
        g, c, o = max(rising)
        head += (f"; the first round multiplied the bounds by up to {g:.3g} ({_QUANTITIES[o]} of channel "
                 f"{loop.names[c]})")
    gains = own_gains(loop, first_box) if first_box else ()
    worst = max(range(len(gains)), key=lambda c: sum(gains[c]), default=None)
    if worst is not None and sum(gains[worst]) >= 1.0:
        mism, drag, mass = gains[worst]
        return (f"{head}; channel {loop.names[worst]} cannot close on its own: its own loop gain is "
                f"{mism + drag + mass:.3g} >= 1 ({mism:.3g} from the drag mismatch's slope, the intervals of its "
                f"damping coefficients; {drag:.3g} from the nominal drag's slope over V + E; {mass:.3g} from its "
                f"added-mass interval; in the decomposition where they are least) (docs/plant.md, section 4); {knobs}")
    if worst is None:
        return f"{head}; the small-gain loop's gain is not below 1 here (docs/plant.md, section 4); {knobs}"
    through = ("the cross terms (Coriolis, the mismatch's other slopes)" if loop.lateral else
               "the cross terms and the hull's free sway (its bound γ̄ and its rate through the sway row, which grow "
               "with E_u and E_r)")
    return (f"{head}; at the first round's box every channel's own loop gain is below 1 (the largest "
            f"{sum(gains[worst]):.3g}, channel {loop.names[worst]}), but the channels drive one another through "
            f"{through} and the slopes grow with E: together the small-gain loop's gain is not below 1 here "
            f"(docs/plant.md, section 4); {knobs}")
