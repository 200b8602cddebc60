"""benchmarks/closed_loop.py: its JSON keys and the profile's split by part (timings not asserted)."""

from __future__ import annotations


import pytest

from .scripts import load_script


def _module():
    return load_script("benchmarks/closed_loop.py", "bench_closed_loop")


@pytest.fixture(scope="module")
def short_run():
    return _module().measure(duration=2.0, profile=True, repeat=2)


def test_the_short_run_reports_every_key(short_run):
    for key in ("wall_s", "walls_s", "realtime_factor", "realtime_factor_with_import", "solver_import_s_excluded",
                "certify_s_excluded", "breakdown", "profile"):
        assert key in short_run, key
    assert len(short_run["walls_s"]) == 2
    assert short_run["realtime_factor"] == pytest.approx(2.0 / short_run["wall_s"])


def test_the_profile_parts_cover_the_run_without_double_counting(short_run):
    prof = short_run["profile"]
    parts = prof["parts_s"]
    assert set(_module().PROFILE_PARTS) | {"other"} == set(parts)
    # 20 periods: the FHOCP ran, the plant stepped 200 ticks, the arc check judged every plan
    assert parts["fhocp"] > 0 and parts["plant"] > 0 and parts["arc_check"] > 0
    assert sum(v for k, v in parts.items() if k != "other") <= prof["profiled_wall_s"] * (1 + 1e-9)
    assert sum(prof["parts_share"].values()) == pytest.approx(1.0)


def test_the_solver_floor_is_a_ceiling_of_the_real_time_factor():
    """The floor run sums the bare Clarabel time of every step: it is part of each step and of the wall."""
    from tubekit import paper_scenario
    import verify
    mod = _module()
    sc = paper_scenario().with_changes(duration=1.0)
    tg = verify.certify(sc, law=sc.controller.law).best_effort_tightening()
    floor = mod.solver_floor(sc, tg)
    assert floor["steps"] == 10  # one FHOCP step per 0.1 s period
    assert 0.0 < floor["clarabel_solve_s"] < floor["fhocp_step_s"] < floor["wall_s"]
    assert floor["floor_realtime_factor"] > floor["realtime_factor"]
    assert floor["floor_realtime_factor"] == pytest.approx(1.0 / floor["clarabel_solve_s"])


def test_the_compiled_loop_logs_the_very_floats_of_the_uncompiled_one():
    """Over a 3 s tube run, the compiled plant, arcs, rollout and error coordinates leave every logged float of
    the run (states, plans, inputs, rejections, slacks, nominal) as the numpy and Python references give it."""
    out = _module().compare_previous(repeat=2, duration=3.0)
    assert out["identical_logs"] is True
    assert len(out["walls_s"]["previous"]) == len(out["walls_s"]["current"]) == 2
