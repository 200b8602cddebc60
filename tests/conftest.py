"""Shared test configuration: hypothesis profiles and the reduced-size flag.

Profiles: ``ci`` (default; derandomized, quick) and ``thorough``
(``pytest --hypothesis-profile=thorough``).
"""

from __future__ import annotations

import os
from dataclasses import replace

import matplotlib
import pytest

matplotlib.use("Agg")

from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile(
    "ci", derandomize=True, max_examples=40, deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "thorough", derandomize=False, max_examples=1000, deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# Tutorials and examples honour this flag to run at reduced sizes in the test suite.
os.environ.setdefault("TUBEKIT_QUICK", "1")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Tests marked ``slow`` run first, the longest first (``@pytest.mark.slow(seconds)``: a rough length, only an
    ordering hint; otherwise the collection's order, the sort being stable): with pytest-xdist's work stealing the
    long ones then start while every worker still has a queue, and the run does not end on one worker finishing a
    long test while the other idles. The order is deterministic, as every worker must see the same one."""
    def key(item: pytest.Item) -> tuple[bool, float]:
        slow = item.get_closest_marker("slow")
        return slow is None, -float(slow.args[0]) if slow is not None and slow.args else 0.0
    items.sort(key=key)


# ---- certificates shared by several test modules (computed once per session) -------------------------------
@pytest.fixture(scope="session")
def pc_cert():
    """The certificate of verify/scenarios/paper_currents.toml (certified)."""
    import verify
    from tubekit import load_scenario
    return verify.certify(load_scenario(verify.SCENARIOS_DIR / "paper_currents.toml"))


@pytest.fixture(scope="session")
def paper_cert():
    """The certificate of the paper's Section VI scenario (not certified)."""
    import verify
    from tubekit import paper_scenario
    return verify.certify(paper_scenario())


@pytest.fixture(scope="session")
def stationary():
    """verify.certifiable_scenario() with a stationary target (trajectory rate 0) and obstacles at (+-3, 0, 0) r 0.4
    (the promises' tests place the vehicle against them)."""
    import verify
    from tubekit.scenario import Obstacle
    sc = verify.certifiable_scenario()
    return sc.with_changes(trajectory=replace(sc.trajectory, rate=0.0),
                           obstacles=(Obstacle((3.0, 0.0, 0.0), 0.4), Obstacle((-3.0, 0.0, 0.0), 0.4)))


@pytest.fixture(scope="session")
def keep_moving_cert():
    """The certificate of examples/keep_moving.toml: a minimum surge with the loiter (safe tier only)."""
    import verify
    from pathlib import Path
    from tubekit import load_scenario
    return verify.certify(load_scenario(Path(__file__).resolve().parents[1] / "examples" / "keep_moving.toml"))
