"""A vehicle's thruster geometry -> its box of limits (tubekit.model.thrusters), checked by hand and by our own LP.

Every expected value here is derived in the test (by hand or by an independent ``linprog`` feasibility solve),
never read from the module under test.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import tomllib
from hypothesis import assume, given, strategies as st
from scipy.optimize import linprog

from tubekit import paper_scenario
from tubekit.design_inputs import DesignInputs
from tubekit.exceptions import ConfigError
from tubekit.model.thrusters import ThrusterGeometry
from tubekit.model.vehicle_sets import (HEAVY_HORIZONTAL_POSITION, STANDARD_GRAVITY, T200_REVERSE_KGF_16V,
                                        bluerov2_heavy_limits, bluerov2_heavy_sway_limit)
from tubekit.model.vehicles import PlantSettings
from tubekit.scenario import load_scenario, scenario_from_dict

from .test_scenario import _to_toml

ROOT = Path(__file__).resolve().parent.parent
SHRINK = 1e-6          # the documented relative shrink of the box (docs/plant.md); LP round-off on top is ~1e-9
T200 = T200_REVERSE_KGF_16V * STANDARD_GRAVITY     # N, each thruster of the Heavy
C45 = math.cos(math.pi / 4)
X_POS, Y_POS = HEAVY_HORIZONTAL_POSITION
ARM = (X_POS + Y_POS) * math.sin(math.pi / 4)      # m, yaw arm of a 45° thruster


def _heavy_rows() -> tuple[list[list[float]], list[float]]:
    """The Heavy's (X, Z, N) allocation and its sway row: thrusters 1-4 horizontal at (±x, ±y) vectored at 45°
    (heading angle a: force (cos a, sin a), moment x sin a − y cos a), thrusters 5-8 vertical."""
    positions = [(X_POS, Y_POS), (X_POS, -Y_POS), (-X_POS, Y_POS), (-X_POS, -Y_POS)]
    angles = [-math.pi / 4, math.pi / 4, -3 * math.pi / 4, 3 * math.pi / 4]
    surge = [math.cos(a) for a in angles] + [0.0] * 4
    heave = [0.0] * 4 + [1.0] * 4
    yaw = [px * math.sin(a) - py * math.cos(a) for (px, py), a in zip(positions, angles)] + [0.0] * 4
    sway = [math.sin(a) for a in angles] + [0.0] * 4
    return [surge, heave, yaw], sway


def _hand_solo() -> tuple[float, float, float]:
    """Solo capacities of the Heavy by hand: 4 T cos 45°, 4 T, 4 T d (N, N, N m)."""
    return 4 * T200 * C45, 4 * T200, 4 * T200 * ARM


def _producible(allocation, thrust, tau) -> bool:
    """Whether some f with |f_i| <= T_i gives B f = tau: our own feasibility LP (HiGHS), then a float check."""
    b, t = np.asarray(allocation, float), np.asarray(thrust, float)
    res = linprog(np.zeros(b.shape[1]), A_eq=b, b_eq=np.asarray(tau, float), bounds=list(zip(-t, t)),
                  method="highs")
    if res.status != 0:
        return False
    scale = float(np.max(np.abs(b) @ t))
    return bool(np.max(np.abs(b @ res.x - tau)) <= 1e-7 * scale and np.all(np.abs(res.x) <= t * (1 + 1e-9)))


def _corners(limits) -> list[np.ndarray]:
    """The 2^k corners (±X, ±Z, ±N[, ±Y]) of the box of half-widths ``limits``."""
    return [np.array(signs) * np.asarray(limits, float)
            for signs in itertools.product((1.0, -1.0), repeat=len(limits))]


# ---- the BlueROV2 Heavy --------------------------------------------------------------------------------------------

@pytest.mark.parametrize("with_sway", [False, True], ids=["no-sway-row", "sway-row"])
def test_the_heavy_geometry_produces_the_shipped_box(with_sway):
    """The shipped (hand-derived) limits are producible: the LP's box with their proportions contains them, and is
    no larger (the hand allocation f = X/(4c) ± N/(4d) is optimal), with or without requiring zero sway."""
    rows, sway = _heavy_rows()
    hand = bluerov2_heavy_limits(surge_share=0.75, sway_share=0.0)   # the whole horizontal thrust to X and N
    solo_hand = _hand_solo()
    shares = [h / s for h, s in zip(hand, solo_hand)]                 # 0.75, 1, 0.25
    geom = ThrusterGeometry(rows, [T200] * 8, shares, sway if with_sway else None)
    assert geom.solo_capacity() == pytest.approx(solo_hand, rel=1e-9)
    for derived, by_hand in zip(geom.limits(), hand):
        assert derived >= by_hand * (1 - SHRINK) * (1 - 1e-9)
        assert derived <= by_hand * (1 + 1e-9)
    assert all(_producible(rows + ([sway] if with_sway else []), [T200] * 8, list(c) + ([0.0] if with_sway else []))
               for c in _corners(geom.limits()))
    assert geom.sway_limit() == 0.0


def test_a_fourth_share_gives_the_heavy_its_shipped_lateral_limit():
    """With the sway row and a fourth share the box has a lateral half-width: the shipped (X, Z, N, Y) box (65 %
    surge, 10 % sway, 25 % yaw of each horizontal thruster) is producible at every one of its 16 corners, and the
    LP's box is no larger than the hand allocation f = X/(4c) ± Y/(4c) ± N/(4d) gives."""
    rows, sway = _heavy_rows()
    hand = (*bluerov2_heavy_limits(), bluerov2_heavy_sway_limit())
    solo_hand = (*_hand_solo(), 4 * T200 * C45)                      # sway alone: 4 T sin 45°
    geom = ThrusterGeometry(rows, [T200] * 8, [h / s for h, s in zip(hand, solo_hand)], sway)
    assert geom.solo_capacity() == pytest.approx(solo_hand, rel=1e-9)
    derived = (*geom.limits(), geom.sway_limit())
    for d, by_hand in zip(derived, hand):
        assert by_hand * (1 - SHRINK) * (1 - 1e-9) <= d <= by_hand * (1 + 1e-9)
    assert all(_producible(rows + [sway], [T200] * 8, [c[0], c[1], c[2], c[3]]) for c in _corners(derived))
    assert not _producible(rows + [sway], [T200] * 8, [1.01 * x for x in derived])


def test_a_fourth_share_needs_the_sway_row():
    rows, _ = _heavy_rows()
    with pytest.raises(ConfigError, match=r"shares.*only with a sway row"):
        ThrusterGeometry(rows, [T200] * 8, [0.65, 1.0, 0.25, 0.1])


# ---- small geometries by hand ----------------------------------------------------------------------------------------

def test_a_single_surge_thruster():
    geom = ThrusterGeometry([[1.0], [0.0], [0.0]], [10.0], [1.0, 0.0, 0.0])
    assert geom.solo_capacity() == pytest.approx((10.0, 0.0, 0.0), abs=1e-9)
    assert geom.limits() == pytest.approx((10.0, 0.0, 0.0), rel=2 * SHRINK)
    assert geom.limits()[0] <= 10.0 and geom.limits()[1:] == (0.0, 0.0)
    with pytest.raises(ConfigError, match=r"plant\.vehicle\.thrusters\.allocation: expected .*heave Z.*no authority"):
        ThrusterGeometry([[1.0], [0.0], [0.0]], [10.0], [1.0, 1.0, 0.0])


def test_a_differential_drive():
    """X = f1 + f2, N = 0.5 (f1 − f2), |f_i| <= 10: solo X = 20, solo N = 0.5·(10 + 10) = 10; the corner
    (20 t, 0, 10 t) needs f1 = X/2 + N = 10 t + 10 t = 20 t <= 10, so t* = 0.5: (10, 0, 5)."""
    geom = ThrusterGeometry([[1.0, 1.0], [0.0, 0.0], [0.5, -0.5]], [10.0, 10.0], [1.0, 0.0, 1.0])
    assert geom.solo_capacity() == pytest.approx((20.0, 0.0, 10.0), abs=1e-9)
    x, z, n = geom.limits()
    assert (x, z, n) == pytest.approx((10.0, 0.0, 5.0), rel=2 * SHRINK) and x <= 10.0 and n <= 5.0 and z == 0.0
    assert ThrusterGeometry.from_dict(geom.to_dict()) == geom and hash(ThrusterGeometry.from_dict(geom.to_dict())) \
        == hash(geom)


# ---- validation ------------------------------------------------------------------------------------------------------

ONE = {"allocation": [[1.0], [0.0], [0.0]], "thrust": [10.0], "shares": [1.0, 0.0, 0.0]}
TWO = {"allocation": [[1.0, 1.0], [0.0, 0.0], [0.5, -0.5]], "thrust": [10.0, 10.0], "shares": [1.0, 0.0, 1.0]}
BAD_TABLES = [
    ({**TWO, "allocation": [[1.0, 1.0], [0.0, 0.0]]}, r"thrusters\.allocation: expected a 3 x n matrix"),
    ({**TWO, "allocation": [[1.0, 1.0], [0.0], [0.5, -0.5]]}, r"thrusters\.allocation\[1\]: expected 2 numbers"),
    ({**TWO, "allocation": [[], [], []]}, r"thrusters\.allocation\[0\]: expected a list of 1 to"),
    ({**TWO, "allocation": "B"}, r"thrusters\.allocation: expected a 3 x n matrix"),
    ({**TWO, "allocation": [[1.0, "x"], [0.0, 0.0], [0.5, -0.5]]}, r"thrusters\.allocation\[0\]\[1\]: expected a fin"),
    ({**TWO, "allocation": [[1.0, 1.0], [0.0, True], [0.5, -0.5]]}, r"thrusters\.allocation\[1\]\[1\]"),
    ({**TWO, "allocation": [[1.0, 1.0], [0.0, 0.0], [0.5, math.nan]]}, r"thrusters\.allocation\[2\]\[1\]"),
    ({**TWO, "thrust": [10.0]}, r"thrusters\.thrust: expected 2 numbers \(one per thruster"),
    ({**TWO, "thrust": [10.0, 10.0, 10.0]}, r"thrusters\.thrust: expected 2 numbers"),
    ({**TWO, "thrust": [10.0, 0.0]}, r"thrusters\.thrust\[1\]: expected a finite number of newtons in \(0,"),
    ({**TWO, "thrust": [-1.0, 10.0]}, r"thrusters\.thrust\[0\]"),
    ({**TWO, "thrust": [10.0, math.inf]}, r"thrusters\.thrust\[1\]"),
    ({**TWO, "thrust": [False, 10.0]}, r"thrusters\.thrust\[0\]"),
    ({**TWO, "thrust": 10.0}, r"thrusters\.thrust: expected"),
    ({**TWO, "shares": [1.0, -0.5, 1.0]}, r"thrusters\.shares\[1\]: expected a finite number in \[0,"),
    ({**TWO, "shares": [0.0, 0.0, 0.0]}, r"thrusters\.shares: expected 3 numbers >= 0, not all 0"),
    ({**TWO, "shares": [1.0, 1.0]}, r"thrusters\.shares: expected 3 numbers"),
    ({**TWO, "sway": [1.0]}, r"thrusters\.sway: expected 2 numbers"),
    ({**TWO, "shares": [1.0, 1.0, 1.0]}, r"thrusters\.allocation: expected .*heave Z.*no authority"),
    ({**ONE, "sway": [1.0]}, r"thrusters\.allocation: expected .*surge X.* and sway: no authority"),
    ({**TWO, "colour": 1}, r"thrusters\.colour: expected one of the keys"),
    ({"thrust": [10.0]}, r"thrusters\.allocation: expected present"),
    ([1, 2], r"plant\.vehicle\.thrusters: expected a table"),
]


@pytest.mark.parametrize("table, match", BAD_TABLES)
def test_a_bad_thruster_table_names_its_field(table, match):
    with pytest.raises(ConfigError, match=match):
        ThrusterGeometry.from_dict(table)


HEAVY_TABLE = {"allocation": _heavy_rows()[0], "thrust": [T200] * 8, "shares": [0.75, 1.0, 0.25]}
BAD_PLANTS = [
    ({"name": "bluerov2_heavy", "X_max": 80.0, "thrusters": HEAVY_TABLE},
     r"plant\.vehicle\.thrusters: expected absent when X_max/Z_max/N_max/Y_max are given \(one source of limits"),
    ({"name": "bluerov2_heavy", "N_max": [5.0, 6.0], "thrusters": {"allocation": 3}},   # refused before it is parsed
     r"plant\.vehicle\.thrusters: expected absent when X_max/Z_max/N_max"),
    ({"name": "remus100", "thrusters": HEAVY_TABLE}, r"plant\.vehicle\.thrusters: expected absent on a finned vehicle"),
    ({"name": "bluerov2_heavy", "thrusters": {**HEAVY_TABLE, "shares": [1.0, 0.0, 1.0]}},
     r"plant\.vehicle\.thrusters\.shares: expected 3 numbers > 0"),
    ({"name": "bluerov2_heavy", "thrusters": {**HEAVY_TABLE, "thrust": [T200] * 7}}, r"thrusters\.thrust: expected 8"),
    ({"name": "bluerov2_heavy", "thrusters": 3.0}, r"plant\.vehicle\.thrusters: expected a table"),
]


@pytest.mark.parametrize("vehicle, match", BAD_PLANTS)
def test_a_thruster_table_the_vehicle_cannot_use_is_refused_by_name(vehicle, match):
    with pytest.raises(ConfigError, match=match):
        PlantSettings.from_dict({"kind": "dynamic", "vehicle": vehicle})


# ---- the property ----------------------------------------------------------------------------------------------------

@st.composite
def _geometries(draw):
    n = draw(st.integers(3, 8))
    entry = st.floats(-1.0, 1.0, allow_nan=False)
    rows = [draw(st.lists(entry, min_size=n, max_size=n)) for _ in range(3)]
    thrust = draw(st.lists(st.floats(1.0, 20.0), min_size=n, max_size=n))
    shares = draw(st.lists(st.floats(0.05, 1.0), min_size=3, max_size=3))
    return rows, thrust, shares


@given(_geometries())
def test_every_corner_of_the_derived_box_is_producible_and_the_box_is_maximal(geometry):
    """Property: for any allocation (3 × n, n in 3..8, entries in [-1, 1]) able to produce every channel and any
    thrusts in [1, 20] N, every corner of the derived box is producible (our own feasibility LP per corner), the box
    has the requested proportions, and 1.001 times it is not producible (some corner is out of reach)."""
    rows, thrust, shares = geometry
    assume(np.linalg.svd(np.array(rows), compute_uv=False)[-1] > 1e-2)   # full row rank: every channel producible
    limits = np.array(ThrusterGeometry(rows, thrust, shares).limits())
    assert np.all(limits > 0.0)
    assert all(_producible(rows, thrust, c) for c in _corners(limits))
    assert not all(_producible(rows, thrust, 1.001 * c) for c in _corners(limits))
    solo = [-linprog(-np.eye(len(thrust) + 1)[-1], A_eq=np.hstack([np.array(rows), -np.eye(3)[:, [c]]]),
                     b_eq=np.zeros(3), bounds=[(-t, t) for t in thrust] + [(0, None)], method="highs").fun
            for c in range(3)]
    ratio = limits / (np.array(shares) * np.array(solo))                # one t for the three channels
    assert ratio == pytest.approx(np.full(3, ratio[0]), rel=1e-6)


# ---- in a scenario ---------------------------------------------------------------------------------------------------

def _heavy_scenario(thrust: list[float]):
    table = {**HEAVY_TABLE, "thrust": thrust, "sway": _heavy_rows()[1]}
    base = paper_scenario().to_dict()
    return scenario_from_dict({**base, "plant": {"kind": "dynamic", "vehicle": {"name": "bluerov2_heavy",
                                                                               "thrusters": table}}})


def test_a_dynamic_scenario_with_thrusters_loads_round_trips_and_keys_its_design(tmp_path):
    sc = _heavy_scenario([T200] * 8)
    x, z, n = sc.plant.thrusters.limits()
    box = sc.plant.params
    assert (box.X_max, box.Z_max, box.N_max) == (x, z, n) and box.actuation == "thrusters"
    assert sc.plant.truth_params.thrust_limits == (x, z, n)
    assert (x, z, n) == pytest.approx(bluerov2_heavy_limits(surge_share=0.75, sway_share=0.0), rel=2 * SHRINK)
    assert box.Y_max == 0.0 and not box.lateral            # a table with three shares leaves no lateral thrust
    d = sc.to_dict()
    assert set(d["plant"]["vehicle"]) == {"name", "thrusters"}           # the table, not the derived limits
    assert scenario_from_dict(d) == sc
    path = tmp_path / "heavy.toml"
    path.write_text(_to_toml(d))
    assert "[plant.vehicle.thrusters]" in path.read_text() and load_scenario(path) == sc
    assert replace(sc.plant, truth=()).thrusters == sc.plant.thrusters     # dataclasses.replace keeps the table
    weaker = _heavy_scenario([T200] * 7 + [0.9 * T200])
    assert weaker.plant.params.Z_max < z
    assert DesignInputs.of(weaker).key() != DesignInputs.of(sc).key()
    assert DesignInputs.of(_heavy_scenario([T200] * 8)).key() == DesignInputs.of(sc).key()
    assert DesignInputs.of(weaker).first_difference(DesignInputs.of(sc))[0] == "plant.vehicle.thrusters.thrust"


def test_a_vehicle_file_and_a_custom_vehicle_may_give_thrusters(tmp_path):
    """In a vehicle file the table is [thrusters]; a custom vehicle then needs no X_max, Z_max, N_max."""
    shipped = PlantSettings("dynamic", "bluerov2_heavy").params.to_dict()
    lines = [f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"' for k, v in shipped.items()
             if k not in ("X_max", "Z_max", "N_max", "Y_max")]
    table = "\n".join(f"{k} = {v!r}" for k, v in HEAVY_TABLE.items())
    (tmp_path / "rov.toml").write_text("\n".join(lines) + "\n\n[thrusters]\n" + table + "\n")
    plant = PlantSettings.from_dict({"kind": "dynamic", "vehicle_file": str(tmp_path / "rov.toml")})
    assert plant.vehicle == "custom" and plant.thrusters == ThrusterGeometry.from_dict(HEAVY_TABLE)
    assert plant.params.X_max == plant.thrusters.limits()[0]
    assert PlantSettings.from_dict(plant.to_dict()) == plant


def test_the_documented_heavy_example_gives_the_shipped_limits():
    """docs/plant.md's TOML example of the Heavy's geometry (rounded entries) gives the shipped box to 0.01 %."""
    text = (ROOT / "docs" / "plant.md").read_text()
    block = next(b for b in re.findall(r"```toml\n(.*?)```", text, flags=re.S)
                 if re.search(r"^\[plant\.vehicle\.thrusters\]", b, flags=re.M))     # the table itself, not a comment
    plant = PlantSettings.from_dict(tomllib.loads(block)["plant"])
    assert plant.params.thrust_limit_floor(1.0) == pytest.approx(bluerov2_heavy_limits(), rel=1e-4)
    assert plant.params.Y_max == pytest.approx(bluerov2_heavy_sway_limit(), rel=1e-4) and plant.params.lateral
