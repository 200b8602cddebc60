"""The SCP solver's options (:class:`ScpOptions`): one frozen, validated value instead of eleven keywords.

``FHOCP(scenario, tightening, mode, options=ScpOptions(...))``; every field has the
default the solver always had (but ``rate_penalty``, new, on by default: ``rate_penalty=0`` gives
the earlier problem), and a bad value is a :class:`~tubekit.exceptions.ConfigError`
naming the field when the options are made, before any problem is built.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, Mapping

from tubekit.exceptions import ConfigError
from tubekit.fhocp.qp.registry import DEFAULT_QP_BACKEND, qp_backend_names
from tubekit.scenario import TerminalMode
from tubekit.validation import choice, nonnegative, positive

__all__ = ["ScpOptions", "DEFAULT_RATE_PENALTY"]

#: The rate penalty's default weight lambda (s): damps the real-time SCP's alternating plans (issue 24 item 8),
#: measured by the ``sign_flips_per_s`` metric of :mod:`tubekit.loop.metrics`.
DEFAULT_RATE_PENALTY = 10.0


def _count(name: str, value: object, minimum: int, expected: str) -> int:
    """``value`` if it is an int >= ``minimum`` (bool rejected), else :class:`ConfigError` (``expected``)."""
    if not isinstance(value, int) or isinstance(value, bool) or value < minimum:
        raise ConfigError(name, expected, value)
    return value


@dataclass(frozen=True)
class ScpOptions:
    """Options of :class:`tubekit.fhocp.scp.FHOCP` (all validated on construction).

    Parameters
    ----------
    max_obstacles : int or None
        Obstacle slots in the compiled problem (the nearest detected obstacles are kept,
        with a warning when some do not fit); ``None``: :func:`tubekit.fhocp.scp.obstacle_slots`
        of the scenario (1 for the paper's).
    terminal : TerminalMode or None
        Terminal-set handling ``"soft"``, ``"hard"`` or ``"off"`` (see :mod:`tubekit.fhocp.convex`);
        ``None``: ``scenario.controller.terminal_mode``.
    penalty : float
        Exact-penalty weight of the state-constraint slacks (> 0).
    terminal_penalty : float or None
        Weight of the terminal slack (> 0); ``None``: ``penalty / 20``.
    max_iterations : int
        Converged mode: most convex subproblems per warm-started solve (>= 1).
    cold_start_iterations : int
        Most subproblems of a solve without a previous plan (>= 1).
    tolerance : float
        Converged mode stops when the predicted merit decrease, or the decrease of
        an accepted step, is below ``tolerance * max(1, |merit|)``, or the input
        step below ``tolerance * V-bar`` (> 0).
    trust_radius : float
        Input trust region as a fraction of V-bar per component (> 0; in converged
        mode the initial radius, adapted by the ratio test).
    extrapolate : bool
        Converged mode: stretch accurately predicted steps by a merit line search.
    fast_path : bool
        Re-solve through the compiled map + a persistent QP backend (``qp_solver``); False uses
        ``problem.solve(solver=cp.CLARABEL)`` (same problem, slower).
    clarabel_settings : mapping or None
        Overrides of :data:`tubekit.fhocp.convex.DEFAULT_CLARABEL_SETTINGS` / Clarabel's settings
        (kept read-only).
    rate_penalty : float
        lambda (s, >= 0) of the rate penalty lambda sum_c R_c (sum_k (v_k,c - v_{k-1},c)^2 + (v_0,c -
        v_last,c)^2) in the cost (:mod:`tubekit.fhocp.rows`); default :data:`DEFAULT_RATE_PENALTY`,
        0 switches it off (the cost of the paper's FHOCP).
    qp_solver : str
        The subproblems' QP backend, a name of :func:`tubekit.fhocp.qp.registry.qp_backend_names`:
        ``"clarabel"`` (default) solves every subproblem with Clarabel; ``"piqp"`` (opt-in, needs the fast
        path and ``pip install piqp``) takes no cones, so it solves the QP relaxation first and its answer
        is kept only where it meets the cones, else Clarabel's (:mod:`tubekit.fhocp.qp.relaxed`). A name
        whose package is missing is a :class:`~tubekit.exceptions.NotAvailableError` when the solver is built.
    """

    max_obstacles: int | None = None
    terminal: TerminalMode | None = None
    penalty: float = 1e3
    terminal_penalty: float | None = None
    max_iterations: int = 30
    cold_start_iterations: int = 30
    tolerance: float = 1e-5
    trust_radius: float = 0.5
    extrapolate: bool = True
    fast_path: bool = True
    clarabel_settings: Mapping[str, Any] | None = None
    rate_penalty: float = DEFAULT_RATE_PENALTY
    qp_solver: str = DEFAULT_QP_BACKEND

    def __post_init__(self) -> None:
        if self.max_obstacles is not None:
            _count("max_obstacles", self.max_obstacles, 0, "an integer >= 0 or None")
        if self.terminal is not None:
            object.__setattr__(self, "terminal", choice("terminal", TerminalMode, self.terminal))
        object.__setattr__(self, "penalty", positive("penalty", self.penalty))
        if self.terminal_penalty is not None:
            object.__setattr__(self, "terminal_penalty", positive("terminal_penalty", self.terminal_penalty))
        _count("max_iterations", self.max_iterations, 1, "an integer >= 1")
        _count("cold_start_iterations", self.cold_start_iterations, 1, "an integer >= 1")
        object.__setattr__(self, "tolerance", positive("tolerance", self.tolerance))
        object.__setattr__(self, "trust_radius", positive("trust_radius", self.trust_radius))
        object.__setattr__(self, "rate_penalty", nonnegative("rate_penalty", self.rate_penalty))
        names = qp_backend_names()
        if not isinstance(self.qp_solver, str) or self.qp_solver not in names:
            raise ConfigError("qp_solver", f"one of the QP backends {names}", self.qp_solver)
        if self.qp_solver != DEFAULT_QP_BACKEND and not self.fast_path:
            raise ConfigError("qp_solver", f"{DEFAULT_QP_BACKEND!r} when fast_path=False (the QP backends read "
                              "the compiled data)", self.qp_solver)
        for name in ("extrapolate", "fast_path"):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(name, "True or False", getattr(self, name))
        if self.clarabel_settings is not None:
            if not isinstance(self.clarabel_settings, Mapping) or \
                    not all(isinstance(k, str) for k in self.clarabel_settings):
                raise ConfigError("clarabel_settings", "a mapping of Clarabel setting names to values",
                                  self.clarabel_settings)
            object.__setattr__(self, "clarabel_settings", MappingProxyType(dict(self.clarabel_settings)))

    def clarabel_overrides(self) -> dict[str, Any] | None:
        """The Clarabel overrides as a new dict (None without any)."""
        return None if self.clarabel_settings is None else dict(self.clarabel_settings)
