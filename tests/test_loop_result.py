"""tubekit.loop.result: one field list (LOG_FIELDS) behind the loop's buffer, the result and the CSV; the run's
metrics in the one convention; ``plot()`` hands the run to the plotting role (``import tubekit`` loads no
matplotlib: tests/test_architecture.py).

The run is hand-built (as in test_loop_promises): a parked vehicle 2 m from a stationary target, 3 periods of
10 ticks, so every column has a value known here.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.jsonable import dumps
from tubekit.loop.metrics import METRIC_KEYS, RUN_KEYS
from tubekit.loop.promises import check_promises
from tubekit.loop.result import CSV_COLUMNS, DYNAMIC_COLUMNS, LOG_FIELDS, LogArrays, SimulationResult, allocate_log
from tubekit.tightening import Tightening
from tubekit.tiers import Tiers

TICKS, STEPS = 10, 3
ROWS = STEPS * TICKS + 1
TUBE = np.array([0.01, 0.01, 0.02])


def _tight(**changes) -> Tightening:
    base = dict(v_max=np.array([0.35, 0.28, 0.35]), e_d_min=0.6, e_o_max=0.3, e_z_max=0.9, e_d_max=2.9,
                obstacle_margin=0.1, sigma=10.0, margins=np.zeros((8, 4)),
                rates=np.zeros(4), tube=TUBE, region=(0.5, 3.0, 1.0, 0.5), disturbance=(0.04, 0.02, 0.03),
                tiers=Tiers(True, True))
    base.update(changes)
    return Tightening(**base)


def _run(stationary, **changes) -> SimulationResult:
    states = np.tile([-2.0, 3.0, 0.0, 0.0], (ROWS, 1))
    inputs = np.zeros((ROWS, 3))
    inputs[-1] = np.nan
    omega = np.zeros((ROWS, 3))
    omega[-1] = np.nan
    step_ms = np.full(ROWS, np.nan)
    step_ms[0:-1:TICKS] = [1.0, 2.0, 3.0]
    fields = dict(
        scenario=stationary, tube=True, law="corrected", sigma=10.0, tightening=_tight(), plant_step_s=0.005,
        ticks_per_step=TICKS, t=np.arange(ROWS) * 0.01, step=np.minimum(np.arange(ROWS) // TICKS, STEPS),
        states=states, desired=np.tile([0.0, 3.0, 0.0], (ROWS, 1)), nominal=states.copy(), v_hat=inputs.copy(),
        kappa=np.zeros((ROWS, 3)), inputs=inputs, omega=omega, saturated=np.zeros(ROWS, dtype=bool),
        fallback=np.zeros(ROWS, dtype=bool), replaced=np.zeros(ROWS, dtype=bool), n_detected=np.zeros(ROWS, int),
        solve_ms=step_ms / 2, step_ms=step_ms, wall=np.linspace(0.0, 0.3, ROWS),
        max_violation=np.array([0.0, 1e-3, 2e-3]), rejected=np.zeros(STEPS, dtype=bool),
        plan_age=np.zeros(STEPS, dtype=int), plan_slack=np.zeros(STEPS),
        backup_active=np.zeros(ROWS, dtype=bool),
        backup_anchor=np.full((ROWS, 3), np.nan), recovery=np.zeros(ROWS, dtype=bool), sway_command=np.zeros(ROWS))
    fields.update(changes)
    return SimulationResult(**fields)


# ---- one field list --------------------------------------------------------------------------------------

def test_the_result_and_the_loop_buffer_take_their_arrays_from_log_fields():
    from tubekit.loop.closed_loop import _Log

    names = [f.name for f in LOG_FIELDS]
    assert len(names) == len(set(names)) == 22 and {"backup_active", "backup_anchor", "candidate", "recovery",
                                                    "sway_command"} <= set(names)
    assert issubclass(SimulationResult, LogArrays) and issubclass(_Log, LogArrays)
    assert {f.name for f in dataclasses.fields(LogArrays)} == set(names)
    assert set(names) <= {f.name for f in dataclasses.fields(_Log)}


def test_allocate_log_gives_each_field_its_rows_width_and_fill():
    arrays = allocate_log(ROWS, STEPS)
    assert set(arrays) == {f.name for f in LOG_FIELDS}
    assert arrays["states"].shape == (ROWS, 4) and np.isnan(arrays["states"]).all()
    assert arrays["saturated"].shape == (ROWS,) and arrays["saturated"].dtype == bool and not arrays["saturated"].any()
    assert arrays["plan_age"].shape == (STEPS,) and arrays["plan_age"].dtype.kind == "i"
    assert np.isnan(arrays["plan_slack"]).all() and (arrays["wall"] == 0).all()


def test_every_csv_column_of_a_log_field_holds_that_field(stationary):
    run = _run(stationary, saturated=np.arange(ROWS) % 7 == 0)
    cols = run.columns()
    assert tuple(cols) == CSV_COLUMNS and len(set(CSV_COLUMNS)) == len(CSV_COLUMNS)
    assert all(len(v) == ROWS for v in cols.values())
    np.testing.assert_array_equal(np.column_stack([cols[n] for n in ("x", "y", "z", "psi")]), run.states)
    np.testing.assert_array_equal(cols["wall_s"], run.wall)
    assert cols["saturated"].tolist() == [int(k % 7 == 0) for k in range(ROWS)]
    # a per-period field sits on the first tick of its period, NaN elsewhere
    assert cols["plan_violation"][[0, 10, 20]].tolist() == [0.0, 1e-3, 2e-3]
    assert np.isnan(np.delete(cols["plan_violation"], [0, 10, 20])).all()
    # derived columns: e_d = 2 m from the target, rho = 0 (nominal = state)
    assert np.allclose(cols["e_d"], 2.0) and np.allclose(cols["rho_norm"], 0.0)


def test_plot_is_a_figure_with_the_verdict_in_its_title(stationary):
    """Issue 35 item 3: ``run.plot()`` returns a matplotlib figure (no pyplot state) titled with the run's tiers and
    what happened to them (``run.metrics["outcome"]``); an unknown kind is refused by name."""
    from matplotlib.figure import Figure

    run = _run(stationary)
    fig = run.plot()
    assert isinstance(fig, Figure) and fig.canvas.manager is None  # not a pyplot figure
    outcome = run.metrics["outcome"]
    assert f"safe: {outcome['safe']}; tracking: {outcome['tracking']}" in fig.get_suptitle()
    view = next(ax for ax in fig.axes if ax.get_title() == "top view")
    assert any(ln.get_label().startswith("target at t = ") for ln in view.get_lines())
    baseline = _run(stationary, tube=False, sigma=0.0, tightening=Tightening.untightened(stationary)).plot()
    assert baseline.get_suptitle().endswith("baseline: nothing is promised")
    with pytest.raises(ConfigError, match="^kind: expected one of summary"):
        run.plot(kind="bode")


def test_a_dynamic_runs_plot_has_the_thrust_panel(stationary):
    dynamic = stationary.with_changes(plant=dataclasses.replace(stationary.plant, kind="dynamic",
                                                                vehicle="bluerov2_heavy"))
    body, thrust = np.zeros((ROWS, 4)), np.tile([10.0, 0.0, -1.0], (ROWS, 1))
    fig = _run(dynamic, body=body, thrust=thrust).plot()
    assert "thrust / limit" in [ax.get_ylabel() for ax in fig.axes]
    assert "thrust / limit" not in [ax.get_ylabel() for ax in _run(stationary).plot().axes]


# ---- the run's metrics: one convention --------------------------------------------------------------------

def test_a_tube_runs_metrics_carry_its_promises_and_bounds(stationary):
    run = _run(stationary)
    m = run.metrics
    assert set(METRIC_KEYS) <= set(m) and set(RUN_KEYS) <= set(m)
    promises = check_promises(run)
    assert m["promises"] == [p.to_dict() for p in promises] and m["promises_kept"] is all(p.ok for p in promises)
    assert m["max_rho_ratio"] == 0.0  # nominal = state: no deviation
    assert m["certified"] is True and m["rho_bound"] == pytest.approx(float(np.linalg.norm(TUBE)))
    assert m["sway_bound"] == 0.03 and m["tube_box"] == TUBE.tolist()
    assert m["law"] == "corrected" and m["sigma"] == 10.0 and m["tube"] is True
    assert m["velocity_error_max"] is None  # kinematic plant
    assert json.loads(dumps(m)) == m  # already JSON values: metrics.json holds exactly this


def test_an_uncertified_run_has_no_rho_bound_and_a_zero_tube_is_an_infinite_ratio(stationary):
    m = _run(stationary, tightening=_tight(tiers=Tiers(), tube=np.zeros(3))).metrics
    assert m["certified"] is False and m["rho_bound"] is None
    assert m["max_rho_ratio"] is None and m["promises_kept"] is False  # inf is null in strict JSON


def test_the_baseline_is_promised_nothing(stationary):
    run = _run(stationary, tube=False, sigma=0.0, tightening=Tightening.untightened(stationary))
    m = run.metrics
    assert m["promises"] == [] and m["promises_kept"] is None and m["max_rho_ratio"] is None
    assert m["sway_bound"] is None and m["rho_bound"] is None and m["law"] is None
    with pytest.raises(ConfigError, match="without a certificate"):
        check_promises(run)


def test_step_timings_in_the_metrics_come_from_the_logged_periods(stationary):
    m = _run(stationary).metrics
    assert m["steps"] == STEPS and m["step_ms_median"] == 2.0
    assert m["fhocp_max_violation"] == 2e-3 and math.isclose(m["wall_s"], 0.3)


def test_a_dynamic_log_writes_the_water_current_after_the_hull(stationary):
    """Issue 30: a dynamic run's CSV ends with the water current the plant applied (current_1..3, m/s), apart
    from omega_1..3; NaN when the log holds none; a kinematic log has neither."""
    body, thrust = np.zeros((ROWS, 4)), np.zeros((ROWS, 3))
    current = np.tile([0.01, -0.02, 0.005], (ROWS, 1))
    cols = _run(stationary, body=body, thrust=thrust, current=current, current_peak=(0.03, 0.01)).columns()
    assert tuple(cols) == CSV_COLUMNS + DYNAMIC_COLUMNS
    assert DYNAMIC_COLUMNS[-3:] == ("current_1", "current_2", "current_3")
    np.testing.assert_array_equal(np.column_stack([cols["current_1"], cols["current_2"], cols["current_3"]]), current)
    unlogged = _run(stationary, body=body, thrust=thrust).columns()
    assert np.all(np.isnan(unlogged["current_1"]))
    kinematic = _run(stationary)
    assert kinematic.current is None and kinematic.current_peak is None and tuple(kinematic.columns()) == CSV_COLUMNS
