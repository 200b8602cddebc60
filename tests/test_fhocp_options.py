"""tubekit.fhocp.options: ScpOptions is frozen, validated on construction, and reaches the solver."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tubekit import ConfigError
from tubekit.fhocp import FHOCP, ScpOptions
from tubekit.scenario import TerminalMode

from .fhocp_cases import SC, STATES, tightening


@pytest.mark.parametrize("kwargs, field", [
    ({"max_obstacles": -1}, "max_obstacles"),
    ({"max_obstacles": True}, "max_obstacles"),
    ({"max_obstacles": 1.5}, "max_obstacles"),
    ({"terminal": "sometimes"}, "terminal"),
    ({"penalty": 0.0}, "penalty"),
    ({"penalty": float("nan")}, "penalty"),
    ({"terminal_penalty": -1.0}, "terminal_penalty"),
    ({"max_iterations": 0}, "max_iterations"),
    ({"cold_start_iterations": 0}, "cold_start_iterations"),
    ({"tolerance": -1e-5}, "tolerance"),
    ({"trust_radius": 0.0}, "trust_radius"),
    ({"extrapolate": "yes"}, "extrapolate"),
    ({"fast_path": 1}, "fast_path"),
    ({"clarabel_settings": ["max_iter", 5]}, "clarabel_settings"),
    ({"clarabel_settings": {1: 5}}, "clarabel_settings"),
])
def test_bad_option_is_a_config_error_naming_the_field(kwargs, field):
    with pytest.raises(ConfigError, match=rf"^{field}: expected"):
        ScpOptions(**kwargs)


def test_options_are_frozen_and_clarabel_settings_read_only():
    opts = ScpOptions(clarabel_settings={"max_iter": 50})
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.tolerance = 1.0  # type: ignore[misc]
    with pytest.raises(TypeError):
        opts.clarabel_settings["max_iter"] = 1  # type: ignore[index]
    copy = opts.clarabel_overrides()
    copy["max_iter"] = 1
    assert opts.clarabel_settings["max_iter"] == 50
    assert ScpOptions().clarabel_overrides() is None


def test_terminal_text_maps_to_the_enum_and_stays_equal_to_its_string():
    opts = ScpOptions(terminal="hard")
    assert opts.terminal is TerminalMode.HARD and opts.terminal == "hard" and f"{opts.terminal}" == "hard"


def test_the_solver_reads_its_options():
    tg = tightening()
    slow = FHOCP(SC, tg, mode="converged", options=ScpOptions(max_obstacles=2, fast_path=False, tolerance=1e-3,
                                                              trust_radius=0.25, terminal="off"))
    assert slow.max_obstacles == 2 and slow.compiled is None
    assert slow.tolerance == 1e-3 and slow.trust_radius == 0.25 and slow.nlp.terminal == "off"
    assert FHOCP(SC, tg).compiled is not None
    with pytest.raises(ConfigError, match="options"):
        FHOCP(SC, tg, options={"tolerance": 1e-3})  # type: ignore[arg-type]


def test_one_iteration_cap_stops_a_cold_start_after_one_subproblem():
    t, s = STATES[2]
    solver = FHOCP(SC, tightening(), mode="converged", options=ScpOptions(cold_start_iterations=1))
    res = solver.solve(t, np.array(s), SC.obstacles)
    assert res.iterations == 1
