"""verify.studies.rederive_tiers: the backup, the safe-only design and the tiers re-derived from the stored scenario."""

from __future__ import annotations

import dataclasses
import json

from verify.certificate.certify import Certificate
from verify.theorem.design import disturbance_bounds
from verify.studies.ledger import Ledger
from verify.studies.rederive import _region
from verify.studies.rederive_tiers import check_tiers, derive_tiers
from verify.theorem.tiers import tracking_design


def _derive(cert: Certificate):
    sc = cert.inputs.scenario
    region = _region(sc, cert)
    dist = disturbance_bounds(sc)
    design = tracking_design(sc, region, cert.gains, cert.design.sigma, dist)
    return design, derive_tiers(cert, sc, region, dist, design)


def test_an_issued_certificate_agrees(pc_cert, paper_cert):
    for cert in (pc_cert, paper_cert):
        design, tiers = _derive(cert)
        led = Ledger()
        derived = check_tiers(json.loads(json.dumps(cert.to_dict())), cert, design, tiers, led)
        assert derived == cert.tiers and all(c["ok"] for c in led.checks) and tiers.fresh is None
        assert (tiers.safe is None) is (cert.safe_design is None)


def test_a_smaller_safe_set_that_does_not_certify_is_named(pc_cert):
    small = dataclasses.replace(pc_cert.backup.safe_set, level=0.3)
    cert = dataclasses.replace(pc_cert, backup=dataclasses.replace(pc_cert.backup, safe_set=small))
    design, tiers = _derive(cert)
    assert not tiers.backup.certified and tiers.fresh.safe_set == pc_cert.backup.safe_set
    led = Ledger()
    raw = json.loads(json.dumps(pc_cert.to_dict()))
    derived = check_tiers(raw, cert, design, tiers, led)
    failed = [c["name"] for c in led.checks if not c["ok"]]
    assert "backup.safe_set" in failed and "tiers.safe" in failed and derived.safe is False


def test_a_law_that_does_not_certify_is_named(pc_cert):
    slow = dataclasses.replace(pc_cert.backup.law, surge=0.1)
    cert = dataclasses.replace(pc_cert, backup=dataclasses.replace(pc_cert.backup, law=slow))
    design, tiers = _derive(cert)
    led = Ledger()
    check_tiers(json.loads(json.dumps(pc_cert.to_dict())), cert, design, tiers, led)
    assert "backup.law" in [c["name"] for c in led.checks if not c["ok"]]
