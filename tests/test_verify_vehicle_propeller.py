"""The propeller's thrust tied to the hull's drag by its top speed (verify.vehicle.propeller)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from flint import arb
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.model.vehicles import vehicle_params
from tubekit.plant.dynamic import body_forces
from verify.vehicle.bound import velocity_loop_bound
from verify.vehicle.model import arb_body_forces
from verify.vehicle.propeller import DRAG_CELLS, drag_cells

ROOT = Path(__file__).resolve().parents[1]
#: Each source's own pair: Prestero's thrust against his drag (10.1 N / 1.62 kg/m), Fossen's (41.2 N / 6.23 kg/m).
TOP_SPEED = (2.497, 2.571)
#: examples/remus100_published.toml's loop design: surge band, |w|, |r| (m/s, m/s, rad/s), the plans' rates.
U_MIN, V_MAX, RATE = 0.57, (1.4, 0.007, 0.0048), (0.05, 0.001, 0.0005)


def _published(tied: bool):
    base = dataclasses.replace(vehicle_params("remus100"), yaw_loop_bandwidth=10.0, heave_loop_bandwidth=3.0)
    return dataclasses.replace(base, top_speed=TOP_SPEED) if tied else base


def _loop(params):
    return velocity_loop_bound(params, v_max=V_MAX, tick=0.01, period=0.1, jump_tick=(0.0, 0.0, 0.0),
                               jump_period=tuple(0.1 * r for r in RATE), rate=RATE, surge_floor=U_MIN, settled=True)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(quad=st.floats(1.62, 6.23), speed=st.floats(*TOP_SPEED), u=st.floats(0.5, 1.5), v=st.floats(-0.01, 0.01),
       w=st.floats(-0.01, 0.01), r=st.floats(-0.01, 0.01))
def test_every_hull_on_the_tie_has_at_least_its_cells_thrust_and_its_surge_force_inside_the_cells(quad, speed, u, v,
                                                                                                   w, r):
    """Property: a hull of the published box whose thrust holds it at its top speed (X_max = |X_uu| s²) lies in one
    drag cell, whose thrust floor is at most that hull's thrust and whose Arb surge force holds the plant's n_u."""
    box = _published(tied=True)
    hull = box.with_point({"X_uu": -quad, "top_speed": speed})
    cells = drag_cells(box)
    assert len(cells) == DRAG_CELLS
    inside = [(balls, floor) for balls, floor in cells if balls["X_uu"].contains(arb(-quad))]
    assert inside
    nu = (arb(u), arb(v), arb(w), arb(r))
    for balls, floor in inside:
        assert floor <= hull.X_max == pytest.approx(quad * speed ** 2)
        assert arb_body_forces(balls, nu)[0].contains(arb(body_forces(hull, (u, v, w, r))[0]))


def test_the_published_boxs_propeller_is_short_only_when_its_thrust_is_not_tied_to_its_drag():
    """At examples/remus100_published.toml's loop design the untied box asks its weakest propeller (Prestero's
    10.1 N) to push Fossen's drag, more than it has; tied, each hull's need is below its own thrust, and it is not
    a trivial number: at least the lightest hull's drag at 1.4 m/s, 1.62 x 1.4² = 3.18 N (by hand). The surge
    acceleration each hull delivers is larger tied (its thrust grows with its drag)."""
    untied, tied = _loop(_published(False)), _loop(_published(True))
    by_name = [{c.condition: c for c in b.conditions} for b in (untied, tied)]
    assert by_name[0]["loop_fixed_point"].ok and by_name[1]["loop_fixed_point"].ok
    x_untied, x_tied = by_name[0]["loop_saturation[X]"], by_name[1]["loop_saturation[X]"]
    assert not x_untied.ok and x_untied.lhs > 10.1 and "top speed" in x_untied.detail
    assert x_tied.ok and 1.62 * 1.4 ** 2 < x_tied.lhs < x_tied.rhs and x_tied.rhs >= 10.1
    assert "tied to its drag" in x_tied.detail
    assert tied.authority[0] > max(untied.authority[0], RATE[0])
    assert [c.condition for c in tied.conditions if not c.ok] == []


@pytest.mark.slow(25)
def test_the_published_survey_keeps_the_bundled_box_and_is_flown_by_its_weakest_and_strongest_propellers():
    """examples/remus100_published.toml: every coefficient interval is the bundled vehicle's own (none narrowed, X_max
    included), a line at >= 1.0 m/s in >= 0.3 m/s of horizontal current with epsilon <= 3 m and a surge floor above
    0.5 m/s, both tiers certified; flown 20 s by the hull with Prestero's drag and thrust (the weakest propeller, the
    binding drag cell) and by Fossen's, every promise is kept, no tick saturated, the plan followed, the surge never
    below u_min. (One certificate for all: certifying it takes most of this test.)"""
    import tubekit
    import verify
    scenario = tubekit.load_scenario(ROOT / "examples" / "remus100_published.toml")
    bundled, box = vehicle_params("remus100"), scenario.plant.params
    assert box.tied and set(bundled.interval_fields) <= set(box.interval_fields)
    assert all(box.interval(name) == bundled.interval(name) for name in bundled.interval_fields)
    assert scenario.trajectory.direction_velocity[0] >= 1.0 and min(scenario.disturbance.amplitude[:2]) >= 0.3
    assert scenario.epsilon <= 3.0 and scenario.limits.u_min > 0.5
    cert = verify.certify(scenario)
    assert cert.tiers.safe and cert.tiers.tracking
    for quad, speed in ((1.62, 2.497), (6.23, 2.571)):
        plant = dataclasses.replace(scenario.plant, truth={"X_uu": -quad, "top_speed": speed})
        run = tubekit.simulate(scenario.with_changes(plant=plant, duration=20.0), cert, progress=False)
        assert [p.name for p in tubekit.check_promises(run) if p.given and not p.ok] == [], quad
        assert run.metrics["saturated_steps"] == 0 and run.metrics["replaced_steps"] == 0
        assert float(np.min(run.inputs[:-1, 0])) >= scenario.limits.u_min
