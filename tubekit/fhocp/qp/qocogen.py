"""qocogen, an opt-in QP backend: QOCO generated as C for the subproblem's sparsity pattern (takes cones).

The SCP's subproblem keeps one sparsity pattern for a whole run (:mod:`tubekit.fhocp.fastpath`), which is what a
code generator needs: on its first solve of a pattern the backend gets a solver for it from
:mod:`tubekit.fhocp.qp.generated` (built once per machine and cached, seconds; then loaded in milliseconds) and
afterwards copies the values into the buffers the library reads (A's zero rows and its cone rows gathered, P's upper
triangle, q and the two halves of b), whose addresses it was given once. QOCO's form is the same as
:class:`~tubekit.fhocp.qp.base.ConeProgramData`'s (:mod:`tubekit.fhocp.qp.qoco`). The statuses map through :data:`QOCOGEN_STATUS`; the generated QOCO detects no
infeasibility, so an infeasible subproblem ends at its iteration cap or in a numerical error: a failure that passes
no solution on. Needs ``pip install qocogen`` and a C compiler.
"""

from __future__ import annotations

import time
from types import MappingProxyType, ModuleType
from typing import Any, Mapping

from tubekit.exceptions import ConfigError, NotAvailableError
from tubekit.fhocp.qp.base import ConeProgramData, ConeSolution, QpBackend, checked_solution
from tubekit.fhocp.qp.generated import NO_COMPILER, SETTING_DEFAULTS, GeneratedSolver, build_solver, compiler
from tubekit.fhocp.result import Status, status_from

__all__ = ["QOCOGEN_STATUS", "REALTIME_QOCOGEN_SETTINGS", "QocogenBackend"]

#: The generated solver's ``enum qoco_custom_solve_status`` (in its order) -> :class:`Status`.
QOCOGEN_STATUS: dict[str, Status] = {
    "QOCO_CUSTOM_UNSOLVED": Status.SOLVER_ERROR,
    "QOCO_CUSTOM_SOLVED": Status.OPTIMAL,
    "QOCO_CUSTOM_SOLVED_INACCURATE": Status.OPTIMAL_INACCURATE,
    "QOCO_CUSTOM_NUMERICAL_ERROR": Status.SOLVER_ERROR,
    "QOCO_CUSTOM_MAX_ITER": Status.USER_LIMIT,
}
_RAW = tuple(QOCOGEN_STATUS)

#: What the FHOCP's real-time mode sets (:class:`tubekit.fhocp.scp.FHOCP`, through ``realtime_settings``), as it
#: sets Clarabel's: absolute and relative tolerance 1e-6. Chosen on the 15,025 recorded real-time subproblems of every
#: shipped scenario (``python benchmarks/qp_backends.py --qocogen-tolerances 1e-6 1e-5``): 0 failures, none
#: inaccurate, plans within 0.017 of the 1e-7 default's (Clarabel's real-time setting moved them by up to 0.031),
#: 13.1 iterations on average against 13.8; the exact plan check decides every plan. 1e-5 moved them by 0.075.
REALTIME_QOCOGEN_SETTINGS: Mapping[str, float] = MappingProxyType({"abstol": 1e-6, "reltol": 1e-6})


class QocogenBackend(QpBackend):
    """A generated QOCO solver per sparsity pattern (module doc).

    Parameters
    ----------
    settings : mapping, optional
        Overrides of the generated solver's settings (names of
        :data:`tubekit.fhocp.qp.generated.SETTING_DEFAULTS`: ``abstol``, ``reltol``, ``max_iters``, ...).
    """

    name = "qocogen"
    takes_cones = True
    package = "qocogen"
    pip_name = "qocogen"
    realtime_settings = REALTIME_QOCOGEN_SETTINGS

    def __init__(self, settings: Mapping[str, Any] | None = None) -> None:
        super().__init__(settings)
        self.load()
        for key, value in self.settings.items():
            if key not in SETTING_DEFAULTS:
                raise ConfigError("qocogen settings", f"names of the generated solver's settings "
                                  f"{tuple(SETTING_DEFAULTS)}", key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
                raise ConfigError(f"qocogen settings.{key}", "a number > 0", value)
        self._solver: GeneratedSolver | None = None
        self._key: Any = None

    @classmethod
    def load(cls) -> ModuleType | None:
        """qocogen (a try-import), or :class:`NotAvailableError` naming what is missing: the package or a C compiler."""
        module = super().load()
        if compiler() is None:
            raise NotAvailableError(NO_COMPILER)
        return module

    def solve(self, data: ConeProgramData) -> ConeSolution:
        """Build or load the solver on a new pattern, then solve ``data`` through its buffers."""
        if self._solver is None or self._key is not data.a_indices:
            self._setup(data)
        else:
            self.updates += 1
        t0 = time.perf_counter()  # the values handed over and the solve
        code, objective, iterations = self._solver.solve(data)
        wall = time.perf_counter() - t0
        raw = _RAW[code] if 0 <= code < len(_RAW) else f"code {code}"
        status = status_from(QOCOGEN_STATUS, raw)
        x = self._solver.x.copy() if status.solved else None
        return checked_solution(status, raw, x, objective + data.offset, wall, iterations, data.n)

    def _setup(self, data: ConeProgramData) -> None:
        """The generated solver of ``data``'s pattern (built, or loaded from the cache)."""
        self._solver = GeneratedSolver(build_solver(data), data, {**SETTING_DEFAULTS, **self.settings})
        self._key = data.a_indices
        self.setups += 1

    def reset(self) -> None:
        """Drop the loaded solver (the next solve loads it again from the cache)."""
        self._solver = None
        self._key = None
