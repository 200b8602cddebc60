"""The design search: its headline numbers agree with direct certification."""

from __future__ import annotations

import pytest

import verify
from tubekit.exceptions import ConfigError
from verify.region import Region


@pytest.fixture(scope="module")
def env():
    return verify.envelope(verify.certifiable_scenario(), "corrected", quick=True)


def test_largest_omega_bar_is_the_edge(env):
    """Just below the reported largest omega-bar the scenario certifies; clearly above it, it does not."""
    sc = verify.certifiable_scenario()
    assert env.certified_at_scenario and env.max_omega_bar is not None
    base = Region.from_scenario(sc)
    assert verify.certify(sc, "corrected", region=base.replace(omega_bar=0.98 * env.max_omega_bar)).certified
    assert not verify.certify(sc, "corrected", region=base.replace(omega_bar=1.10 * env.max_omega_bar)).certified
    assert env.max_omega_bar >= sc.disturbance.omega_bar  # the scenario itself certifies


def test_plot_is_written(env, tmp_path):
    path = verify.plot_envelope(env, tmp_path / "env.png")
    assert path.stat().st_size > 10_000


def test_paper_law_has_no_envelope_toward_target():
    env = verify.envelope(verify.certifiable_scenario(), "paper", quick=True)
    assert not env.certified_at_scenario and env.max_omega_bar is None


def test_bad_law():
    with pytest.raises(ConfigError, match="law"):
        verify.envelope(verify.certifiable_scenario(), "pid")
