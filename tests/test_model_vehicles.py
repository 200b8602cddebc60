"""Shipped vehicle parameter sets and the scenario's [plant] table: values, validation, CLI exit 2."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit import paper_scenario
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario, scenario_from_dict
from tubekit.model.vehicles import REMUS100, VEHICLES, PlantSettings, VehicleParams, vehicle_params


def _mass_matrix(p: VehicleParams) -> np.ndarray:
    m11, m22, m33, m44, m24, m42 = p.mass_entries
    return np.array([[m11, 0, 0, 0], [0, m22, 0, m24], [0, 0, m33, 0], [0, m42, 0, m44]])


def test_remus100_is_prestero_reduced_to_4dof():
    p = VEHICLES["remus100"]
    assert p.m == pytest.approx(299.0 / 9.81, abs=0.01)
    m = _mass_matrix(p)
    np.testing.assert_allclose(np.diag(m), [31.41, 65.98, 65.98, 8.33])
    assert np.all(np.linalg.eigvalsh(m) > 0) and np.allclose(m, m.T)
    # lift-only parts + added-mass parts give Prestero's totals back
    assert p.Y_ur_lift + p.X_udot == pytest.approx(5.22)
    assert p.N_uv_lift + (p.Y_vdot - p.X_udot) == pytest.approx(-24.0)
    assert p.N_ur_lift + p.Y_rdot == pytest.approx(-2.00)


@pytest.mark.parametrize("overrides, field", [
    ({"m": -30.0}, "plant.vehicle.m"),
    ({"I_zz": 0.0}, "plant.vehicle.I_zz"),
    ({"N_rdot": 10.0}, "plant.vehicle.M"),          # I_zz - N_rdot < 0: M not positive definite
    ({"Y_vdot": 40.0}, "plant.vehicle.M"),
    ({"N_vdot": 0.5}, "plant.vehicle.N_vdot"),      # M not symmetric
    ({"Y_vv": 10.0}, "plant.vehicle.Y_vv"),         # damping that adds energy
    ({"X_max": 0.0}, "plant.vehicle.X_max"),
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
    assert sc.plant.dynamic and sc.plant.params == REMUS100
    sc = scenario_from_dict({**base, "plant": {"kind": "dynamic", "vehicle": {"name": "remus100", "X_max": 20.0},
                                               "tracking_bound": [0.1, 0.1, 0.2]}})
    assert sc.plant.params.X_max == 20.0 and sc.plant.tracking_bound == (0.1, 0.1, 0.2)
    assert scenario_from_dict(sc.to_dict()) == sc
    for bad, field in (({"kind": "hovercraft"}, "plant.kind"), ({"vehicle": "nautilus"}, "plant.vehicle"),
                       ({"colour": 1}, "plant.colour"), ({"tracking_bound": [0.1]}, "plant.tracking_bound"),
                       ({"vehicle": {"m": -1.0}}, "plant.vehicle.m")):
        with pytest.raises(ConfigError) as err:
            scenario_from_dict({**base, "plant": bad})
        assert err.value.field == field
    assert PlantSettings.from_dict({}).kind == "kinematic"


def test_simulate_exits_2_naming_the_vehicle_field(tmp_path, capsys):
    from tubekit.app.cli import main
    path = tmp_path / "bad.toml"
    path.write_text('duration = 0.2\n[plant]\nkind = "dynamic"\n[plant.vehicle]\nm = -1.0\n')
    with pytest.raises(ConfigError):
        load_scenario(path)
    assert main(["simulate", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "plant.vehicle.m" in capsys.readouterr().err
