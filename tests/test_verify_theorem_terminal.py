"""verify.theorem.terminal: the tracking theorem's terminal set and law, and what it refuses by name."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import verify
from tubekit import load_scenario
from tubekit.model.kinematics import unicycle_step
from tubekit.model.terminal_law import line_of_sight
from tubekit.model.trajectory import Line
from tubekit.scenario import Obstacle
from verify.theorem.terminal import TERMINAL_PREFIXES, law_conditions, terminal_bounds

PC = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


def test_paper_currents_gets_a_terminal_law_and_every_condition_holds(pc_cert):
    law = pc_cert.design.terminal
    assert pc_cert.tiers.tracking and law is not None
    mine = [c for c in pc_cert.design.conditions if c.condition.startswith(TERMINAL_PREFIXES)]
    names = {c.condition for c in mine}
    assert {"terminal_inputs[u]", "terminal_invariant[d_lo]", "terminal_invariant[alpha]", "terminal_in_region[e_o]",
            "terminal_sensing", "path_clearance[0]", "path_clearance[1]", "initial_terminal"} <= names
    assert all(c.ok for c in mine)
    assert pc_cert.region.e_d[0] < law.d_lo < law.d_star < law.d_hi < pc_cert.region.e_d[1]
    assert pc_cert.tightening.terminal_law == law and pc_cert.tightening.plan_always_available


def test_the_papers_obstacles_on_the_circle_refuse_tracking_by_name():
    """The paper puts its obstacles on the target's circle: the candidate's footprint cannot pass them."""
    sc = PC.with_changes(obstacles=(Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((-3.0, 0.0, 0.0), 0.4)))
    cert = verify.certify(sc)
    assert cert.tiers.safe and not cert.tiers.tracking and cert.design.terminal is None
    failed = {c.condition: c for c in cert.failures}
    assert set(failed) == {"path_clearance[0]", "path_clearance[1]"}
    assert failed["path_clearance[0]"].detail.split("has ")[1].startswith("0")        # the path meets the centre
    assert cert.tightening.terminal_law is None and not cert.tightening.plan_always_available


@pytest.mark.parametrize("change, name", [
    ({"limits.rate": (0.1, 0.1, 0.1)}, "terminal_rate[u]"),
    ({"region.heading": "both"}, "terminal_heading"),
])
def test_designs_outside_the_theorem_are_named(change, name):
    cert = verify.certify(PC.with_changes(**change))
    assert not cert.tiers.tracking and name in [c.condition for c in cert.failures]


def test_a_law_without_radial_gain_is_not_invariant(pc_cert):
    """λ = 0: the completion never closes the radial gap, so the deviation pushes d out of [d_lo, d_hi]."""
    b = terminal_bounds(PC, pc_cert.design, pc_cert.region)
    lazy = dataclasses.replace(pc_cert.design.terminal, gain_d=0.0)
    failed = {c.condition for c in law_conditions(b, lazy) if not c.ok}
    assert {"terminal_invariant[d_lo]", "terminal_invariant[d_hi]"} <= failed


def test_a_start_the_law_cannot_bring_to_the_set_refuses_tracking():
    """2.5 m behind the target (inside R): the law's 8 rows cannot close 1.6 m to X_f (d_hi ≈ 0.86 m) in 0.8 s."""
    cert = verify.certify(PC.with_changes(initial_state=(-2.5, 3.0, 0.2, 0.0)))
    assert not cert.tiers.tracking and [c.condition for c in cert.failures] == ["initial_terminal"]
    assert "d <= d_hi" in cert.failures[0].detail


def _circle_target(t: float) -> tuple[np.ndarray, np.ndarray]:
    tr = PC.trajectory
    return np.asarray(tr.position(t), float).reshape(3), np.asarray(tr.velocity(t), float).reshape(3)


@settings(max_examples=80, deadline=None, derandomize=True)
@given(t=st.floats(0.0, 100.0), u=st.floats(0.0, 1.0), a=st.floats(-1.0, 1.0), z=st.floats(-1.0, 1.0),
       bearing=st.floats(-math.pi, math.pi), dx=st.floats(-1.0, 1.0), dy=st.floats(-1.0, 1.0), dpsi=st.floats(-1, 1))
def test_one_completion_from_the_deviated_set_lands_in_the_set(pc_cert, t, u, a, z, bearing, dx, dy, dpsi):
    """Property (step 17, invariance): from any state of X_f moved by the replay's deviation (D_xy, D_ψ, D_z), one
    row of the certified law held over δ along the exact arc stays in V̄ and ends in X_f, against the scenario's
    own target (a circle at 0.19 m/s). Independent of the proof: a float simulation of the arc."""
    law, design = pc_cert.design.terminal, pc_cert.design
    b = terminal_bounds(PC, design, pc_cert.region)
    dt = PC.controller.dt
    p, v = _circle_target(t)
    d = law.d_lo + u * (law.d_hi - law.d_lo)
    where = p[:2] + d * np.array([math.cos(bearing), math.sin(bearing)])   # the vehicle at distance d
    los = math.atan2(p[1] - where[1], p[0] - where[0])
    x = np.array([where[0], where[1], p[2] + z * law.z_max, los + a * law.alpha_max])
    shift = np.array([dx, dy]) / max(1.0, math.hypot(dx, dy)) * b.dev_xy
    x = x + np.array([shift[0], shift[1], math.copysign(b.dev_z, z), dpsi * b.dev_psi])
    row = law.command(x, p, v, dt)
    assert np.all(np.abs(row) <= np.asarray(design.v_bar) + 1e-12)
    end = unicycle_step(x, row, dt)
    p_end, _ = _circle_target(t + dt)
    assert law.contains(end, p_end), (line_of_sight(end, p_end), law)


def test_a_surge_floor_with_an_obstacle_near_the_path_leaves_tracking_refused_by_the_path_and_safe_given(
        keep_moving_cert):
    """Under the surge floor the bearing face makes the terminal law's own conditions hold (step 17b); on
    keep_moving what refuses tracking is the loiter's footprint about the completion's end against the obstacle 3 m
    off the path, which the safe tier does not read."""
    c = keep_moving_cert
    assert c.tiers.safe and not c.tiers.tracking
    failed = [x for x in c.conditions if x.ok is not True]
    assert [x.condition for x in failed] == ["path_clearance[0]"]
    assert "binding: the backup's footprint" in failed[0].detail
    assert "path_clearance[0]" not in {x.condition for x in c.tier_conditions["safe"]}


# ---- the search: the grid's refinement and the path's shortcut ------------------------------------------------

BRISK_TRACKED = "examples/bluerov2_brisk_tracked.toml"


def test_where_no_coarse_set_fits_the_rows_the_refinement_finds_one_that_meets_every_condition(monkeypatch):
    """``examples/bluerov2_brisk_tracked.toml`` (0.2 m/s in 0.1 m/s of current, rate-limited plans): the coarse
    grid alone has no set meeting every condition (the nearest whose rows fit the plans' jump cannot be reached
    from the start, 6 m behind the target: ``initial_terminal``); with the refinement the kept set meets every
    condition, and its lower end is not a point of the coarse grid."""
    import verify.theorem.terminal as terminal
    sc = load_scenario(BRISK_TRACKED)
    cert = verify.certify(sc)
    law = cert.design.terminal
    assert cert.tiers.tracking and law is not None and law.has_rows
    assert all(c.ok for c in cert.design.conditions if c.condition.startswith(TERMINAL_PREFIXES))
    b = terminal_bounds(sc, cert.design, cert.region)
    coarse_lows = {round(s.d_lo, 9) for s in terminal._sets(b)}
    assert round(law.d_lo, 9) not in coarse_lows
    monkeypatch.setattr(terminal, "_refined", lambda bounds, wanted: iter(()))
    monkeypatch.setattr(terminal, "_started", lambda bounds, distance, wanted: iter(()))  # the coarse grid alone
    found, conds = terminal.design_terminal(sc, cert.design, cert.region, cert.backup.safe_set)
    assert found is None and {c.condition for c in conds if not c.ok} == {"initial_terminal"}


@pytest.mark.slow
def test_where_every_set_of_the_grid_misses_the_start_a_set_centred_on_it_keeps_both_tiers(monkeypatch):
    """``examples/remus100_survey.toml`` with its rock 18.5 m off the line (20 m in the file): the grid's sets that
    clear the rock lie beyond the start, 60 m behind the target, so without the sets centred on the start the search
    ends at ``initial_terminal``; with them both tiers hold and X_f's centre is the start's distance."""
    import verify.theorem.terminal as terminal
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "remus100_survey.toml").with_changes(
        obstacles=(Obstacle((-40.0, 18.5, 0.0), 0.5),))
    cert = verify.certify(sc)
    law = cert.design.terminal
    assert cert.tiers.safe and cert.tiers.tracking and law is not None
    assert law.d_lo < 60.0 < law.d_hi and (law.d_lo + law.d_hi) / 2 == pytest.approx(60.0, rel=1e-9)
    monkeypatch.setattr(terminal, "_started", lambda bounds, distance, wanted: iter(()))
    found, conds = terminal.design_terminal(sc, cert.design, cert.region, cert.backup.safe_set)
    assert found is None and "initial_terminal" in {c.condition for c in conds if not c.ok}


def test_the_path_shortcut_rests_on_footprints_nested_by_the_sets_reach(pc_cert):
    """A set whose path clearance fails blocks every set whose footprint contains its own, unsampled
    (:func:`verify.theorem.path_clearance.contains`); on the paper's scenario (no bearing face) the grid's
    footprints are nested by d_hi: each contains every one that reaches less."""
    from verify.theorem.path_clearance import contains
    from verify.theorem.terminal import _sets, footprint_of
    b = terminal_bounds(PC, pc_cert.design, pc_cert.region)
    laws = sorted(_sets(b), key=lambda law: law.d_hi)
    safe = pc_cert.backup.safe_set
    feet = [footprint_of(PC, pc_cert.design, b, law, safe) for law in laws]
    assert len({round(law.d_hi, 9) for law in laws}) > 3
    for near, far in zip(feet, feet[1:]):
        assert contains(far, near)
    assert not contains(feet[0], feet[-1]) or feet[0] == feet[-1]


@pytest.mark.parametrize("edits, proved", [
    ({}, True),
    ({"controller.candidate": False}, True),                      # a run setting: that run rests on a premise
    ({"region.heading": "away"}, False),                          # the terminal law points at the target
    ({"limits.u_min": 0.05, "trajectory": Line(start=(0.0, 0.0, 0.0), direction_velocity=(0.0, 0.0, 0.0))},
     False),                                                      # a minimum surge behind a target that stops
    ({"limits.u_min": 0.05}, True),                               # ... behind one with a speed floor
])
def test_step_17_proves_a_plan_at_every_period_only_where_it_covers_the_loop(edits, proved):
    """proves_feasibility: the terminal ingredients cover the design (module doc)."""
    from verify.kernel.region import Region
    from verify.theorem.terminal import proves_feasibility
    sc = PC.with_changes(**edits)
    assert proves_feasibility(sc, Region.from_scenario(sc)) is proved


@pytest.mark.parametrize("rate, searched", [
    ((0.5, 0.5, 0.05), True),     # the yaw row fails: the feedforward may lower it
    ((0.5, 0.002, 1.0), False),   # the heave row fails: nothing the feedforward changes
])
def test_the_feedforwards_laws_are_searched_only_where_they_could_lower_what_fails(monkeypatch, rate, searched):
    """paper_currents with rate-limited plans: where the best memoryless set fails its yaw row, the search goes on
    to the line-of-sight feedforward's laws (step 17e); where it fails its heave row (a member of
    FEEDFORWARD_CANNOT_LOWER), their grid is never built, and the verdict names the heave row."""
    import verify.theorem.terminal as terminal

    built = []
    sets = terminal._grid_sets

    def spy(b, fine=False, feedforward=False):
        built.append(feedforward)
        return sets(b, fine, feedforward)
    monkeypatch.setattr(terminal, "_grid_sets", spy)
    cert = verify.certify(PC.with_changes(**{"limits.rate": rate}))
    assert not cert.tiers.tracking and any(built) is searched
    if not searched:
        assert "terminal_rate[w]" in {c.condition for c in cert.failures}
        assert "terminal_rate[w]" in terminal.FEEDFORWARD_CANNOT_LOWER


def test_the_search_builds_the_grids_sets_only_as_far_as_it_reads_them(monkeypatch):
    """``examples/keep_moving_survey.toml`` (a surge floor and rate-limited plans: each set of the grid needs its
    gentle gains, row faces and bearing face): the first set of the grid is built with a small share of the row-face
    sizings the whole grid needs, and reading the grid on from there gives the sets that building the whole grid at
    once gives, in the same order."""
    import verify.theorem.terminal as terminal
    import verify.theorem.terminal_rows as rows
    from verify.theorem.terminal_bearing import bearing_row_sets
    sc = load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving_survey.toml")
    cert = verify.certify(sc)
    b = terminal_bounds(sc, cert.design, cert.region)
    assert b.surge_floor is not None and b.jumps is not None
    sized: list[object] = []
    with_gains = rows._with_gains
    monkeypatch.setattr(rows, "_with_gains", lambda *args: sized.append(args[1]) or with_gains(*args))
    terminal._built_sets.cache_clear()
    first = next(iter(terminal._grid_sets(b)))
    to_first = len(sized)
    whole = terminal._sets(b)
    assert whole[0] == first and len(whole) > 100
    assert 0 < 20 * to_first < len(sized)
    grid = terminal._grid(b, terminal._grid_points(terminal.WIDTHS, terminal.LOWER_ENDS), tuple(terminal.ANGLES))
    assert list(whole) == bearing_row_sets(b, grid)
