"""verify.backup.protocol: the proof of a backup-law kind, its registry, and a second law plugged in (issue 30)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

import pytest

from tubekit.exceptions import ConfigError
from tubekit.model.backup import BACKUP_LAWS, SafeSet, StationKeeping, backup_law_from_dict
from verify.backup import (BACKUP_PROOFS, DEFAULT_BACKUP_KIND, STATION_KEEPING_PROOF, BackupCertificate, BackupProof,
                           StationKeepingProof, backup_command_rate, backup_tick_change, certify_backup, proof_for,
                           register_backup_proof)

LAW = StationKeeping(surge=0.3, yaw_rate=0.2, yaw_band=0.3, heave=0.15, heave_band=1.0, surge_fade=2.0,
                     yaw_fade=2.0, ramp=5.0, yaw_law="continuous", unstable=0.6)
SAFE = SafeSet(level=5.0, shape=1.0, depth=2.0)
BOUNDS = dict(omega_xy=0.1, omega_z=0.05, limits=(0.3, 0.15, 0.2))


def test_station_keeping_is_the_first_registered_proof():
    assert isinstance(STATION_KEEPING_PROOF, BackupProof) and isinstance(STATION_KEEPING_PROOF, StationKeepingProof)
    assert BACKUP_PROOFS[StationKeeping.kind] is STATION_KEEPING_PROOF
    assert proof_for(LAW) is proof_for("station_keeping") is proof_for(DEFAULT_BACKUP_KIND) is STATION_KEEPING_PROOF


def test_the_station_keeping_proof_is_its_modules_functions():
    """Each step of the protocol is the function of its module, number for number."""
    p = STATION_KEEPING_PROOF
    kw = dict(BOUNDS, tick=0.01, handover=(0.1, 0.05), yaw_rate_error=0.02)
    assert p.certify(LAW, SAFE, **kw) == certify_backup(LAW, SAFE, **kw)
    loop = dict(BOUNDS, loop_error=(0.01, 0.01, 0.02))
    assert p.command_rate(LAW, SAFE, **loop) == backup_command_rate(LAW, SAFE, **loop)
    assert p.tick_change(LAW, SAFE, **loop, tick=0.01) == backup_tick_change(LAW, SAFE, **loop, tick=0.01)
    cert = p.certify(LAW, SAFE, **kw)
    assert cert.summary_lines()[0].startswith("backup (station keeping): ")


@pytest.mark.parametrize("what", ["hover", 3, None, object()])
def test_a_kind_without_a_proof_is_refused_by_name(what):
    with pytest.raises(ConfigError, match=r"backup\.kind"):
        proof_for(what)


def test_registration_is_refused_for_a_non_proof_an_unknown_kind_or_a_taken_kind():
    with pytest.raises(ConfigError, match=r"backup\.proof"):
        register_backup_proof(object())

    class Unknown(StationKeepingProof):
        kind = "no_such_law"
    with pytest.raises(ConfigError, match=r"backup\.kind"):
        register_backup_proof(Unknown())
    with pytest.raises(ConfigError, match=r"backup\.kind"):
        register_backup_proof(StationKeepingProof())  # another object for station keeping
    assert register_backup_proof(STATION_KEEPING_PROOF) is STATION_KEEPING_PROOF  # the same one again: no change


def test_a_stored_law_reads_back_by_kind_and_without_one():
    cert = certify_backup(LAW, SAFE, **BOUNDS, tick=0.01, handover=(0.1, 0.05))
    d = cert.to_dict()
    assert d["law"]["kind"] == "station_keeping"
    assert BackupCertificate.from_dict(d) == cert
    del d["law"]["kind"]
    assert BackupCertificate.from_dict(d) == cert
    d["law"]["kind"] = "spiral"
    with pytest.raises(ConfigError, match=r"certificate\.backup\.law\.kind"):
        BackupCertificate.from_dict(d)
    d["law"]["kind"] = "station_keeping"
    del d["law"]["surge"]
    with pytest.raises(ConfigError, match=r"certificate\.backup\.law\.surge"):
        BackupCertificate.from_dict(d)


# ---- a second backup law: one model class and one proof, nothing else changes ---------------------------------

@dataclass(frozen=True)
class Hover(StationKeeping):
    """A second kind (for the test: station keeping's evaluation under another name)."""

    kind: ClassVar[str] = "hover_test"


class SpyProof:
    """The proof of ``hover_test``: station keeping's, recording which step was asked for."""

    kind = Hover.kind

    def __init__(self) -> None:
        self.calls: list[str] = []

    def design(self, **kw) -> BackupCertificate:
        self.calls.append("design")
        cert = STATION_KEEPING_PROOF.design(**kw)
        fields = {f.name: getattr(cert.law, f.name) for f in dataclasses.fields(cert.law)}
        return dataclasses.replace(cert, law=Hover(**fields))

    def certify(self, law, safe, **kw) -> BackupCertificate:
        self.calls.append("certify")
        return STATION_KEEPING_PROOF.certify(law, safe, **kw)

    def command_rate(self, law, safe, **kw) -> tuple[float, float, float]:
        self.calls.append("command_rate")
        return STATION_KEEPING_PROOF.command_rate(law, safe, **kw)

    def tick_change(self, law, safe, **kw) -> tuple[float, float, float]:
        self.calls.append("tick_change")
        return STATION_KEEPING_PROOF.tick_change(law, safe, **kw)

    def sway_change(self, law, safe, **kw) -> float:
        self.calls.append("sway_change")
        return STATION_KEEPING_PROOF.sway_change(law, safe, **kw)

    def summary_lines(self, cert: BackupCertificate) -> list[str]:
        return [f"backup (hover): {'certified' if cert.certified else 'NOT certified'}"]


@pytest.fixture
def hover(monkeypatch):
    """``hover_test`` registered as a law and a proof for one test (both registries restored after it)."""
    spy = SpyProof()
    monkeypatch.setitem(BACKUP_LAWS, Hover.kind, Hover)
    monkeypatch.setitem(BACKUP_PROOFS, Hover.kind, spy)
    assert register_backup_proof(spy) is spy
    return spy


def test_a_second_law_round_trips_and_speaks_for_itself(hover):
    law = Hover(**{f.name: getattr(LAW, f.name) for f in dataclasses.fields(LAW)})
    assert proof_for(law) is hover and law.to_dict()["kind"] == "hover_test"
    assert backup_law_from_dict(law.to_dict()) == law
    cert = hover.certify(law, SAFE, **BOUNDS, tick=0.01, handover=(0.1, 0.05))
    again = BackupCertificate.from_dict(cert.to_dict())
    assert again == cert and type(again.law) is Hover
    assert cert.summary_lines() == ["backup (hover): certified"]


def test_the_theorem_and_the_loop_bound_go_through_the_registry(hover, pc_cert):
    """backup_of designs the asked kind, recertify_backup proves a stored law by its kind, and the dynamic plant's
    loop bound charges the law's own tick change: each through the registered proof."""
    from tubekit.scenario import load_scenario
    from verify.theorem.tiers import backup_of, recertify_backup
    from verify.vehicle.compose import loop_for_law
    sc, dist, margins = pc_cert.inputs.scenario, pc_cert.disturbance, pc_cert.design.margins
    designed = backup_of(sc, dist, margins, kind=Hover.kind)
    # designed, then proved again for the anchor's reach (the room the safe set leaves past the margins)
    assert hover.calls == ["design", "certify"] and type(designed.law) is Hover
    assert designed.safe_set == pc_cert.backup.safe_set and designed.conditions == pc_cert.backup.conditions
    again = recertify_backup(sc, designed.law, designed.safe_set, dist, margins, designed.anchor_reach)
    assert hover.calls == ["design", "certify", "certify"] and again == designed
    slow = load_scenario("examples/bluerov2_slow.toml")
    loop = loop_for_law(slow, Hover(**{f.name: getattr(LAW, f.name) for f in dataclasses.fields(LAW)}), SAFE,
                        (0.05, 0.02, 0.08), 0.0, 0.01)
    assert hover.calls[-1] == "tick_change" and loop.loop.jump_tick != (0.0, 0.0, 0.0)
