"""The 4-DOF dynamic plant: energy, published terminal speeds, sway sign, fast-loop limit, sway bound,
truth against the controller's nominal model, fins' speed-dependent saturation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tubekit import paper_scenario
from tubekit.plant.factory import make_plant
from tubekit.plant.dynamic import DynamicPlant, body_acceleration, body_forces, kinetic_energy
from tubekit.exceptions import ConfigError, ShapeError
from tubekit.model.kinematics import SwayModel
from tubekit.plant.kinematic import Plant
from tubekit.scenario import Disturbance
from tubekit.model.vehicles import BLUEROV2_HEAVY, REMUS100, PlantSettings
from verify.theorem.design import hull_sway_bound

CALM = Disturbance(amplitude=(0.0, 0.0, 0.0), sway=SwayModel(gain=0.0, amplitude=0.0, bound=0.0))
REMUS = REMUS100.nominal  # a point of the box: the default truth


def _open_loop(nu0, tau, h: float, steps: int, p=REMUS) -> np.ndarray:
    """RK4 of M ν̇ = τ − n(ν) with τ = (X, Z, N) held; returns ν at every step (steps + 1, 4)."""
    def f(nu):
        return np.array(body_acceleration(p, tuple(nu), tau))
    out = [np.asarray(nu0, dtype=float)]
    nu = out[0]
    for _ in range(steps):
        k1 = f(nu)
        k2 = f(nu + 0.5 * h * k1)
        k3 = f(nu + 0.5 * h * k2)
        k4 = f(nu + h * k3)
        nu = nu + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        out.append(nu)
    return np.array(out)


def test_coriolis_is_skew_symmetric_so_only_damping_changes_energy():
    p = REMUS.with_overrides({name: 0.0 for name in ("X_uu", "Y_vv", "Y_rr", "Z_ww", "N_vv", "N_rr", "Y_uv",
                                                        "Y_ur_lift", "Z_uw", "N_uv_lift", "N_ur_lift")})
    rng = np.random.default_rng(1)
    for _ in range(50):
        nu = rng.uniform(-1, 1, 4)
        assert abs(float(np.dot(nu, body_forces(p, nu)))) < 1e-12  # νᵀ C(ν) ν = 0


@pytest.mark.parametrize("nu0", [(0.5, 0.1, 0.2, 0.3), (0.3, -0.2, -0.1, -0.5), (1.0, 0.0, 0.0, 0.4)])
def test_no_thrust_no_current_kinetic_energy_does_not_increase(nu0):
    traj = _open_loop(nu0, (0.0, 0.0, 0.0), 0.01, 3000)
    energy = np.array([kinetic_energy(REMUS, nu) for nu in traj])
    assert np.all(traj[:, 0] >= 0.0)  # forward motion: the lift terms dissipate (docs/plant.md)
    assert np.all(np.diff(energy) <= 1e-12 * energy[0])
    assert energy[-1] < 0.5 * energy[0]


@pytest.mark.parametrize("thrust", [0.5, 2.0])
def test_constant_surge_thrust_reaches_the_speed_where_drag_balances_it(thrust):
    traj = _open_loop((0.0, 0.0, 0.0, 0.0), (thrust, 0.0, 0.0), 0.05, 8000)
    terminal = math.sqrt(thrust / -REMUS.X_uu)  # X = -X_u|u| u |u| (X_u = 0)
    assert traj[-1, 0] == pytest.approx(terminal, rel=1e-6)
    assert np.all(np.abs(traj[:, 1:]) < 1e-12)


@pytest.mark.parametrize("moment", [1.0, -1.0])
def test_steady_turn_sway_has_the_sign_the_hull_coefficients_predict(moment):
    traj = _open_loop((0.5, 0.0, 0.0, 0.0), (1.0, 0.0, moment), 0.02, 10000)
    u, v, _, r = traj[-1]
    assert np.max(np.abs(traj[-1] - traj[-100])) < 1e-6  # steady
    m11 = REMUS.mass_entries[0]
    predicted = math.copysign(1.0, (REMUS.Y_ur_lift - m11) * u * r)  # the centripetal + fin-lift force
    assert math.copysign(1.0, v) == predicted and abs(v) > 1e-3


def _scenario(vehicle: str = "remus100", truth=(), **overrides):
    plant = PlantSettings("dynamic", vehicle=vehicle, overrides=overrides, truth=truth)
    return paper_scenario().with_changes(disturbance=CALM, plant=plant)


def _commands(n: int) -> list[tuple[float, float, float]]:
    t = np.arange(n) * 0.01
    return [(0.25 + 0.1 * math.sin(0.5 * ti), 0.1 * math.cos(0.3 * ti), 0.3 * math.sin(0.4 * ti)) for ti in t]


def _run(plant, commands, substeps: int) -> np.ndarray:
    x, out = (0.0, 0.0, 0.0, 0.0), []
    for i, v in enumerate(commands):
        x = plant.step_tuple(0.01 * i, x, v, 0.01 / substeps, substeps)
        out.append(x)
    return np.array(out)


def test_fast_low_level_loop_tends_to_the_kinematic_plant():
    commands = _commands(500)
    kinematic = _run(Plant(CALM), commands, 2)
    stiff_hull = {"Y_v": -1.0e5, "X_max": 1e5, "Z_max": 1e5, "N_max": 1e5,  # no sway: the kinematic eq. 11
                  "actuation": "thrusters", "Z_uuds": 0.0, "N_uudr": 0.0, "fin_max": 0.0}
    gaps = []
    for bandwidth, lag in ((5.0, 0.1), (50.0, 0.01), (500.0, 0.001)):
        plant = DynamicPlant(_scenario(loop_bandwidth=bandwidth, thruster_time_constant=lag, **stiff_hull))
        gaps.append(float(np.max(np.abs(_run(plant, commands, 40) - kinematic))))
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 1e-3


@pytest.mark.parametrize("truth", [(), {"X_uu": -141.0, "Y_vv": -217.0, "N_rr": -0.43, "X_udot": -2.6}])
def test_velocity_loop_removes_steady_error_whatever_the_truth_in_the_box(truth):
    sc = _scenario("bluerov2_heavy", truth=truth)
    plant = DynamicPlant(sc)
    assert plant.model == sc.plant.params.nominal and plant.params == sc.plant.truth_params
    _run(plant, [(0.3, 0.1, 0.2)] * 1000, 2)
    body, thrust = plant.history()
    np.testing.assert_allclose(body[-1, [0, 2, 3]], [0.3, 0.1, 0.2], atol=1e-4)  # the integral absorbs d
    assert np.all(np.abs(thrust) <= np.array(plant.params.thrust_limits) + 1e-12)


def test_remus_fins_saturate_at_low_speed_so_the_yaw_command_is_not_reached():
    """At u = 0.3 m/s the rudder gives |N_uudr| u² δ_max ≈ 0.14 N m; r = 0.2 rad/s needs
    |N_r|r|| r² ≈ 61 · 0.04 ≈ 2.5 N m (nominal): the yaw channel saturates and r falls short."""
    plant = DynamicPlant(_scenario())
    _run(plant, [(0.3, 0.0, 0.2)] * 1000, 2)
    body, thrust = plant.history()
    truth = plant.params
    limits = np.array([truth.thrust_limits_at(u) for u in body[:, 0]])
    assert np.all(np.abs(thrust) <= limits * (1 + 1e-3) + 1e-9)  # lagged by T_thr while u (and the limit) drift
    assert body[-1, 0] == pytest.approx(0.3, abs=1e-3) and body[-1, 3] < 0.1
    n_max_hand = 0.5 * (6.15 + 2.75) * 0.3 ** 2 * 0.349
    assert np.max(np.abs(thrust[-100:, 2])) == pytest.approx(n_max_hand, rel=1e-2)


def test_params_argument_must_be_a_point():
    with pytest.raises(ValueError, match="point vehicle"):
        DynamicPlant(_scenario(), params=REMUS100)
    plant = DynamicPlant(_scenario(), params=REMUS100.interval("m") and REMUS100.sample(np.random.default_rng(0)))
    assert plant.params.is_point and plant.model == REMUS100.nominal


def _terminal_speed(x_u: float, x_uu: float, thrust: float) -> float:
    """Positive root of |X_uu| u² + |X_u| u = X (by hand: the quadratic formula)."""
    a, b = abs(x_uu), abs(x_u)
    return (-b + math.sqrt(b * b + 4 * a * thrust)) / (2 * a)


@pytest.mark.parametrize("source", ["prestero", "fossen"])
def test_remus_reaches_its_published_top_speed_at_full_thrust(source):
    """Published: REMUS 100's top speed 2.5 m/s (Fossen's remus100.m, after Allen et al. 2000). Each source's
    (drag, full thrust) pair, integrated open loop, reaches it within 3 %."""
    lo = source == "prestero"
    x_uu = REMUS100.interval("X_uu")[1 if lo else 0]
    x_max = REMUS100.interval("X_max")[0 if lo else 1]
    p = REMUS.with_overrides({"X_uu": x_uu, "X_max": x_max})
    traj = _open_loop((0.0, 0.0, 0.0, 0.0), (p.thrust_limits_at(2.5)[0], 0.0, 0.0), 0.05, 4000, p=p)
    hand = _terminal_speed(p.X_u, x_uu, x_max)
    assert traj[-1, 0] == pytest.approx(hand, rel=1e-6)
    assert traj[-1, 0] == pytest.approx(2.5, rel=0.03)


def test_bluerov2_heavy_box_brackets_its_published_top_speed():
    """Published: BlueROV2 top forward speed 1.5 m/s (Blue Robotics). With all four horizontal thrusters on surge
    (4 T cos 45°, the top-speed run; the shipped X_max keeps 35 % of them for sway and yaw) the box's terminal
    speeds run from the von Benzon/Wu end (high drag) to the Einarsson & Lipenitis end (low drag); the published
    speed lies inside, and the open-loop plant reproduces both ends."""
    x_max = 4 * 4.1 * 9.80665 * math.cos(math.pi / 4)
    ends = []
    for k in (0, 1):
        p = BLUEROV2_HEAVY.with_point({"X_u": BLUEROV2_HEAVY.interval("X_u")[k],
                                       "X_uu": BLUEROV2_HEAVY.interval("X_uu")[k]})
        traj = _open_loop((0.0, 0.0, 0.0, 0.0), (x_max, 0.0, 0.0), 0.01, 3000, p=p)
        hand = _terminal_speed(p.X_u, p.X_uu, x_max)
        assert traj[-1, 0] == pytest.approx(hand, rel=1e-6)
        ends.append(hand)
    assert ends[0] < 1.5 < ends[1]


def test_hull_sway_stays_within_its_iss_bound_under_aggressive_commands():
    sc = _scenario()
    rng = np.random.default_rng(3)
    commands = [tuple(rng.uniform(-1, 1, 3) * sc.limits.vector) for _ in range(60) for _ in range(50)]
    plant = DynamicPlant(sc)
    _run(plant, commands, 2)
    body, _ = plant.history()
    u_bar, r_bar = float(np.max(np.abs(body[:, 0]))), float(np.max(np.abs(body[:, 3])))
    gamma = float(hull_sway_bound(plant.params, u_bar, r_bar))  # the truth: a point of the box
    assert 0.0 < np.max(np.abs(body[:, 1])) <= gamma
    assert float(hull_sway_bound(REMUS100, u_bar, r_bar)) >= gamma  # the box's bound covers the truth


def test_omega_series_is_current_plus_loop_error_and_sway():
    sc = paper_scenario().with_changes(plant=PlantSettings("dynamic"))
    plant = DynamicPlant(sc)
    commands = _commands(30)
    states = np.vstack([[0.0, 0.0, 0.0, 0.0], _run(plant, commands, 2)])
    inputs = np.vstack([commands, [np.nan] * 3])
    t = np.arange(31) * 0.01
    omega = plant.omega_series(t, states, inputs)
    body, _ = plant.history()
    i = 17
    c = Plant(sc.disturbance).current(t[i])
    psi = states[i, 3]
    want = c + np.array([(body[i, 0] - inputs[i, 0]) * math.cos(psi) - body[i, 1] * math.sin(psi),
                         (body[i, 0] - inputs[i, 0]) * math.sin(psi) + body[i, 1] * math.cos(psi),
                         body[i, 2] - inputs[i, 1]])
    np.testing.assert_allclose(omega[i], want, atol=1e-14)
    assert np.all(np.isnan(omega[-1]))


def test_make_plant_kinds():
    sc = paper_scenario()
    assert isinstance(make_plant(sc), Plant)
    assert isinstance(make_plant(sc, kind="dynamic"), DynamicPlant)
    with pytest.raises(ConfigError, match="plant"):
        make_plant(sc, kind="hovercraft")


def test_the_omega_peak_covers_every_tick_and_the_stages_between():
    """ω at the ticks (omega_series) is the first RK4 stage of each tick, so the peak over every stage
    evaluation is at least the largest tick value; the between-tick stages can only add to it."""
    sc = paper_scenario().with_changes(plant=PlantSettings("dynamic"))
    plant = DynamicPlant(sc)
    assert plant.omega_peak() == (0.0, 0.0)
    commands = _commands(30)
    states = np.vstack([[0.0, 0.0, 0.0, 0.0], _run(plant, commands, 2)])
    omega = plant.omega_series(np.arange(31) * 0.01, states, np.vstack([commands, [np.nan] * 3]))[:-1]
    peak_xy, peak_z = plant.omega_peak()
    assert peak_xy >= np.max(np.hypot(omega[:, 0], omega[:, 1])) - 1e-12
    assert peak_z >= np.max(np.abs(omega[:, 2])) - 1e-12


def test_the_water_current_is_logged_apart_from_omega_at_the_ticks_and_every_stage():
    """Issue 30: at the ticks the logged current is the scenario's current itself; over every RK4 stage its peak
    covers the tick values and stays within the current's bound max(a_x, a_y), a_z (no constant here)."""
    sc = paper_scenario().with_changes(plant=PlantSettings("dynamic"))
    plant = DynamicPlant(sc)
    assert plant.current_peak() == (0.0, 0.0)
    _run(plant, _commands(30), 2)
    t = np.arange(31) * 0.01
    current = plant.current_series(t)
    np.testing.assert_array_equal(current, Plant(sc.disturbance).current(t))
    peak_xy, peak_z = plant.current_peak()
    assert peak_xy >= np.max(np.hypot(current[:, 0], current[:, 1])) - 1e-15
    assert peak_z >= np.max(np.abs(current[:, 2])) - 1e-15
    amplitude = sc.disturbance.amplitude
    assert sc.disturbance.constant == (0.0, 0.0, 0.0)
    assert peak_xy <= max(amplitude[0], amplitude[1]) + 1e-12 and peak_z <= amplitude[2] + 1e-12


# ---- the commanded sway velocity v_c ---------------------------------------------------------------------------
def _sway_commands(n: int) -> list[tuple[float, float, float]]:
    return [(0.2 + 0.1 * math.sin(0.7 * 0.01 * i), 0.08 * math.cos(0.5 * 0.01 * i), 0.2 * math.sin(0.9 * 0.01 * i))
            for i in range(n)]


# captured from the code before the sway command existed (the sway loop regulated v to 0): 300 ticks of
# _sway_commands on examples/bluerov2_current.toml, h = 0.005 s, 2 substeps, from (-1, 3, 0.2, 0)
_BEFORE_POSE = (-0.04374737013050533, 3.386952229222297, 0.5265649671090286, 0.42795093599202255)
_BEFORE_STATE = (0.28880201583651494, 7.09650985748559e-05, 0.0060317139632765525, 0.09060750569823511,
                 15.009892108336151, -1.0896593104230285, -0.08632764635561205, -0.0009327061274314589,
                 -0.001634355224929835, -0.005254029313867374, 0.5175349184966562, -7.515926055446984e-05)
_BEFORE_PEAK = [0.10251651179563187, 0.09535226895273749, 0.10000000000000003, 0.09510565162951536]
_BEFORE_OMEGA_150 = (0.060152811857910896, 0.08120055816903907, 0.0596282605498967)


@pytest.mark.parametrize("path", ["compiled", "python"])
def test_zero_sway_command_gives_the_very_floats_of_the_sway_loop_regulating_to_zero(path):
    """v_c = 0 (the default, and passed explicitly) is bit for bit the former sway loop on e_v = −v, on both paths."""
    from tubekit import load_scenario

    sc = load_scenario("examples/bluerov2_current.toml")
    override = Plant(sc.disturbance).current_at if path == "python" else None
    plant = DynamicPlant(sc, override=override)
    assert plant.lateral
    commands = _sway_commands(300)
    x, states = (-1.0, 3.0, 0.2, 0.0), [(-1.0, 3.0, 0.2, 0.0)]
    for i, v in enumerate(commands):
        x = plant.step_tuple(0.01 * i, x, v, 0.005, 2, sway=0.0) if i % 2 else plant.step_tuple(0.01 * i, x, v,
                                                                                                   0.005, 2)
        states.append(x)
    assert x == _BEFORE_POSE
    assert tuple(plant.state) == _BEFORE_STATE
    assert plant._peak == _BEFORE_PEAK
    t, inputs = 0.01 * np.arange(301), np.vstack([commands, [np.nan] * 3])
    omega = plant.omega_series(t, np.array(states), inputs)
    assert tuple(omega[150].tolist()) == _BEFORE_OMEGA_150
    np.testing.assert_array_equal(plant.omega_series(t, np.array(states), inputs, sway=np.zeros(301)), omega)


def _hold_sway(plant: DynamicPlant, sway: float, ticks: int) -> np.ndarray:
    """From rest at the origin, command (0, 0, 0) and the sway velocity ``sway`` (m/s) for ``ticks`` of 0.01 s."""
    x, states = (0.0, 0.0, 0.0, 0.0), [(0.0, 0.0, 0.0, 0.0)]
    for i in range(ticks):
        x = plant.step_tuple(0.01 * i, x, (0.0, 0.0, 0.0), 0.005, 2, sway=sway)
        states.append(x)
    return np.array(states)


def test_the_sway_loop_tracks_a_commanded_sway_velocity_on_both_paths():
    """Property: BlueROV2 Heavy (lateral thrust), at rest in calm water, commanded v_c = 0.1 m/s for 20 s: the body
    sway converges to v_c within 1e-3 m/s, the other velocities stay at their (zero) commands, the Python path
    (a current override) equals the compiled one to 1e-12, and ω counts the sway against v_c."""
    sc = _scenario("bluerov2_heavy")
    compiled, python = DynamicPlant(sc), DynamicPlant(sc, override=lambda t: (0.0, 0.0, 0.0))
    assert compiled.lateral
    states = _hold_sway(compiled, 0.1, 2000)
    np.testing.assert_allclose(_hold_sway(python, 0.1, 2000), states, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(python.state, compiled.state, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(python._peak, compiled._peak, rtol=0.0, atol=1e-12)
    body, thrust = compiled.history()
    assert abs(body[-1, 1] - 0.1) < 1e-3 and np.all(np.abs(body[-100:, 1] - 0.1) < 1e-3)
    np.testing.assert_allclose(body[-1, [0, 2, 3]], 0.0, atol=1e-3)
    assert abs(compiled.state[10]) <= compiled.params.Y_max  # the lateral thrust Y
    np.testing.assert_allclose(states[-1, 1], 0.1 * 20.0, rtol=0.1)  # ψ ≈ 0: the body sway is the world's y
    t, inputs = 0.01 * np.arange(2001), np.vstack([np.zeros((2000, 3)), [np.nan] * 3])
    vc = np.full(2001, 0.1)
    for plant in (compiled, python):
        tracked, free = plant.omega_series(t, states, inputs, sway=vc), plant.omega_series(t, states, inputs)
        assert np.max(np.hypot(tracked[-100:-1, 0], tracked[-100:-1, 1])) < 1e-3  # v_b − v_c ≈ 0
        assert np.hypot(free[-2, 0], free[-2, 1]) == pytest.approx(0.1, abs=1e-3)  # v_b against 0
        assert np.all(np.isnan(tracked[-1]))
    np.testing.assert_allclose(python.omega_series(t, states, inputs, sway=vc),
                               compiled.omega_series(t, states, inputs, sway=vc), rtol=0.0, atol=1e-12)
    with pytest.raises(ShapeError, match="sway"):
        compiled.omega_series(t, states, inputs, sway=vc[:-1])


def test_a_sway_command_needs_lateral_thrust():
    plant = DynamicPlant(_scenario("remus100"))
    assert not plant.lateral
    with pytest.raises(ConfigError, match="sway"):
        plant.step_tuple(0.0, (0.0, 0.0, 0.0, 0.0), (0.3, 0.0, 0.0), 0.005, 2, sway=0.1)
    with pytest.raises(ConfigError, match="sway"):
        plant.step(0.0, np.zeros(4), np.array([0.3, 0.0, 0.0]), 0.005, 2, sway=-0.05)
    assert plant.state is None  # refused before the first step
    plant.step(0.0, np.zeros(4), np.array([0.3, 0.0, 0.0]), 0.005, 2, sway=0.0)


@pytest.mark.parametrize("path", ["compiled", "python"])
def test_a_yaw_loop_of_its_own_bandwidth_turns_faster_and_leaves_the_other_channels_as_they_were(path):
    """The BlueROV2 Heavy under way at (0.2, 0.05, 0) in calm water, its yaw-rate command stepped to 0.1 rad/s
    at t = 0.1 s, its yaw loop at 20 rad/s against the loop_bandwidth's 10: the yaw rate reaches 90 % of the step
    sooner and its summed error over the 0.9 s is smaller, while heave (same gains, decoupled from yaw) follows the
    very same floats and surge (coupled to yaw only through the sway) moves by less than 1e-5 m/s."""
    def run(yaw):
        plant = DynamicPlant(_scenario("bluerov2_heavy", yaw_loop_bandwidth=yaw),
                             override=(lambda t: (0.0, 0.0, 0.0)) if path == "python" else None)
        _run(plant, [(0.2, 0.05, 0.0)] * 10 + [(0.2, 0.05, 0.1)] * 90, 2)
        return plant.history()[0]

    slow, fast = run(0.0), run(20.0)
    np.testing.assert_array_equal(fast[:11], slow[:11])
    assert np.argmax(fast[:, 3] >= 0.09) < np.argmax(slow[:, 3] >= 0.09)
    assert np.sum(np.abs(0.1 - fast[11:, 3])) < 0.8 * np.sum(np.abs(0.1 - slow[11:, 3]))
    np.testing.assert_array_equal(fast[:, 2], slow[:, 2])
    assert np.max(np.abs(fast[:, 0] - slow[:, 0])) < 1e-5


# ---- [plant] start = "settled": the loop's equilibrium at limits.initial ------------------------------------------

def _settled(vehicle: str, surge: float, u_max: float = 2.5):
    plant = PlantSettings("dynamic", vehicle=vehicle, start="settled")
    return paper_scenario().with_changes(disturbance=CALM, plant=plant, **{
        "limits.u_max": u_max, "limits.rate": (0.5, 0.5, 1.0), "limits.initial": (surge, 0.0, 0.0)})


@st.composite
def _settled_runs(draw):
    """A vehicle, a truth anywhere in its box and a straight-run surge it can hold at every point of that box."""
    vehicle = draw(st.sampled_from(["bluerov2_heavy", "remus100"]))
    box = PlantSettings("dynamic", vehicle=vehicle).params
    fractions = draw(st.lists(st.floats(0.0, 1.0), min_size=len(box.interval_fields),
                              max_size=len(box.interval_fields)))
    truth = {k: min(max(lo + f * (hi - lo), lo), hi)  # inside the interval despite rounding
             for k, f in zip(box.interval_fields, fractions) for lo, hi in [box.interval(k)]}
    surge = draw(st.floats(0.0, 0.7 if vehicle == "bluerov2_heavy" else 1.2))  # below either top speed at any corner
    return vehicle, box.with_point(truth), surge


@given(_settled_runs())
def test_a_settled_start_is_the_loops_equilibrium_wherever_the_truth_lies_in_the_box(run):
    """Property: started settled at u_0 and commanded u_0, the vehicle (any point of its box) stays at ν = (u_0, 0,
    0, 0) with its thrust and integrators unchanged for 1 s: no start transient, though the controller's model is the
    box's midpoint and the truth is not."""
    vehicle, truth, surge = run
    plant = DynamicPlant(_settled(vehicle, surge), params=truth)
    x = (0.0, 0.0, 0.0, 0.0)
    for k in range(100):
        x = plant.step_tuple(0.01 * k, x, (surge, 0.0, 0.0), 0.005, 2)
        if k == 0:
            first = plant.state
    assert np.allclose(plant.state, first, rtol=0.0, atol=1e-9)
    assert np.allclose(plant.state[:4], (surge, 0.0, 0.0, 0.0), rtol=0.0, atol=1e-9)
    assert x[0] == pytest.approx(surge, abs=1e-8)  # 1 s at u_0 along x, no current


@pytest.mark.parametrize("end", [0, 1])
def test_without_a_model_feedforward_the_integrators_hold_the_whole_drag_and_a_settled_start_stays(end):
    """With ``loop_feedforward = "none"`` the loop commands M̂ a only: at ν = the command with the integrators at 0
    it commands no force at all, and started settled at 0.3 m/s at a corner of the BlueROV2's box the integrator
    holds the truth's whole drag, so the vehicle stays at 0.3 m/s for 1 s."""
    box = BLUEROV2_HEAVY.with_overrides({"loop_feedforward": "none"})
    truth = box.with_point({k: box.interval(k)[end] for k in box.interval_fields})
    sc = _settled("bluerov2_heavy", 0.3).with_changes(plant=PlantSettings(
        "dynamic", vehicle="bluerov2_heavy", start="settled", overrides={"loop_feedforward": "none"}))
    plant = DynamicPlant(sc, params=truth)
    assert plant.thrust_command((0.3, 0.0, 0.0, 0.1), (0.3, 0.0, 0.1), (0.0, 0.0, 0.0))[0] == (0.0, 0.0, 0.0)
    x = (0.0, 0.0, 0.0, 0.0)
    for k in range(100):
        x = plant.step_tuple(0.01 * k, x, (0.3, 0.0, 0.0), 0.005, 2)
    drag = body_forces(truth, (0.3, 0.0, 0.0, 0.0))[0]
    assert plant.state[4] == pytest.approx(drag, rel=1e-9) and plant.state[0] == pytest.approx(0.3, abs=1e-9)


def test_a_settled_start_the_vehicle_cannot_hold_names_the_field():
    """The BlueROV2 Heavy's eight T200 do not hold 2.4 m/s against its drag: no equilibrium there."""
    with pytest.raises(ConfigError, match=r"^plant\.start: expected 'trimmed': the vehicle cannot hold 2\.4 m/s"):
        DynamicPlant(_settled("bluerov2_heavy", 2.4)).step_tuple(0.0, (0.0,) * 4, (2.4, 0.0, 0.0), 0.01, 1)


def test_a_trimmed_start_moves_where_a_settled_one_does_not():
    """At a corner of the BlueROV2's box the trimmed start at 0.3 m/s (integrators 0, τ = n̂) has a transient that a
    settled one lacks: the counterexample the settled start removes."""
    box = BLUEROV2_HEAVY
    truth = box.with_point({k: box.interval(k)[0] for k in box.interval_fields})
    worst = []
    for start in ("trimmed", "settled"):
        sc = _settled("bluerov2_heavy", 0.3).with_changes(**{"plant.start": start})
        plant, x = DynamicPlant(sc, params=truth), (0.0,) * 4
        errors = []
        for k in range(100):
            x = plant.step_tuple(0.01 * k, x, (0.3, 0.0, 0.0), 0.01, 1)
            errors.append(abs(plant.state[0] - 0.3))
        worst.append(max(errors))
    assert worst[0] > 1e-3 and worst[1] < 1e-9
