"""Region search: every grid point is certified or reported with its first failure."""

from __future__ import annotations

import pytest

import verify
from tubekit import paper_scenario
from tubekit.app.cli import main
from tubekit.exceptions import ConfigError
from tubekit.scenario import load_scenario
from verify.studies.region_search import search_region

PAPER_CURRENTS = str(verify.SCENARIOS_DIR / "paper_currents.toml")


def test_paper_scenario_reports_what_it_tried():
    """Section VI with u_max and epsilon raised past keep_up's and yaw_budget's needs: the search runs its grid."""
    sc = paper_scenario().with_changes(epsilon=0.5, **{"limits.u_max": 0.6})
    res = search_region(sc, e_o_max=(0.3, 0.6), e_d_max=(1.5, 3.0))
    assert len(res.tried) == 4 and res.best is None and res.blocked_by == ()
    assert all(not t.certified and t.first_failure for t in res.tried)
    text = res.summary()
    assert "none certifies" in text and "tried 4" in text
    assert res.to_dict()["any_certified"] is False


def test_a_failure_no_region_can_remove_is_said_at_once():
    """Issue 32: the paper's target (0.377 m/s) and current outrun u_max = 0.4 in every region: nothing searched."""
    res = search_region(paper_scenario())
    assert res.tried == () and res.best is None
    assert any(b.startswith("keep_up[u]: limits.u_max = 0.4 < ") for b in res.blocked_by)
    assert "no region can help" in res.summary() and res.to_dict()["blocked_by"] == list(res.blocked_by)


def test_best_is_widest_certified():
    res = search_region(load_scenario(PAPER_CURRENTS), e_o_max=(0.3, 0.5), e_d_max=(2.0, 3.0))
    assert res.best is not None and res.best.certified
    assert (res.best.e_o_max, res.best.e_d_max) == max((t.e_o_max, t.e_d_max) for t in res.certified)


def test_the_table_names_each_failure_whole_and_counts_them():
    """A failed condition's name is printed whole (``path_clearance[0]`` is wider than the table's 14 characters,
    and it was cut to ``path_clearance``), and the failures are counted under the table with the skips' reason."""
    res = search_region(load_scenario(PAPER_CURRENTS), e_o_max=(0.3, 0.5), e_d_max=(0.4, 2.0))
    verdicts = {(t.e_o_max, t.e_d_max): t.first_failure for t in res.tried}
    assert verdicts[(0.3, 2.0)] == "path_clearance[0]" and verdicts[(0.5, 2.0)] == ""
    rows = res.summary().splitlines()
    row_03 = next(r for r in rows if r.strip().startswith("0.3 |"))
    assert row_03.split("|")[1:] == [f" {'skipped':>17s} ", f" {'path_clearance[0]':>17s}"]
    assert "  first failures: skipped: e_d_max <= epsilon = 0.5 (2), path_clearance[0] (1)" in rows


def test_small_e_d_max_is_skipped():
    res = search_region(load_scenario(PAPER_CURRENTS), e_o_max=(0.5,), e_d_max=(0.4, 3.0))
    assert res.tried[0].first_failure.startswith("skipped")


@pytest.mark.parametrize("kwargs, field", [
    (dict(e_o_max=(1.2,)), "e_o_max"),
    (dict(e_o_max=()), "e_o_max"),
    (dict(e_d_max=(-1.0,)), "e_d_max"),
    (dict(e_d_max=("far",)), "e_d_max"),
])
def test_bad_grids(kwargs, field):
    with pytest.raises(ConfigError, match=field):
        search_region(paper_scenario(), **kwargs)


@pytest.mark.slow
def test_cli_search_region_exit_codes(capsys):
    assert main(["certify", PAPER_CURRENTS, "--search-region"]) == 0
    assert "best: e_o_max = 0.9" in capsys.readouterr().out
    assert main(["certify", "--search-region"]) == 3
    assert "no region can help" in capsys.readouterr().out
