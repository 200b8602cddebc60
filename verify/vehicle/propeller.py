"""The propeller's thrust tied to the hull's drag by its top speed (``plant.vehicle.top_speed``).

A box that takes the thrust limit X_max and the surge drag (X_u, X_u|u|) as independent intervals pairs the
weakest propeller with the largest drag: for REMUS 100's bundled box, Prestero's thrust (10.1 N, the thrust his own
drag needs at 2.5 m/s) against Fossen's drag, a hull whose top speed is 1.27 m/s, which neither source describes.
With ``top_speed`` s in [s_lo, s_hi] every hull's thrust is the one that holds it at its top speed running straight,
X_max(θ) = |X_u| s + |X_u|u|| s², so over a cell of the drag coefficient

    X_max(θ) >= X_floor(cell) = max(X_max's lower end, |X_u|_lo s_lo + |X_u|u||_lo(cell) s_lo²)      (N),

a lower bound that moves with the drag. No interval is narrowed: X_max's own interval must hold every tied thrust
(:class:`tubekit.model.vehicle_params.VehicleParams`).

**Step T1, the surge command against its own hull's thrust** (``loop_saturation[X]``). In the second
decomposition of :mod:`verify.vehicle.bound`, τ_cmd_u = n_u(ν; θ) + m̂_u (k_i, k_p, 0) x exactly, and
:func:`verify.vehicle.bound.command_excess` bounds the second term by B (N) under the fixed point's assumptions. So
|τ_cmd_u| < X_max(θ) for every θ when, in every cell of X_u|u| (:data:`DRAG_CELLS`) and every surge band,
sup|n_u(ν; θ_cell)| + B < X_floor(cell) (:func:`tied_surge_need`): the need and the thrust come from the same hull.

**Step T2, the surge acceleration each hull delivers** (``rate_authority[u]``): per cell,
a_u >= (X_floor(cell) − sup|n_u(ν; θ_cell)|) / sup m11 over V, the least over the cells and the surge bands
(:func:`tied_surge_authority`).
"""

from __future__ import annotations

import math
from typing import Sequence

from flint import arb

from tubekit.model.vehicle_params import VehicleParams
from verify.kernel.intervals import enclose, lower, upper
from verify.vehicle.model import arb_body_forces, hull_balls, velocity_box

__all__ = ["DRAG_CELLS", "drag_cells", "tied_surge_need", "tied_surge_authority"]

#: Cells of the quadratic surge drag X_u|u| in which the tied thrust is taken (a count).
DRAG_CELLS = 32


def drag_cells(params: VehicleParams) -> list[tuple[dict[str, arb], float]]:
    """Per cell of X_u|u| (:data:`DRAG_CELLS` equal cells of its interval): the hull's balls with that cell, and
    X_floor(cell) (N), the smallest thrust a hull of the cell has (module doc)."""
    base = hull_balls(params)
    s_lo = arb(params.interval("top_speed")[0])
    x_lo = params.interval("X_max")[0]
    linear = arb(-params.interval("X_u")[1])  # damping is <= 0 over the box: the least |x| is at the upper end
    lo, hi = params.interval("X_uu")
    edges = [lo + (hi - lo) * k / DRAG_CELLS for k in range(DRAG_CELLS + 1)] if hi > lo else [lo, hi]
    out = []
    for a, b in zip(edges[:-1], edges[1:]):
        tied = lower(linear * s_lo + arb(-b) * s_lo * s_lo)
        out.append(({**base, "X_uu": enclose(a, b)}, max(x_lo, tied)))
    return out


def _surge_force(hull: dict[str, arb], box: Sequence[float], sway: float, surge: tuple[float, float]) -> arb:
    """n_u over the surge band ``surge`` (m/s), |v| <= ``sway``, |w| <= box[1], |r| <= box[2] and the cell's hull."""
    return arb_body_forces(hull, (enclose(*surge), *velocity_box(0.0, sway, box[1], box[2])[1:]))[0]


def tied_surge_need(params: VehicleParams, box: Sequence[float], sway: float, bands: Sequence[tuple[float, float]],
                    excess: float) -> tuple[float, float]:
    """(need, thrust) (N) of the cell and surge band where need/thrust is largest (Step T1): need =
    sup|n_u(ν; θ_cell)| + ``excess`` over the band, thrust = X_floor(cell); the condition holds iff need < thrust
    there. ``box`` is (|u|, |w|, |r|) of the velocity box (m/s, m/s, rad/s), ``sway`` its |v| (m/s), ``bands`` the
    surge bands (m/s), ``excess`` :func:`verify.vehicle.bound.command_excess` (N)."""
    worst = (-math.inf, math.inf, math.inf)
    for hull, thrust in drag_cells(params):
        for band in bands:
            need = upper(abs(_surge_force(hull, box, sway, band)) + arb(excess))
            ratio = need / thrust if thrust > 0.0 else math.inf
            if ratio > worst[0]:
                worst = (ratio, need, thrust)
    return worst[1], worst[2]


def tied_surge_authority(params: VehicleParams, box: Sequence[float], sway: float,
                         bands: Sequence[tuple[float, float]]) -> float:
    """a_u (m/s²) of Step T2: the least over the cells of X_u|u| and the surge ``bands`` (m/s) of
    (X_floor(cell) − sup|n_u|) / sup m11, with |w| <= box[1], |r| <= box[2] and |v| <= ``sway``."""
    worst = math.inf
    for hull, thrust in drag_cells(params):
        for band in bands:
            force = _surge_force(hull, box, sway, band)
            worst = min(worst, lower((arb(thrust) - abs(force)) / hull["m11"]))
    return worst
