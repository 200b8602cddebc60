"""verify.backup.none: no backup law, the safe tier as the tracking tier's corollary (docs/verify.md step 13g)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import verify
from tubekit import load_scenario
from tubekit.exceptions import ConfigError
from tubekit.model.backup import SafeSet
from tubekit.model.no_backup import POINT_SET, NoBackup
from tubekit.scenario import Obstacle
from tubekit.tiers import Tiers
from verify.backup import BACKUP_PROOFS, NO_BACKUP_PROOF, certify_none
from verify.studies.recheck import recheck

from .corners import at_corner

ROOT = Path(__file__).resolve().parents[1]
NO_BACKUP = ROOT / "examples" / "bluerov2_no_backup.toml"
PC = load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")
POINT = SafeSet(level=POINT_SET, shape=0.0, depth=POINT_SET)


@pytest.fixture(scope="module")
def no_backup_cert():
    return verify.certify(load_scenario(NO_BACKUP))


def test_the_proof_is_registered_and_certifies_a_point_with_one_condition_and_no_command_change():
    assert BACKUP_PROOFS["none"] is NO_BACKUP_PROOF
    bc = NO_BACKUP_PROOF.design(omega_xy=0.1, omega_z=0.1, limits=(0.3, 0.1, 0.2), tick=0.01,
                                handover=(0.1, 0.1))
    assert bc.certified and bc.law == NoBackup() and bc.safe_set == POINT
    assert [c.condition for c in bc.conditions] == ["backup_none"]
    kw = dict(omega_xy=0.1, omega_z=0.1, limits=(0.3, 0.1, 0.2), loop_error=(0.01, 0.01, 0.01))
    assert NO_BACKUP_PROOF.command_rate(bc.law, POINT, **kw) == (0.0, 0.0, 0.0)
    assert NO_BACKUP_PROOF.tick_change(bc.law, POINT, tick=0.01, **kw) == (0.0, 0.0, 0.0)
    assert NO_BACKUP_PROOF.sway_change(bc.law, POINT, tick=0.01, **kw) == 0.0


def test_another_law_is_refused_by_name():
    with pytest.raises(ConfigError, match=r"backup\.kind: expected a 'none' law"):
        certify_none(verify.certify(PC).backup.law, POINT, omega_xy=0.1, omega_z=0.1, tick=0.01)


def test_the_safe_tier_is_given_only_with_the_tracking_tier():
    """The paper's obstacles on the target's circle refuse tracking (``path_clearance``): with station keeping the
    safe tier still holds by the backup's own proof; without a backup it is refused too, every tracking condition
    being one of its own. Where tracking holds, both hold."""
    rocks = PC.with_changes(obstacles=(Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((-3.0, 0.0, 0.0), 0.4)))
    kept = verify.certify(rocks)
    assert kept.tiers == Tiers(True, False)
    none = verify.certify(rocks.with_changes(**{"controller.backup": "none"}))
    assert none.tiers == Tiers(False, False) and {"path_clearance[0]", "path_clearance[1]"} <= {
        c.condition for c in none.failures}
    assert set(none.tier_failures["safe"]) == set(none.tier_failures["tracking"])
    free = verify.certify(PC.with_changes(**{"controller.backup": "none"}))
    assert free.tiers == Tiers(True, True) and free.backup.law == NoBackup()


@pytest.mark.slow
def test_without_a_backup_the_rocks_may_come_to_x_f_s_reach_and_the_box_widen(no_backup_cert):
    """examples/bluerov2_no_backup.toml (±15 % of every coefficient, rocks 10 m beside the path): both tiers, the
    completion's footprint being X_f's reach; with station keeping the same scenario keeps only the safe tier (the
    loop's cells of step 5c close its bound), its safe set too wide for the rocks beside the path, and at the ±10 % box and rocks 23 m away of
    examples/bluerov2_brisk_tracked.toml station keeping's loop error is above this one in every channel. A rock 7 m
    off is inside X_f's reach even from a start 5 m behind (at 8 m both tiers hold from there, with the line-of-sight
    feedforward's narrower set, docs/verify.md step 17e)."""
    assert no_backup_cert.tiers == Tiers(True, True)
    law = no_backup_cert.design.terminal
    assert no_backup_cert.backup.safe_set == POINT and law.d_hi + 0.4 < 10.0
    sk = verify.certify(load_scenario(NO_BACKUP).with_changes(**{"controller.backup": "station_keeping"}))
    assert sk.tiers == Tiers(True, False) and {"path_clearance[0]", "path_clearance[1]"} <= {
        c.condition for c in sk.failures}
    brisk = verify.certify(load_scenario(ROOT / "examples" / "bluerov2_brisk_tracked.toml"))
    assert all(a < b for a, b in zip(no_backup_cert.velocity_loop.error, brisk.velocity_loop.error))
    nearer = load_scenario(NO_BACKUP).with_changes(obstacles=(Obstacle((8.0, 7.0, 0.0), 0.4),),
                                                   initial_state=(-5.0, 0.0, 0.0, 0.0))
    assert "path_clearance[0]" in [c.condition for c in verify.certify(nearer).failures]


def test_recheck_confirms_it_and_catches_a_law_the_scenario_does_not_name(no_backup_cert):
    """Re-derived, every stored number agrees; a station-keeping certificate whose law is edited to ``none`` (its
    checksum aside) disagrees by name: the scenario names another law, and the proof's conditions differ."""
    assert recheck(json.loads(json.dumps(no_backup_cert.to_dict()))).ok
    raw = json.loads(json.dumps(verify.certify(PC).to_dict()))
    raw["backup"]["law"] = {"kind": "none"}
    res = recheck(raw)
    assert not res.ok and {"backup.law.kind", "conditions[backup_none]"} <= {f["name"] for f in res.failed}


def test_flown_at_a_corner_of_the_box_both_tiers_are_kept_and_no_law_ever_runs(no_backup_cert):
    """20 s of examples/bluerov2_no_backup.toml with the hull at the box's upper corner: a plan at every period,
    every promise of both tiers kept, the backup never active."""
    import tubekit
    run = tubekit.simulate(at_corner(load_scenario(NO_BACKUP), 1), no_backup_cert, duration=20.0, progress=False)
    promises = {p.name: p for p in tubekit.check_promises(run)}
    assert all(p.ok for p in promises.values() if p.given), [p for p in promises.values() if p.given and not p.ok]
    assert promises["plan_available"].ok and not run.backup_active.any()


def test_with_no_plan_and_no_backup_the_last_command_is_kept_and_the_broken_promise_reported():
    """The counterexample the certificate does not cover: the FHOCP failing for 2 s with the candidate off (the
    tracking theorem's premise, a plan at every period, broken by construction): the law keeps the command applied
    last, and the run reports the broken premise (``recursive_feasibility``: no candidate stood in)."""
    from tubekit.loop.closed_loop import run_closed_loop
    from tubekit.loop.promises import check_promises

    from .failing_solver import failing_between
    sc = load_scenario(NO_BACKUP).with_changes(duration=6.0, **{"controller.candidate": False})
    cert = verify.certify(load_scenario(NO_BACKUP))
    res = run_closed_loop(sc, tightening=cert.tightening, solver_factory=failing_between(20, 40), progress=False)
    on = np.flatnonzero(res.backup_active[:-1])
    assert on.size > 0
    np.testing.assert_array_equal(res.inputs[on], np.repeat(res.inputs[on[0] - 1][None, :], on.size, axis=0))
    broken = {p.name for p in check_promises(res) if p.given and not p.ok}
    assert broken == {"recursive_feasibility"}
