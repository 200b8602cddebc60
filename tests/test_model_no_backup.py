"""tubekit.model.no_backup: ``controller.backup = "none"``, a registered law that keeps the last command."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BACKUP_LAWS, BackupLaw, backup_law_from_dict
from tubekit.model.no_backup import NO_BACKUP_KIND, NoBackup

LAW = NoBackup()


def test_the_kind_is_registered_a_backup_law_that_adds_no_command_and_blends():
    assert BACKUP_LAWS["none"] is NoBackup and NO_BACKUP_KIND == "none" and isinstance(LAW, BackupLaw)
    assert not NoBackup.lateral and LAW.blends and LAW.bounds == (0.0, 0.0, 0.0)
    assert LAW.sway_bound == 0.0 and math.isinf(LAW.sway_release) and LAW.within(0.1, 0.1, 0.1)
    assert backup_law_from_dict({"kind": "none"}) == LAW and LAW.to_dict() == {"kind": "none"}


def test_a_parameter_the_law_does_not_have_is_refused_by_name():
    with pytest.raises(ConfigError, match=r"backup\.law: expected the parameters of a none law"):
        backup_law_from_dict({"kind": "none", "gain": 0.1})


@settings(max_examples=40, deadline=None, derandomize=True)
@given(x=st.floats(-50, 50), y=st.floats(-50, 50), psi=st.floats(-math.pi, math.pi),
       start=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.2, 0.2), st.floats(-0.3, 0.3)),
       elapsed=st.floats(0.0, 1e4))
def test_the_command_is_the_last_one_kept_whatever_the_state(x, y, psi, start, elapsed):
    """Property: wherever the vehicle is and however long after the hand-over, the command is the one applied at
    the hand-over, and no sway is commanded."""
    state, anchor = (x, y, -1.0, psi), (0.0, 0.0, -1.0)
    assert LAW.command(state, anchor, elapsed, start) == start
    assert LAW.lateral_command(state, anchor, elapsed, start) == (*start, 0.0)


def test_a_scenario_may_name_it():
    from tubekit import load_scenario
    import verify
    sc = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml").with_changes(**{"controller.backup": "none"})
    assert sc.controller.backup == "none"
