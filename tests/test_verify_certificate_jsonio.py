"""verify.certificate.jsonio: the checksum over the canonical content (an integrity check, not a signature)."""

from __future__ import annotations

import hashlib
import json

from verify.certificate.jsonio import NOT_CHECKSUMMED, checksum_of


def test_the_checksum_is_sha256_of_the_sorted_content_without_itself_and_the_wall_time():
    d = {"b": [1.5, None], "a": {"y": 1, "x": "é"}, "elapsed_s": 0.3, "checksum": "old"}
    expected = hashlib.sha256('{"a":{"x":"é","y":1},"b":[1.5,null]}'.encode()).hexdigest()
    assert checksum_of(d) == expected
    assert set(NOT_CHECKSUMMED) == {"checksum", "elapsed_s"}


def test_key_order_and_json_text_do_not_matter_but_values_do():
    d = {"x": 0.1, "y": [1, 2]}
    again = json.loads(json.dumps({"y": [1, 2], "x": 0.1}, indent=4))
    assert checksum_of(again) == checksum_of(d)
    assert checksum_of({"x": 0.1000000001, "y": [1, 2]}) != checksum_of(d)
    assert checksum_of(dict(d, elapsed_s=9.0)) == checksum_of(d)


def test_a_certificate_written_and_read_back_keeps_its_checksum(pc_cert):
    d = pc_cert.to_dict()
    assert checksum_of(json.loads(json.dumps(d, indent=2))) == d["checksum"]
