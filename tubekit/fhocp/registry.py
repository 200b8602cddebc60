"""The FHOCP backends by name: ``name -> factory(scenario, tightening)`` returning a :class:`FhocpSolver`.

Built in:

* ``"scp"`` (default) — :class:`tubekit.fhocp.scp.FHOCP` in ``scenario.controller.fhocp_mode``
  with default :class:`~tubekit.fhocp.options.ScpOptions`;
* ``"ipopt"`` — :class:`tubekit.fhocp.ipopt.IpoptFHOCP`, the CasADi + IPOPT peer (optional:
  without CasADi, :class:`~tubekit.exceptions.NotAvailableError` with the install hint);
* ``"scp-piqp"`` — the SCP solver with ``ScpOptions(qp_solver="piqp")``: PIQP on the QP relaxation,
  checked against the cones, else Clarabel (:mod:`tubekit.fhocp.qp.relaxed`; opt-in, needs PIQP);
* ``"scp-qoco"`` — the SCP solver with ``ScpOptions(qp_solver="qoco")``: QOCO on the whole cone program
  (:mod:`tubekit.fhocp.qp.qoco`; opt-in, needs QOCO);
* ``"scp-qocogen"`` — the SCP solver with ``ScpOptions(qp_solver="qocogen")``: QOCO generated as C for the
  subproblem's sparsity pattern, built once per machine (:mod:`tubekit.fhocp.qp.qocogen`; opt-in, needs qocogen
  and a C compiler).

The closed loop builds its solver with :func:`make_solver` from
``scenario.controller.fhocp_backend``; :func:`register_backend` adds a backend.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from tubekit.exceptions import ConfigError
from tubekit.fhocp.ipopt import IpoptFHOCP, import_casadi
from tubekit.fhocp.options import ScpOptions
from tubekit.fhocp.qp.registry import get_qp_backend
from tubekit.fhocp.result import FhocpSolver, SolverFactory
from tubekit.fhocp.scp import FHOCP, obstacle_slots

if TYPE_CHECKING:
    from tubekit.scenario import Scenario
    from tubekit.tightening import Tightening

__all__ = ["DEFAULT_BACKEND", "backends", "get_backend", "register_backend", "make_solver"]

#: The backend of a scenario that names none.
DEFAULT_BACKEND = "scp"


def _scp(scenario: Scenario, tightening: Tightening) -> FhocpSolver:
    """The SCP solver in the scenario's FHOCP mode, default options."""
    return FHOCP(scenario, tightening)


def _ipopt(scenario: Scenario, tightening: Tightening) -> FhocpSolver:
    """The CasADi + IPOPT peer with the scenario's terminal mode and obstacle slots."""
    import_casadi()  # NotAvailableError with the install hint before anything is built
    return IpoptFHOCP(scenario, tightening, max_obstacles=obstacle_slots(scenario),
                      terminal=scenario.controller.terminal_mode)


def _scp_on(qp_solver: str) -> SolverFactory:
    """The factory of the SCP solver whose subproblems the opt-in QP backend ``qp_solver`` solves (same answers as
    ``scp`` to the solvers' tolerances)."""

    def factory(scenario: Scenario, tightening: Tightening) -> FhocpSolver:
        get_qp_backend(qp_solver, "backend")  # NotAvailableError with the install hint before anything is built
        return FHOCP(scenario, tightening, options=ScpOptions(qp_solver=qp_solver))

    return factory


_BACKENDS: dict[str, SolverFactory] = {"scp": _scp, "ipopt": _ipopt, "scp-piqp": _scp_on("piqp"),
                                       "scp-qoco": _scp_on("qoco"), "scp-qocogen": _scp_on("qocogen")}


def backends() -> tuple[str, ...]:
    """The registered backend names, in registration order."""
    return tuple(_BACKENDS)


def register_backend(name: str, factory: SolverFactory, *, replace: bool = False) -> None:
    """Register ``factory(scenario, tightening) -> FhocpSolver`` as backend ``name``.

    Raises
    ------
    ConfigError
        An empty or non-str name, a factory that is not callable, or a taken name without ``replace``.
    """
    if not isinstance(name, str) or not name:
        raise ConfigError("name", "a non-empty backend name", name)
    if not callable(factory):
        raise ConfigError("factory", "a callable factory(scenario, tightening)", factory)
    if name in _BACKENDS and not replace:
        raise ConfigError("name", f"a name not yet registered (taken: {backends()}), or replace=True", name)
    _BACKENDS[name] = factory


def get_backend(name: str, field: str = "controller.fhocp_backend") -> SolverFactory:
    """The factory registered as ``name``; :class:`ConfigError` (``field``) listing the names otherwise."""
    factory = _BACKENDS.get(name) if isinstance(name, str) else None
    if factory is None:
        raise ConfigError(field, f"one of the FHOCP backends {backends()}", name)
    return factory


def make_solver(scenario: Scenario, tightening: Tightening, backend: str | None = None) -> FhocpSolver:
    """The solver of backend ``backend`` (default ``scenario.controller.fhocp_backend``) for this problem."""
    name = scenario.controller.fhocp_backend if backend is None else backend
    return get_backend(name, "controller.fhocp_backend" if backend is None else "backend")(scenario, tightening)
