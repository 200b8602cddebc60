"""Certificates derived with steps of the velocity loop's bound switched off (a helper, not a test module)."""

from __future__ import annotations

import contextlib
import math
from typing import Iterator

from tubekit.scenario import Scenario
from verify.certificate.certify import Certificate, certify

__all__ = ["fresh_solutions", "certified_with_steps_off", "STEP_5B", "STEP_5C"]

#: The functions of ``verify.vehicle.bound`` that give the second (step 5b: one output) and third (step 5c: a
#: channel's four outputs) decompositions.
STEP_5B, STEP_5C = "_mass_in_state", "_in_cells"
#: What each gives when switched off: no bound.
_OFF = {STEP_5B: math.inf, STEP_5C: (math.inf,) * 4}


@contextlib.contextmanager
def fresh_solutions() -> Iterator[None]:
    """The memo of dynamic solutions (``verify.vehicle.compose``) cleared on entry and on exit, so no other test
    sees what is certified inside (a certificate derived under a patch)."""
    import verify.vehicle.compose as compose
    compose._SOLVED.clear()
    try:
        yield
    finally:
        compose._SOLVED.clear()


def certified_with_steps_off(monkeypatch, scenario: Scenario, steps: tuple[str, ...]) -> Certificate:
    """``scenario`` certified with each of the loop bound's decompositions in ``steps`` (:data:`STEP_5B`,
    :data:`STEP_5C`) giving no bound, inside :func:`fresh_solutions`."""
    import verify.vehicle.bound as bound
    for step in steps:
        monkeypatch.setattr(bound, step, lambda *args, _off=_OFF[step]: _off)
    with fresh_solutions():
        return certify(scenario)
