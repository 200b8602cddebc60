"""Shared test configuration: hypothesis profiles and the reduced-size flag.

Profiles: ``ci`` (default; derandomized, quick) and ``thorough``
(``pytest --hypothesis-profile=thorough``).
"""

from __future__ import annotations

import gc
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


_FULL_COLLECTION_SINCE_FREEZE = [False]
_FROZEN_AFTER_RECLAIM = [100_000]  # objects frozen right after the last reclaim (a floor at the start)


def _note_full_collection(phase: str, info: dict[str, int]) -> None:
    """A ``gc.callbacks`` entry: notes that a full (generation-2) collection has finished."""
    if phase == "stop" and info.get("generation") == 2:
        _FULL_COLLECTION_SINCE_FREEZE[0] = True


gc.callbacks.append(_note_full_collection)


def pytest_runtest_logfinish(nodeid: str, location: tuple[str, int | None, str]) -> None:
    """After a test during which a full collection ran, its survivors leave the collector's reach (:func:`gc.freeze`).

    A worker's heap grows to over a million long-lived objects (sympy's caches, compiled laws, session
    certificates); every later full collection, and every ``gc.collect()`` a benchmark makes before timing,
    would walk them all again (measured: 59 s of the two workers' 893 s of CPU went to collections; 18 s with
    this). Objects freed by their reference count are still freed; cycles that die after being frozen stay
    allocated until the frozen count doubles, when one full collection over everything reclaims them (a few times
    a session)."""
    if not _FULL_COLLECTION_SINCE_FREEZE[0]:
        return
    if gc.get_freeze_count() > 2 * _FROZEN_AFTER_RECLAIM[0]:  # reclaim the frozen cycles once their count doubles
        gc.unfreeze()
        gc.collect()
        gc.freeze()
        _FROZEN_AFTER_RECLAIM[0] = gc.get_freeze_count()
    else:
        gc.freeze()
    _FULL_COLLECTION_SINCE_FREEZE[0] = False  # after the reclaim's own collection: its survivors are frozen already


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
