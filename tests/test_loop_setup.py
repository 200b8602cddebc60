"""tubekit.loop.setup: a run's arguments, its time grid and the clip to V."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tubekit import ConfigError, Tightening, paper_scenario
from tubekit.loop.setup import Clock, saturate, status_text, validate_inputs
from tubekit.tiers import Tiers


def test_the_clock_holds_periods_of_ticks_of_substeps():
    sc = paper_scenario().with_changes(duration=1.0)
    clock = Clock.of(sc, 2)
    assert (clock.steps, clock.ticks, clock.substeps) == (10, 10, 2)
    assert clock.h == pytest.approx(0.01) and clock.plant_step == pytest.approx(0.005)
    assert len(clock.t) == 101 and clock.t[-1] == pytest.approx(1.0) and len(clock.tau) == 11


def test_saturate_clips_only_outside_the_box_and_says_so():
    assert saturate((0.1, -0.2, 0.3), (0.4, 0.3, 0.5)) == ((0.1, -0.2, 0.3), False)
    assert saturate((0.5, -0.35, 0.2), (0.4, 0.3, 0.5)) == ((0.4, -0.3, 0.2), True)


def test_saturate_clips_to_a_surge_floor_as_to_the_upper_corner():
    """With V's lower corner (u_min = 0.1 m/s) a surge below it is clipped up and counted; None is the symmetric box."""
    lim, low = (0.4, 0.3, 0.5), (0.1, -0.3, -0.5)
    assert saturate((0.1, -0.3, 0.5), lim, low) == ((0.1, -0.3, 0.5), False)
    assert saturate((0.05, -0.35, 0.2), lim, low) == ((0.1, -0.3, 0.2), True)
    assert saturate((-0.4, 0.0, 0.0), lim, low) == ((0.1, 0.0, 0.0), True)
    assert saturate((-0.4, 0.0, 0.0), lim, None) == ((-0.4, 0.0, 0.0), False)


def test_status_text_reads_enums_and_strings():
    from tubekit.scenario import FhocpMode
    assert status_text(FhocpMode.REALTIME) == "realtime" and status_text("optimal") == "optimal"


def test_validate_inputs_calls_the_one_design_check():
    """The tightening's require() runs here, once, before any tick: a run of another start is refused."""
    from tubekit.design_inputs import DesignInputs
    sc = paper_scenario()
    tight = dataclasses.replace(Tightening.untightened(sc), sigma=0.0, design=DesignInputs.of(sc, sigma=0.0),
                                tiers=Tiers(True, True))
    assert validate_inputs(sc, tight, True, 2)[2] == 0.0
    with pytest.raises(ConfigError, match=r"design_key\.initial_state"):
        validate_inputs(sc.with_changes(initial_state=(0.0, 2.0, 0.0, 0.0)), tight, True, 2)
    with pytest.raises(ConfigError, match="plant_substeps"):
        validate_inputs(sc, tight, True, 0)
    assert np.array_equal(validate_inputs(sc, None, False, 2)[0].v_max, sc.limits.vector)
