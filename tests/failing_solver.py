"""A solver factory for the loop whose FHOCP fails at a window of periods: the replay runs out and the backup takes
over from a moving vehicle (shared by the loop's and the dynamic certificate's tests)."""

from __future__ import annotations

from tubekit.exceptions import SolverError
from tubekit.fhocp import FHOCP


def failing_between(first: int, last: int) -> type:
    """A ``solver_factory`` class: the scenario's FHOCP, raising :class:`SolverError` at the periods [first, last)."""

    class _Failing:
        def __init__(self, scenario, tightening) -> None:
            self.inner, self.k = FHOCP(scenario, tightening), 0

        def solve(self, t, state, obstacles, v_last=None):
            self.k += 1
            if first <= self.k - 1 < last:
                raise SolverError("injected")
            return self.inner.solve(t, state, obstacles, v_last=v_last)

    return _Failing
