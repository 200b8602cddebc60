"""How fast a fin-steered hull can turn at all: the steady turn at full rudder, over the corners of its box.

A certificate's yaw-rate limit r_max must be a rate the vehicle can hold against its own hull, so the steady turn
at full rudder is an upper bound on any certifiable r_max at that surge. For a hull with fins (``actuation =
"fins"``) at surge u, the steady turn (v, r) balances the hull's sway and yaw rows of n(ν)
(``tubekit.plant.dynamic.body_forces``) against no lateral force and the rudder's full moment |N_uuδr| u² δ_max:

    n_2(u, v, 0, r) = 0,     n_4(u, v, 0, r) = |N_uuδr| u² δ_max.

For each r the sway row is strictly increasing in v (its damping −Y_vv|v|v − Y_uv u v with Y_vv, Y_uv <= 0), so
v(r) is its one root (``brentq``); the turn rate is the first r > 0 where the yaw row reaches the rudder's moment
(a scan, then ``brentq``). Every corner of the box's intervals that enter these rows is solved (the mass entries,
the sway and yaw damping, the rudder; the bundled REMUS 100: 2^8 = 256 corners); the table gives the slowest
corner's turn, the midpoint hull's and the fastest corner's, with the slowest corner's radius u / r.

Without linear damping (Y_v = N_r = 0, as bundled) every term of both rows and the rudder's moment scale as u²
when (v, r) scale as u, so the radius does not depend on the speed: a slower surge turns proportionally slower.

Usage: ``python benchmarks/steady_turn.py [--vehicle remus100] [--speed 0.57 1.0 1.4] [--rudder 1.0]``
(a second or two). Nothing is timed.
"""

from __future__ import annotations

import argparse
import itertools
import math
import sys
from dataclasses import dataclass

__all__ = ["SteadyTurn", "steady_turn", "steady_fields", "steady_sway", "corner_turns", "STEADY_FIELDS", "main"]

#: The box's coefficients that enter the steady sway and yaw rows (the mass entries m11, m22, m24 and the damping),
#: and the rudder.
STEADY_FIELDS = ("m", "X_udot", "Y_vdot", "Y_rdot", "Y_v", "Y_vv", "Y_rr", "N_r", "N_vv", "N_rr", "N_uudr")
#: The largest turn rate searched (rad/s) and the scan's step (rad/s).
R_SEARCH, R_STEP = 5.0, 1e-3


@dataclass(frozen=True)
class SteadyTurn:
    """One steady turn: surge u (m/s), sway v (m/s), yaw rate r (rad/s) and the rudder's moment (N m)."""

    u: float
    v: float
    r: float
    moment: float

    @property
    def radius(self) -> float:
        """u / r (m): the turn's radius measured along the surge."""
        return self.u / self.r


def steady_sway(params, u: float, r: float) -> float:
    """The v where the sway row n_2(u, v, 0, r) vanishes (m/s)."""
    from scipy.optimize import brentq

    from tubekit.plant.dynamic import body_forces

    reach = 10.0 * (abs(u) + abs(r)) + 1.0
    return brentq(lambda v: body_forces(params, (u, v, 0.0, r))[1], -reach, reach, xtol=1e-14)


def steady_turn(params, u: float, rudder: float = 1.0) -> SteadyTurn | None:
    """The steady turn of the point hull ``params`` at surge ``u`` (m/s) with the rudder at ``rudder`` of its
    largest angle (0 < rudder <= 1): the smallest r > 0 whose yaw row reaches the moment; None when no r up to
    :data:`R_SEARCH` does."""
    from scipy.optimize import brentq

    from tubekit.plant.dynamic import body_forces

    moment = abs(params.N_uudr) * u * u * params.fin_max * rudder

    def excess(r: float) -> float:
        return body_forces(params, (u, steady_sway(params, u, r), 0.0, r))[3] - moment

    lo = 0.0
    f_lo = excess(lo)
    for k in range(1, int(R_SEARCH / R_STEP) + 1):
        hi = k * R_STEP
        f_hi = excess(hi)
        if f_lo < 0.0 <= f_hi:
            r = brentq(excess, lo, hi, xtol=1e-14)
            return SteadyTurn(u=u, v=steady_sway(params, u, r), r=r, moment=moment)
        lo, f_lo = hi, f_hi
    return None


def steady_fields(box) -> list[str]:
    """The fields of :data:`STEADY_FIELDS` that are intervals of ``box`` (the corners' axes)."""
    return [n for n in STEADY_FIELDS if n in box.free_fields]


def corner_turns(box, u: float, rudder: float = 1.0) -> list[tuple[dict[str, float], SteadyTurn | None]]:
    """Each corner of ``box`` (a :class:`tubekit.model.vehicle_params.VehicleParams`) over its intervals among
    :data:`STEADY_FIELDS`, with its steady turn at ``u`` (m/s); the other coefficients at their midpoints."""
    names = steady_fields(box)
    out = []
    for ends in itertools.product((0, 1), repeat=len(names)):
        corner = {n: box.interval(n)[e] for n, e in zip(names, ends)}
        out.append((corner, steady_turn(box.with_point(corner), u, rudder)))
    return out


def _check_args(args: argparse.Namespace, ap: argparse.ArgumentParser) -> None:
    if not all(math.isfinite(s) and s > 0.0 for s in args.speed):
        ap.error(f"--speed: expected positive speeds (m/s), got {args.speed}")
    if not (math.isfinite(args.rudder) and 0.0 < args.rudder <= 1.0):
        ap.error(f"--rudder: expected a fraction in (0, 1], got {args.rudder}")


def main(argv: list[str] | None = None) -> int:
    from tubekit.model.vehicles import vehicle_params

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vehicle", default="remus100", help="a bundled vehicle with fins")
    ap.add_argument("--speed", type=float, nargs="+", default=[0.57, 1.0, 1.4], help="surge speeds (m/s)")
    ap.add_argument("--rudder", type=float, default=1.0, help="the rudder's share of its largest angle")
    args = ap.parse_args(argv)
    _check_args(args, ap)
    box = vehicle_params(args.vehicle)
    if box.actuation != "fins":
        ap.error(f"--vehicle: expected a vehicle with fins, got {args.vehicle!r} ({box.actuation})")
    print(f"{args.vehicle}: steady turn with the rudder at {args.rudder:g} of {box.fin_max:g} rad, "
          f"{2 ** len(steady_fields(box))} corners")
    print("| u (m/s) | slowest corner r (rad/s) | its radius (m) | midpoint r | fastest corner r |")
    print("|---|---|---|---|---|")
    for u in args.speed:
        turns = [t for _, t in corner_turns(box, u, args.rudder)]
        rates = [t.r for t in turns if t is not None]
        slow = min((t for t in turns if t is not None), key=lambda t: t.r)
        mid = steady_turn(box.nominal, u, args.rudder)
        missing = "" if len(rates) == len(turns) else f" ({len(turns) - len(rates)} corners: no turn found)"
        print(f"| {u:g} | {slow.r:.4g} | {slow.radius:.3g} | {mid.r:.4g} | {max(rates):.4g}{missing} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
