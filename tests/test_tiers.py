"""tubekit.tiers: the two tiers of promise as one typed value."""

from __future__ import annotations

import pytest

from tubekit.exceptions import ConfigError
from tubekit.tiers import Tiers


@pytest.mark.parametrize("tiers, safe_only, both, label", [
    (Tiers(), False, False, "no tier"),
    (Tiers(True, False), True, False, "safe tier only"),
    (Tiers(True, True), False, True, "both tiers"),
])
def test_each_combination_reads_as_it_means(tiers, safe_only, both, label):
    assert (tiers.safe_only, tiers.both, tiers.label()) == (safe_only, both, label)
    assert Tiers.from_dict(tiers.to_dict()) == tiers


ERRORS = [
    (lambda: Tiers(False, True), r"tiers\.tracking: expected false when the safe tier is not given"),
    (lambda: Tiers(1, 0), r"tiers\.safe: expected true or false"),
    (lambda: Tiers.from_dict({"safe": True}), r"tiers\.tracking: expected true or false, received 'missing'"),
    (lambda: Tiers.from_dict([True, True]), r"tiers: expected a table"),
]


@pytest.mark.parametrize("build, match", ERRORS)
def test_impossible_tiers_are_refused(build, match):
    with pytest.raises(ConfigError, match=match):
        build()
