"""The scenario TOML schema (docs/scenario.md): round trip, examples, one error per bad field."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tubekit import ConfigError, TubekitError, load_scenario, paper_scenario, scenario_from_dict
from tubekit.model.trajectory import Circle, Helix, Line, Waypoints
from tubekit.model.vehicles import PlantSettings

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(type(v))


def _to_toml(d: dict, prefix: str = "") -> str:
    """A minimal TOML writer for scenario dicts (scalars, arrays, tables, arrays of tables)."""
    lines, tables, arrays = [], [], []
    for k, v in d.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            arrays.append((k, v))
        else:
            lines.append(f"{k} = {_toml_value(v)}")
    out = "\n".join(lines) + "\n"
    for k, v in tables:
        name = f"{prefix}{k}"
        out += f"\n[{name}]\n" + _to_toml(v, name + ".")
    for k, v in arrays:
        for item in v:
            out += f"\n[[{prefix}{k}]]\n" + _to_toml(item, f"{prefix}{k}.")
    return out


def test_paper_scenario_round_trips_through_toml(tmp_path):
    sc = paper_scenario()
    path = tmp_path / "paper.toml"
    path.write_text(_to_toml(sc.to_dict()))
    back = load_scenario(path)
    assert back == sc
    assert back.to_dict() == sc.to_dict()


def test_paper_defaults_are_section_vi():
    sc = scenario_from_dict({})
    assert isinstance(sc.trajectory, Circle) and sc.trajectory.radius == 3.0
    assert sc.trajectory.rate == pytest.approx(math.pi / 25)
    assert [o.center for o in sc.obstacles] == [(3.0, 0.0, 0.0), (-3.0, 0.0, 0.0)]
    assert tuple(sc.limits.vector) == (0.4, 0.3, 0.5)
    assert (sc.sensing_range, sc.epsilon, sc.duration) == (1.5, 0.1, 100.0)
    assert (sc.controller.dt, sc.controller.horizon_steps) == (0.1, 8)
    assert sc.disturbance.amplitude == (0.1, 0.1, 0.1) and sc.disturbance.period == 15.0


@pytest.mark.parametrize("name, cls", [("circle", Circle), ("helix", Helix), ("line", Line),
                                       ("waypoints", Waypoints)])
def test_examples_load(name, cls):
    sc = load_scenario(EXAMPLES / f"{name}.toml")
    assert type(sc.trajectory) is cls and sc.name == name
    assert len(sc.obstacles) >= 1


def test_circle_example_is_the_paper_scenario():
    a = load_scenario(EXAMPLES / "circle.toml").to_dict()
    b = paper_scenario().to_dict()
    a.pop("name"), b.pop("name")
    assert a == b


def test_missing_keys_take_paper_values_and_tables_merge():
    sc = scenario_from_dict({"limits": {"u_max": 0.6}, "controller": {"dt": 0.2, "ancillary_rate_hz": 50.0}})
    assert tuple(sc.limits.vector) == (0.6, 0.3, 0.5)
    assert sc.controller.dt == 0.2 and sc.controller.horizon_steps == 8


BAD = [
    ({"speed": 1.0}, "speed"),
    ({"trajectory": {"kind": "spiral"}}, r"trajectory\.kind"),
    ({"trajectory": {"radius": 3.0}}, r"trajectory\.kind"),
    ({"trajectory": {"kind": "circle", "radius": -1.0}}, r"trajectory\.radius"),
    ({"trajectory": {"kind": "circle", "foo": 1.0}}, r"trajectory"),
    ({"trajectory": {"kind": "waypoints", "points": [[0.0, 0.0, 0.0]]}}, r"trajectory\.points"),
    ({"obstacles": [{"center": [3.0, 0.0, 0.0], "radius": 0.4}, {"center": [-3.0, 0.0, 0.0], "radius": 0.0}]},
     r"obstacles\[1\]\.radius"),
    ({"obstacles": [{"center": [3.0, 0.0, 0.0]}]}, r"obstacles\[0\]"),
    ({"obstacles": [{"center": "here", "radius": 0.4}]}, r"obstacles\[0\]\.center"),
    ({"obstacles": {"center": [0.0, 0.0, 0.0], "radius": 1.0}}, r"obstacles"),
    ({"obstacles": [{"center": [0.0, 0.0, 0.0], "radius": 0.4}, {"center": [1.0, 0.0, 0.0], "radius": 0.4}]},
     r"obstacles\[0\], obstacles\[1\]"),
    ({"limits": {"u_max": 0.0}}, r"limits\.u_max"),
    ({"limits": {"v_max": 1.0}}, r"limits\.v_max"),
    ({"limits": 5}, r"limits"),
    ({"vehicle_radius": -0.2}, r"vehicle_radius"),
    ({"sensing_range": 0.1}, r"sensing_range"),
    ({"epsilon": "small"}, r"epsilon"),
    ({"duration": float("nan")}, r"duration"),
    ({"disturbance": {"period": -15.0}}, r"disturbance\.period"),
    ({"disturbance": {"amplitude": [-0.1, 0.1, 0.1]}}, r"disturbance\.amplitude"),
    ({"disturbance": {"sway": {"gian": 0.1}}}, r"disturbance\.sway"),
    ({"controller": {"law": "magic"}}, r"controller\.law"),
    ({"controller": {"ancillary_rate_hz": 15.0}}, r"controller\.ancillary_rate_hz"),
    ({"controller": {"horizon_steps": 0}}, r"controller\.horizon_steps"),
    ({"controller": {"Q": [1.0, 0.0, 1.0]}}, r"controller\.Q"),
    ({"controller": {"sigma": -1.0}}, r"controller\.sigma"),
    ({"controller": {"gain": 1.0}}, r"controller\.gain"),
    ({"region": {"e_o_max": 1.0}}, r"region\.e_o_max"),
    ({"region": {"heading": "sideways"}}, r"region\.heading"),
    ({"controller": {"fhocp_mode": "fast"}}, r"controller\.fhocp_mode: expected one of \('realtime', 'converged'\)"),
    ({"controller": {"terminal_mode": "SOFT"}},
     r"controller\.terminal_mode: expected one of \('soft', 'hard', 'off'\)"),
    ({"region": {"heading": "TOWARD"}}, r"region\.heading: expected one of \('toward', 'away', 'both'\)"),
    ({"controller": {"fhocp_backend": ""}}, r"controller\.fhocp_backend"),
    ({"controller": {"fhocp_backend": 3}}, r"controller\.fhocp_backend"),
    ({"region": {"e_d_max": 0.05}}, r"region\.e_d_max"),
    ({"workspace": [[0.0, 0.0, 0.0], [-1.0, 1.0, 1.0]]}, r"workspace"),
    ({"workspace": [[0.0, 0.0, 0.0]]}, r"workspace"),
]


@pytest.mark.parametrize("data, field", BAD, ids=[f for _, f in BAD])
def test_each_bad_field_is_named(data, field):
    with pytest.raises(ConfigError, match=field):
        scenario_from_dict(data)


@pytest.mark.parametrize("data, field", [({"initial_state": [1.0, 2.0, 3.0]}, "initial_state"),
                                         ({"controller": {"R": [1.0, 1.0]}}, r"controller\.R")])
def test_wrong_lengths_are_named(data, field):
    with pytest.raises(TubekitError, match=field):
        scenario_from_dict(data)



def test_sway_errors_name_the_full_path():
    with pytest.raises(ConfigError, match=r"disturbance\.sway\.bound"):
        scenario_from_dict({"disturbance": {"sway": {"bound": -1.0}}})


def test_obstacle_centre_length_names_the_index():
    with pytest.raises(TubekitError, match=r"obstacles\[0\]\.center"):
        scenario_from_dict({"obstacles": [{"center": [1.0, 2.0], "radius": 0.4}]})


def test_boolean_is_not_a_number():
    with pytest.raises(ConfigError, match="duration"):
        scenario_from_dict({"duration": True})


def test_file_errors_name_config(tmp_path):
    with pytest.raises(ConfigError, match="CONFIG"):
        load_scenario(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("duration = = 3\n")
    with pytest.raises(ConfigError, match="CONFIG.*valid TOML"):
        load_scenario(bad)


# ---- enums, backend name, dotted changes ------------------------------------------------------

def test_modes_and_heading_are_enums_equal_to_their_toml_strings(tmp_path):
    import json

    from tubekit.scenario import FhocpMode, Heading, TerminalMode
    sc = scenario_from_dict({"controller": {"fhocp_mode": "converged", "terminal_mode": "hard"},
                             "region": {"heading": "both"}})
    assert sc.controller.fhocp_mode is FhocpMode.CONVERGED and sc.controller.fhocp_mode == "converged"
    assert sc.controller.terminal_mode is TerminalMode.HARD and sc.region.heading is Heading.BOTH
    d = sc.to_dict()
    assert type(d["controller"]["fhocp_mode"]) is str and type(d["region"]["heading"]) is str
    assert json.loads(json.dumps(d))["controller"]["terminal_mode"] == "hard"
    path = tmp_path / "s.toml"
    path.write_text(_to_toml(d))
    assert load_scenario(path) == sc


def test_backend_name_is_left_out_by_default_and_round_trips_otherwise(tmp_path):
    assert "fhocp_backend" not in paper_scenario().to_dict()["controller"]
    sc = scenario_from_dict({"controller": {"fhocp_backend": "ipopt"}})
    assert sc.controller.fhocp_backend == "ipopt" and sc.to_dict()["controller"]["fhocp_backend"] == "ipopt"
    path = tmp_path / "s.toml"
    path.write_text(_to_toml(sc.to_dict()))
    assert load_scenario(path) == sc


def test_with_changes_accepts_dotted_nested_fields():
    sc = paper_scenario()
    changed = sc.with_changes(duration=20.0, **{"limits.u_max": 0.3, "controller.fhocp_mode": "converged",
                                                "disturbance.sway.gain": 0.2})
    assert changed.duration == 20.0 and changed.limits.u_max == 0.3 and changed.limits.w_max == sc.limits.w_max
    assert changed.controller.fhocp_mode == "converged" and changed.controller.dt == sc.controller.dt
    assert changed.disturbance.sway.gain == 0.2 and changed.disturbance.period == sc.disturbance.period
    assert sc.limits.u_max == 0.4  # the original is untouched


@pytest.mark.parametrize("changes, match", [
    ({"limits.v_max": 1.0}, r"^limits\.v_max: expected a field of InputLimits"),
    ({"speed": 1.0}, r"^speed: expected a field of Scenario"),
    ({"duration.seconds": 1.0}, r"^duration\.seconds: expected no dotted part"),
    ({"limits.u_max": -0.3}, r"^limits\.u_max: expected a number > 0"),
    ({"controller.fhocp_mode": "fast"}, r"^controller\.fhocp_mode: expected one of \('realtime', 'converged'\)"),
    ({"region.heading": "up"}, r"^region\.heading: expected one of"),
])
def test_with_changes_errors_name_the_field(changes, match):
    with pytest.raises(ConfigError, match=match):
        paper_scenario().with_changes(**changes)


def test_the_repr_holds_plain_floats():
    """Issue 24 item 9: the scenario's repr reads as Python, without ``np.float64(...)``."""
    text = repr(paper_scenario())
    assert "np." not in text and "float64" not in text
    assert "workspace=((-10.0, -10.0, -5.0), (10.0, 10.0, 5.0))" in text


@pytest.mark.parametrize("table, match", [
    ({"duration": "100"}, r"^duration: expected a finite number, received '100'"),
    ({"duration": True}, r"^duration: expected a finite number, received True"),
    ({"name": 5}, r"^name: expected a string, received 5"),
    ({"controller": {"horizon_steps": True}}, r"^controller\.horizon_steps: expected an integer >= 1"),
    ({"controller": {"law": ["paper"]}}, r"^controller\.law: expected one of"),
    ({"initial_state": ["-0.5", 3.0, 0.2, 0.0]}, r"^initial_state: expected 4 numbers"),
    ({"epsilon": "0.1"}, r"^epsilon: expected a finite number"),
])
def test_types_are_strict(table, match):
    """Issue 24 item 2: a string or a bool where a number belongs is refused, naming the field."""
    with pytest.raises(ConfigError, match=match):
        scenario_from_dict(table)


@pytest.mark.parametrize("table, match", [
    # 1e308 s / 0.1 s overflows the period count: refused before any count is made an int
    ({"duration": 1e308}, r"^duration: expected at most 1e\+09 FHOCP periods of 0\.1 s"),
    # a period of 1e-9 s holds no tick of the 100 Hz ancillary law: the period is wrong, not the rate
    ({"controller": {"dt": 1e-9}}, r"^controller\.dt: expected at least one tick 1/ancillary_rate_hz = 0\.01 s"),
    ({"controller": {"dt": 10.0, "ancillary_rate_hz": 1e308}},
     r"^controller\.ancillary_rate_hz: expected at most 1e\+06 ticks per period"),
    ({"controller": {"ancillary_rate_hz": 155.0}}, r"^controller\.ancillary_rate_hz: expected a positive multiple"),
    ({"disturbance": {"constant": [1e200, 0.0, 0.0]}},
     r"^disturbance\.constant: expected a speed of magnitude <= 1e\+06 m/s"),
    ({"disturbance": {"amplitude": [0.0, 1e300, 0.0]}}, r"^disturbance\.amplitude: expected a speed of magnitude"),
])
def test_huge_numbers_name_their_own_field(table, match):
    """Issue 24 items 1 and 3: products that overflow are refused up front, each error naming the right field."""
    with pytest.raises(ConfigError, match=match):
        scenario_from_dict(table)


# ---- limits.rate (issue 22 design (1)) ---------------------------------------------------------------------------

def test_rate_limit_is_off_by_default_and_in_the_dict_only_when_set(tmp_path):
    assert paper_scenario().limits.rate is None and "rate" not in paper_scenario().to_dict()["limits"]
    assert paper_scenario().limits.jump(0.1) is None
    sc = paper_scenario().with_changes(**{"limits.rate": [0.3, 0.2, 1]})
    assert sc.limits.rate == (0.3, 0.2, 1.0) and sc.to_dict()["limits"]["rate"] == [0.3, 0.2, 1.0]
    assert np.allclose(sc.limits.jump(0.1), [0.03, 0.02, 0.1], rtol=1e-15)
    path = tmp_path / "rated.toml"
    path.write_text(_to_toml(sc.to_dict()))
    assert load_scenario(path) == sc


@pytest.mark.parametrize("rate, match", [
    ("0.3", r"limits\.rate: expected three numbers"),
    ([0.3, 0.3], r"limits\.rate: expected three numbers"),
    ([0.3, "0.3", 1.0], r"limits\.rate\[1\]: expected a number > 0"),
    ([0.3, 0.3, 0.0], r"limits\.rate\[2\]: expected a number > 0"),
    ([-1.0, 0.3, 1.0], r"limits\.rate\[0\]: expected a number > 0"),
    ([0.3, math.inf, 1.0], r"limits\.rate\[1\]: expected a finite number"),
    ([True, 0.3, 1.0], r"limits\.rate\[0\]: expected a number > 0"),
])
def test_rate_limit_errors_name_the_field(rate, match):
    with pytest.raises(ConfigError, match=match):
        scenario_from_dict({"limits": {"rate": rate}})


# ---- limits.u_min: a minimum surge ------------------------------------------------------------------------------

def test_a_surge_floor_is_off_by_default_in_the_dict_only_when_set_and_round_trips(tmp_path):
    """The symmetric box keeps its dict (so every design key of a scenario without a floor is unchanged)."""
    assert paper_scenario().limits.u_min is None and "u_min" not in paper_scenario().to_dict()["limits"]
    sc = paper_scenario().with_changes(**{"limits.u_min": 0.1})
    assert sc.limits.u_min == 0.1 and sc.to_dict()["limits"]["u_min"] == 0.1
    path = tmp_path / "floored.toml"
    path.write_text(_to_toml(sc.to_dict()))
    assert load_scenario(path) == sc
    assert scenario_from_dict({"limits": {"u_max": 1.5, "u_min": 0.5}}).limits.lower[0] == 0.5


@pytest.mark.parametrize("table, match", [
    ({"u_min": 0.4}, r"^limits\.u_min: expected a surge in \[0, u_max = 0\.4\) m/s"),   # the paper's u_max is 0.4
    ({"u_min": -0.2}, r"^limits\.u_min"),
    ({"u_min": "fast"}, r"^limits\.u_min"),
    ({"u_min": 1.0, "u_max": 0.8}, r"^limits\.u_min"),
])
def test_surge_floor_errors_name_the_field(table, match):
    with pytest.raises(ConfigError, match=match):
        scenario_from_dict({"limits": table})


@pytest.mark.parametrize("plant, ok", [
    ({}, False),                                                                    # the kinematic plant
    ({"kind": "dynamic", "vehicle": "remus100"}, False),                           # no lateral thrust
    ({"kind": "dynamic", "vehicle": "bluerov2_heavy"}, True),                      # Y_max > 0
])
def test_a_backup_that_commands_sway_needs_a_vehicle_with_lateral_thrust(plant, ok):
    data = {**paper_scenario().to_dict(), "controller": {"backup": "hold"}, "plant": plant}
    if ok:
        assert scenario_from_dict(data).controller.backup == "hold"
    else:
        with pytest.raises(ConfigError, match=r"controller\.backup"):
            scenario_from_dict(data)


@pytest.mark.parametrize("value", [-0.5, math.nan, math.inf])
def test_a_negative_or_non_finite_lookahead_is_refused_by_name(value):
    with pytest.raises(ConfigError, match=r"controller\.lookahead"):
        scenario_from_dict({**paper_scenario().to_dict(), "controller": {"lookahead": value}})


def test_the_lookahead_is_written_only_when_on_and_is_not_a_certificate_input():
    from tubekit.design_inputs import DesignInputs
    base = paper_scenario()
    on = base.with_changes(**{"controller.lookahead": 1.5})
    assert "lookahead" not in base.to_dict()["controller"] and on.to_dict()["controller"]["lookahead"] == 1.5
    assert scenario_from_dict(on.to_dict()) == on
    assert DesignInputs.of(on).key() == DesignInputs.of(base).key()


# ---- limits.initial: the command before t = 0 ------------------------------------------------------------------

def test_an_initial_command_is_off_by_default_in_the_dict_only_when_set_and_round_trips(tmp_path):
    """Without it the run starts at rest (the box's point nearest it) and the dict is unchanged; with it the command
    before t = 0 is the one given, and the scenario round-trips through TOML."""
    base = paper_scenario().with_changes(**{"limits.rate": (0.5, 0.5, 1.0)})
    assert base.limits.initial is None and "initial" not in base.to_dict()["limits"]
    assert list(base.limits.start_command) == [0.0, 0.0, 0.0]
    floored = base.with_changes(**{"limits.u_min": 0.1})
    assert list(floored.limits.start_command) == [0.1, 0.0, 0.0]
    sc = base.with_changes(**{"limits.initial": (0.2, 0.0, -0.1)})
    assert list(sc.limits.start_command) == [0.2, 0.0, -0.1] and sc.to_dict()["limits"]["initial"] == [0.2, 0.0, -0.1]
    path = tmp_path / "under_way.toml"
    path.write_text(_to_toml(sc.to_dict()))
    assert load_scenario(path) == sc


@pytest.mark.parametrize("table, match", [
    ({"initial": [0.2, 0.0, 0.0]}, r"^limits\.initial: expected only with limits\.rate"),
    ({"rate": [0.5, 0.5, 1.0], "initial": [0.5, 0.0, 0.0]}, r"^limits\.initial: expected a command inside the box"),
    ({"rate": [0.5, 0.5, 1.0], "u_min": 0.1, "initial": [0.05, 0.0, 0.0]}, r"^limits\.initial: expected a command"),
    ({"rate": [0.5, 0.5, 1.0], "initial": [0.2, 0.0]}, r"^limits\.initial"),
    ({"rate": [0.5, 0.5, 1.0], "initial": "cruise"}, r"^limits\.initial"),
])
def test_initial_command_errors_name_the_field(table, match):
    with pytest.raises(ConfigError, match=match):
        scenario_from_dict({"limits": table})


# ---- [plant] start: a velocity loop settled before t = 0 ---------------------------------------------------------

def test_a_settled_start_is_written_only_when_set_and_round_trips(tmp_path):
    """``[plant] start = "settled"`` lands in the dict (a trimmed start leaves it as it was) and through TOML."""
    base = paper_scenario().with_changes(**{"limits.rate": (0.5, 0.5, 1.0), "limits.initial": (0.2, 0.0, 0.0),
                                            "plant": PlantSettings("dynamic", "bluerov2_heavy")})
    assert not base.plant.settled and "start" not in base.to_dict()["plant"]
    sc = base.with_changes(**{"plant.start": "settled"})
    assert sc.plant.settled and sc.to_dict()["plant"]["start"] == "settled"
    path = tmp_path / "settled.toml"
    path.write_text(_to_toml(sc.to_dict()))
    assert load_scenario(path) == sc


@pytest.mark.parametrize("table, match", [
    ({"plant": {"kind": "dynamic", "start": "warm"}}, r"^plant\.start: expected one of \('trimmed', 'settled'\)"),
    ({"plant": {"start": "settled"}}, r"^plant\.start: expected 'trimmed' on the kinematic plant"),
    ({"plant": {"kind": "dynamic", "start": "settled"}}, r"^plant\.start: expected 'trimmed' without limits\.rate"),
    ({"plant": {"kind": "dynamic", "start": "settled"},
      "limits": {"rate": [0.5, 0.5, 1.0], "initial": [0.2, 0.0, 0.1]}}, r"^limits\.initial: expected w = r = 0"),
    ({"plant": {"kind": "dynamic", "start": "settled"},
      "limits": {"rate": [0.5, 0.5, 1.0], "initial": [0.2, 0.1, 0.0]}}, r"^limits\.initial: expected w = r = 0"),
])
def test_settled_start_errors_name_the_field(table, match):
    with pytest.raises(ConfigError, match=match):
        scenario_from_dict(table)
