"""Shipped vehicle parameter sets and the scenario's [plant] table: values, validation, CLI exit 2."""

from __future__ import annotations

import pytest

from tubekit import paper_scenario
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, scenario_from_dict
from tubekit.model.vehicles import REMUS100, VEHICLES, PlantSettings, VehicleParams, vehicle_params


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
