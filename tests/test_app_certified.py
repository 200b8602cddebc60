"""tubekit.app.certified: certify or take a certificate; the campaign's certificates by input key, stored
and loaded back only through the checksum, design-key and scenario checks (issue 23)."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from tubekit import load_scenario
from tubekit.exceptions import ConfigError
from tubekit.app.certified import (IssuedCertificate, certify_design, input_key, issue_certificate, load_certificate,
                                   read_cached, write_cached)


@pytest.fixture(scope="module")
def scenario():
    import verify

    return load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml")


@pytest.fixture()
def stored(pc_cert) -> dict:
    """The certificate as a file would give it back (strict JSON, read again)."""
    return json.loads(json.dumps(pc_cert.to_dict()))


def _with_period(scenario, period: float):
    return scenario.with_changes(disturbance=replace(scenario.disturbance, period=period))


def test_the_input_key_ignores_what_certify_does_not_read_and_sees_the_start(scenario):
    key = input_key(scenario)
    assert len(key) == 64 and int(key, 16) >= 0
    assert input_key(scenario.with_changes(name="renamed")) == key
    assert input_key(_with_period(scenario, 3.0)) == key
    moved = list(scenario.initial_state)
    moved[0] += 0.01
    assert input_key(scenario.with_changes(initial_state=tuple(moved))) != key


def test_a_stored_certificate_loads_back_to_the_same_certificate_and_tightening(pc_cert, stored, scenario):
    design = load_certificate(stored, scenario)
    assert design.certificate == pc_cert
    assert design.certified == pc_cert.certified is True
    assert design.tightening.design_key == pc_cert.design_key
    # a scenario differing only in what certify does not read takes the same certificate
    assert load_certificate(stored, _with_period(scenario.with_changes(name="other"), 4.0)).certified


def _edited(d: dict, **changes) -> dict:
    return {**d, **changes}


def _resummed(d: dict) -> dict:
    from verify.certificate.jsonio import checksum_of

    return {**d, "checksum": checksum_of(d)}


def _design_edited(d: dict) -> dict:
    """The stored design's epsilon edited, the checksum re-stamped, the design key left."""
    inputs = {**d["inputs"], "scenario": {**d["inputs"]["scenario"], "epsilon": 0.45}}
    return _resummed({**d, "inputs": inputs})


def _rekeyed_for_another_epsilon(d: dict) -> dict:
    """A consistent certificate of another design (epsilon 0.45): key and checksum re-stamped."""
    from tubekit.design_inputs import DesignInputs
    inputs = {**d["inputs"], "scenario": {**d["inputs"]["scenario"], "epsilon": 0.45}}
    return _resummed({**d, "inputs": inputs, "design_key": DesignInputs.from_dict(inputs).key()})


@pytest.mark.parametrize("edit, other_scenario, field", [
    (lambda d: [d], None, r"^certificate: expected a certificate JSON object"),
    (lambda d: _edited(d, scenario="renamed after issue"), None, r"^certificate\.checksum: "),
    (_design_edited, None, r"^certificate\.design_key: expected the key of its design inputs"),
    (lambda d: d, {"initial_state": (-0.7, 3.1, 0.0, 0.1)}, r"^design_key\.initial_state: "),
    (lambda d: d, {"epsilon": 0.45}, r"^design_key\.epsilon: "),
    (_rekeyed_for_another_epsilon, None, r"^design_key\.epsilon: "),
])
def test_a_certificate_that_fails_a_check_is_refused_naming_it(stored, scenario, edit, other_scenario, field):
    target = scenario.with_changes(**other_scenario) if other_scenario else scenario
    with pytest.raises(ConfigError, match=field):
        load_certificate(edit(stored), target)


def test_issue_certificate_gives_the_key_a_checksummed_dict_and_the_best_effort_tightening(pc_cert, scenario):
    from verify.certificate.jsonio import checksum_of

    issued = issue_certificate(scenario)
    assert isinstance(issued, IssuedCertificate) and issued.key == input_key(scenario)
    assert issued.data["checksum"] == checksum_of(issued.data)
    assert issued.data["design_key"] == pc_cert.design_key
    assert issued.tightening.certified == pc_cert.certified
    assert certify_design(scenario, certificate=pc_cert).tightening.design_key == issued.tightening.design_key


def test_the_cache_stores_by_input_key_and_reads_back_through_the_checks(pc_cert, stored, scenario, tmp_path):
    folder = tmp_path / "certificates"
    assert read_cached(folder, scenario) is None
    issued = IssuedCertificate(input_key(scenario), stored, pc_cert.best_effort_tightening())
    path = write_cached(folder, issued)
    assert path == folder / f"{input_key(scenario)}.json"
    assert read_cached(folder, scenario.with_changes(name="same design")).certificate == pc_cert
    path.write_text(json.dumps(_edited(stored, scenario="edited")), encoding="utf-8")
    with pytest.raises(ConfigError, match=r"certificates/[0-9a-f]{64}\.json\.checksum: "):
        read_cached(folder, scenario)
    path.write_text("{not json", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"[0-9a-f]{64}\.json: expected a certificate JSON file"):
        read_cached(folder, scenario)
