"""Shipped vehicle parameter sets and the scenario's [plant] table: values, validation, CLI exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from tubekit import paper_scenario
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, scenario_from_dict
from tubekit.model.vehicles import CUSTOM, REMUS100, VEHICLES, PlantSettings, VehicleParams, vehicle_params


def test_the_module_re_exports_the_shipped_sets():
    assert VEHICLES["remus100"] is REMUS100 and REMUS100 == VehicleParams()
    assert vehicle_params("bluerov2_heavy").actuation == "thrusters"


@pytest.mark.parametrize("overrides, field", [
    ({"m": -30.0}, "plant.vehicle.m"),
    ({"I_zz": 0.0}, "plant.vehicle.I_zz"),
    ({"N_rdot": 10.0}, "plant.vehicle.M"),          # I_zz - N_rdot < 0: M not positive definite
    ({"Y_vdot": 40.0}, "plant.vehicle.M"),
    ({"N_vdot": 0.5}, "plant.vehicle.N_vdot"),      # M not symmetric
    ({"Y_vv": 10.0}, "plant.vehicle.Y_vv"),         # damping that adds energy
    ({"X_max": 0.0}, "plant.vehicle.X_max"),
    ({"Y_vv": [-100.0, 10.0]}, "plant.vehicle.Y_vv"),  # an interval reaching positive damping
    ({"Y_vv": [-100.0, -200.0]}, "plant.vehicle.Y_vv"),  # lo > hi
    ({"mass": 30.0}, "plant.vehicle.mass"),         # unknown key
    ({"m": "heavy"}, "plant.vehicle.m"),
])
def test_bad_vehicle_parameter_names_the_field(overrides, field):
    with pytest.raises(ConfigError) as err:
        vehicle_params("remus100", overrides)
    assert err.value.field == field


def test_plant_table_parsing_and_round_trip():
    base = paper_scenario().to_dict()
    assert "plant" not in base and paper_scenario().plant.kind == "kinematic"
    sc = scenario_from_dict({**base, "plant": {"kind": "dynamic", "vehicle": "remus100"}})
    assert sc.plant.dynamic and sc.plant.params == REMUS100 and sc.plant.truth_params == REMUS100.nominal
    sc = scenario_from_dict({**base, "plant": {"kind": "dynamic", "vehicle": {"name": "remus100", "X_max": 20.0}}})
    assert sc.plant.params.X_max == 20.0
    assert scenario_from_dict(sc.to_dict()) == sc
    for bad, field in (({"kind": "hovercraft"}, "plant.kind"), ({"vehicle": "nautilus"}, "plant.vehicle"),
                       ({"colour": 1}, "plant.colour"), ({"tracking_bound": [0.1, 0.1, 0.2]}, "plant.tracking_bound"),
                       ({"vehicle": {"m": -1.0}}, "plant.vehicle.m")):
        with pytest.raises(ConfigError) as err:
            scenario_from_dict({**base, "plant": bad})
        assert err.value.field == field
    assert PlantSettings.from_dict({}).kind == "kinematic"


def test_truth_is_a_point_of_the_box_and_round_trips_through_toml_and_json(tmp_path):
    import json
    toml = tmp_path / "truth.toml"
    toml.write_text('duration = 1.0\n[plant]\nkind = "dynamic"\n[plant.vehicle]\nname = "bluerov2_heavy"\n'
                    'X_uu = [-150.0, -30.0]\n[plant.truth]\nX_uu = -140.0\nY_vv = -210.0\n')
    sc = load_scenario(toml)
    assert sc.plant.params.interval("X_uu") == (-150.0, -30.0)
    truth = sc.plant.truth_params
    assert truth.is_point and truth.X_uu == -140.0 and truth.Y_vv == -210.0
    assert truth.Z_ww == pytest.approx(0.5 * (-190.0 - 74.23))  # the others: midpoints
    d = json.loads(json.dumps(sc.to_dict()))
    assert d["plant"]["vehicle"]["X_uu"] == [-150.0, -30.0] and d["plant"]["truth"] == {"X_uu": -140.0,
                                                                                         "Y_vv": -210.0}
    assert scenario_from_dict(d) == sc
    assert "truth" not in PlantSettings("dynamic").to_dict()  # written only when set


@pytest.mark.parametrize("truth, field", [
    ({"X_uu": -200.0}, "plant.truth.X_uu"),        # outside [-150, -30]
    ({"m": 13.5}, "plant.truth.m"),                # a point field has no truth to choose
    ({"X_uu": "fast"}, "plant.truth.X_uu"),
    ({"colour": 1.0}, "plant.truth.colour"),
])
def test_bad_truth_names_the_field(truth, field):
    base = paper_scenario().to_dict()
    plant = {"kind": "dynamic", "vehicle": {"name": "bluerov2_heavy", "X_uu": [-150.0, -30.0]}, "truth": truth}
    with pytest.raises(ConfigError) as err:
        scenario_from_dict({**base, "plant": plant})
    assert err.value.field == field
    with pytest.raises(ConfigError) as err:
        scenario_from_dict({**base, "plant": {"kind": "dynamic", "truth": 3.0}})
    assert err.value.field == "plant.truth"


def test_simulate_exits_2_naming_the_vehicle_field(tmp_path, capsys):
    from tubekit.app.cli import main
    path = tmp_path / "bad.toml"
    path.write_text('duration = 0.2\n[plant]\nkind = "dynamic"\n[plant.vehicle]\nm = -1.0\n')
    with pytest.raises(ConfigError):
        load_scenario(path)
    assert main(["simulate", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "plant.vehicle.m" in capsys.readouterr().err


# ---- your own vehicle: a complete table, or a vehicle file ---------------------------------------------------------

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _toml_value(value) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(repr(float(x)) for x in value) + "]"
    return repr(float(value))


def _with_vehicle_file(tmp_path: Path, vehicle: dict) -> Path:
    """examples/bluerov2_slow.toml with its [plant.vehicle] table replaced by ``vehicle_file = "myrov.toml"``."""
    (tmp_path / "myrov.toml").write_text("".join(f"{k} = {_toml_value(v)}\n" for k, v in vehicle.items()))
    head, rest = (EXAMPLES / "bluerov2_slow.toml").read_text().split("[plant.vehicle]", 1)
    tail = rest[rest.index("\n["):] if "\n[" in rest else ""     # the tables after it, if any
    path = tmp_path / "scenario.toml"
    path.write_text(head.replace('kind = "dynamic"\n', 'kind = "dynamic"\nvehicle_file = "myrov.toml"\n') + tail)
    return path


def test_a_vehicle_file_with_every_parameter_is_the_vehicle(tmp_path):
    """Issue 32: a vehicle of your own, every parameter in a file beside the scenario (no shipped set): the same
    coefficient box as the shipped scenario's inline table, and it survives the scenario's round trip."""
    shipped = load_scenario(EXAMPLES / "bluerov2_slow.toml")
    sc = load_scenario(_with_vehicle_file(tmp_path, shipped.plant.params.to_dict()))
    assert sc.plant.vehicle == CUSTOM and sc.plant.params == shipped.plant.params
    assert scenario_from_dict(sc.to_dict()).plant == sc.plant


def test_a_vehicle_file_may_start_from_a_shipped_set(tmp_path):
    file = tmp_path / "v.toml"
    file.write_text('name = "bluerov2_heavy"\nX_uu = [-150.0, -30.0]\n')
    plant = PlantSettings.from_dict({"kind": "dynamic", "vehicle_file": str(file)})
    assert plant.vehicle == "bluerov2_heavy" and plant.params.X_uu == (-150.0, -30.0)


@pytest.mark.parametrize("plant, field", [
    ({"vehicle_file": "/nonexistent/myrov.toml"}, "plant.vehicle_file"),
    ({"vehicle_file": 3}, "plant.vehicle_file"),
    ({"vehicle_file": "x.toml", "vehicle": "remus100"}, "plant.vehicle_file"),
    ({"vehicle": {"name": "custom", "m": 11.5}}, r"plant\.vehicle\.I_zz: expected every parameter of a 'custom'"),
    ({"vehicle": "myrov"}, r"plant\.vehicle: expected one of \['bluerov2_heavy', 'remus100'\] or 'custom'"),
    ({"vehicle": {"name": "custom", "mass": 11.5}}, r"plant\.vehicle\.mass: expected one of the keys"),
])
def test_your_own_vehicle_errors_name_the_field(plant, field):
    with pytest.raises(ConfigError, match=field):
        PlantSettings.from_dict({"kind": "dynamic", **plant})


def test_thrusters_live_in_the_vehicle_table_and_replace_its_limits():
    """[plant.vehicle.thrusters] is part of the vehicle table (``overrides``): PlantSettings takes it there (a table or
    a ThrusterGeometry), exposes it as ``thrusters``, derives X_max/Z_max/N_max from it and writes back the table."""
    from tubekit.model.thrusters import ThrusterGeometry
    # one surge thruster of 30 N, a heave pair of 20 N each, a yaw pair at ±0.25 m of 8 N each: the channels are
    # independent, so the box is the solo capacities 30 N, 40 N, 2 * 8 * 0.25 = 4 N m
    table = {"allocation": [[1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.25, -0.25]],
             "thrust": [30.0, 20.0, 20.0, 8.0, 8.0]}
    a = PlantSettings("dynamic", "bluerov2_heavy", overrides={"thrusters": table, "m": 12.0})
    b = PlantSettings("dynamic", "bluerov2_heavy", overrides={"m": 12.0, "thrusters": ThrusterGeometry.from_dict(table)})
    assert a == b and hash(a) == hash(b) and a.thrusters == ThrusterGeometry.from_dict(table)
    assert (a.params.X_max, a.params.Z_max, a.params.N_max) == pytest.approx((30.0, 40.0, 4.0), rel=2e-6)
    assert a.params.X_max <= 30.0 and a.params.Z_max <= 40.0 and a.params.N_max <= 4.0 and a.params.m == 12.0
    vehicle = a.to_dict()["vehicle"]
    assert vehicle["thrusters"]["thrust"] == table["thrust"] and "X_max" not in vehicle
    assert PlantSettings.from_dict(a.to_dict()) == a
    assert PlantSettings("dynamic", "bluerov2_heavy").thrusters is None
    assert PlantSettings("dynamic", "bluerov2_heavy").to_dict() == {"kind": "dynamic",
                                                                   "vehicle": {"name": "bluerov2_heavy"}}


def test_a_plant_shrunk_to_a_share_of_the_published_box_keeps_its_other_overrides():
    """PlantSettings.shrunk(0.5): each interval coefficient of the bundled BlueROV2 box is its midpoint ± half its
    half-width (worked out here from the published intervals), the loop's bandwidth override stays, and a share
    outside [0, 1] names its field."""
    plant = PlantSettings(kind="dynamic", vehicle="bluerov2_heavy",
                          overrides=(("loop_bandwidth", 20.0), ("X_uu", (-100.0, -90.0))))
    half = plant.shrunk(0.5)
    published = vehicle_params("bluerov2_heavy")
    assert dict(half.overrides)["loop_bandwidth"] == 20.0
    for name in published.interval_fields:
        lo, hi = published.interval(name)
        mid, quarter = (lo + hi) / 2, (hi - lo) / 4
        assert half.params.interval(name) == pytest.approx((mid - quarter, mid + quarter), rel=1e-12), name
    assert plant.shrunk(0.0).params.is_point
    assert plant.shrunk(1.0).params.interval("X_uu") == pytest.approx((-141.0, -34.96), rel=1e-12)
    with pytest.raises(ConfigError, match="fraction"):
        plant.shrunk(1.5)
