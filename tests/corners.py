"""A scenario's coefficient box: its simulated hull at a corner, and its share of the published spread (helpers, not
a test module)."""

from __future__ import annotations

import dataclasses

from tubekit.scenario import Scenario

__all__ = ["at_corner", "flown_at_corner", "assert_holds_share"]


def at_corner(scenario: Scenario, end: int) -> Scenario:
    """``scenario`` with the simulated hull (``[plant.truth]``) at the lower (``end`` 0) or upper (1) end of every
    interval of its vehicle's coefficient box; the certificate's box is unchanged."""
    params = scenario.plant.params
    corner = {k: v[end] for k, v in vars(params).items() if not k.startswith("_") and isinstance(v, tuple)}
    return scenario.with_changes(plant=dataclasses.replace(scenario.plant, truth=tuple(corner.items())))


def flown_at_corner(scenario: Scenario, end: int, cert, duration: float | None = 20.0) -> tuple[dict, object]:
    """(the promises by name, the run) of ``duration`` s (None: the scenario's own) of ``scenario`` under the
    certificate ``cert`` with the hull at the lower (``end`` 0) or upper (1) corner of its coefficient box."""
    import tubekit
    run = tubekit.simulate(at_corner(scenario, end), cert, duration=duration, progress=False)
    return {p.name: p for p in tubekit.check_promises(run)}, run


def assert_holds_share(scenario: Scenario, vehicle: str, share: float, inside: bool = False) -> None:
    """Assert that ``scenario``'s coefficient box contains ``share`` of the bundled ``vehicle``'s spread about its
    midpoints (``VehicleParams.shrunk``) in every interval, and with ``inside`` that it lies within that spread."""
    from tubekit.model.vehicles import vehicle_params
    published = vehicle_params(vehicle)
    inner, own = published.shrunk(share), scenario.plant.params
    for field in inner.interval_fields:
        (lo, hi), (a, b) = own.interval(field), inner.interval(field)
        assert lo <= a and b <= hi, field
        if inside:
            p_lo, p_hi = published.interval(field)
            assert p_lo <= lo and hi <= p_hi, field
