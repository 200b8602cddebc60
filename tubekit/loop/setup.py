"""Setting up a run of the closed loop: its arguments checked, its solver built, its time grid and progress bar.

:func:`validate_inputs` checks the arguments of :func:`tubekit.loop.closed_loop.run_closed_loop` and calls
:meth:`tubekit.tightening.Tightening.require` (the one check of the design, before any tick);
:func:`build_solver` builds the FHOCP; :class:`Clock` is the time grid (periods, ticks, RK4 substeps);
:func:`saturate` clips a command to V (the loop counts every clip).
"""

from __future__ import annotations

import enum
import inspect
import math
import sys
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from tubekit.checks import require_one_period
from tubekit.exceptions import ConfigError
from tubekit.model.ancillary import AncillaryLaw, get_law
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

if TYPE_CHECKING:  # the solver package (cvxpy) is loaded only when a solver is built
    from tubekit.fhocp.result import FhocpSolver, SolverFactory

__all__ = ["validate_inputs", "build_solver", "takes_v_last", "silence_fallback_warnings", "progress_bar", "Clock",
           "saturate", "status_text"]


def validate_inputs(scenario: Scenario, tightening: Tightening | None, tube: bool,
                    plant_substeps: int) -> tuple[Tightening, AncillaryLaw, float]:
    """Check the arguments of :func:`run_closed_loop`; return (tightening, the scenario's law, σ in 1/s).

    Raises
    ------
    ConfigError
        Bad ``plant_substeps``, a duration shorter than one period, a tube run
        without tightening, a tightening of another design, or a σ that is not finite and >= 0.
    """
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.Scenario", type(scenario).__name__)
    if not isinstance(plant_substeps, int) or isinstance(plant_substeps, bool) or plant_substeps < 1:
        raise ConfigError("plant_substeps", "an integer >= 1", plant_substeps)
    require_one_period("duration", scenario.duration, scenario.controller.dt)
    if tightening is None:
        if tube:
            raise ConfigError("tightening", "a Tightening (e.g. verify.certify(...).tightening) for the tube run",
                              None)
        tightening = Tightening.untightened(scenario)
    law_obj = get_law(scenario.controller.law)
    if not tube:
        return tightening, law_obj, 0.0
    tightening.require(scenario)  # the one check of the design: another design (another start too) never runs
    sig = float(tightening.sigma)
    if not math.isfinite(sig) or sig < 0:
        raise ConfigError("sigma", "a finite number >= 0", sig)
    return tightening, law_obj, sig


def build_solver(scenario: Scenario, tightening: Tightening, solver_factory: SolverFactory | None) -> FhocpSolver:
    """``solver_factory(scenario, tightening)``, or the scenario's backend from the registry.

    The default is :func:`tubekit.fhocp.registry.make_solver`: backend
    ``scenario.controller.fhocp_backend`` (``"scp"``: :class:`tubekit.fhocp.FHOCP` in
    ``scenario.controller.fhocp_mode``).
    """
    if solver_factory is not None:
        return solver_factory(scenario, tightening)
    from tubekit.fhocp.registry import make_solver  # imported lazily: cvxpy loads only when a solver is built
    return make_solver(scenario, tightening)


def takes_v_last(solver: FhocpSolver) -> bool:
    """True when ``solver.solve`` accepts the keyword ``v_last`` (the built-in backends do)."""
    try:
        params = inspect.signature(solver.solve).parameters
    except (TypeError, ValueError):  # pragma: no cover - a builtin without a signature
        return False
    return "v_last" in params or any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())


def silence_fallback_warnings() -> None:
    try:
        from tubekit.fhocp import FallbackWarning
    except ImportError:  # pragma: no cover - a stand-in solver without the real module
        return
    warnings.simplefilter("ignore", FallbackWarning)


def progress_bar(total: int, enabled: bool, label: str) -> Any:
    if not enabled or not sys.stderr.isatty():
        return None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return None
    return tqdm(total=total, desc=label, unit="step", leave=False, dynamic_ncols=True)


@dataclass(frozen=True)
class Clock:
    """The time grid: ``steps`` periods of ``ticks`` ticks of ``h`` s, ``substeps`` RK4 steps per tick."""

    steps: int
    ticks: int
    h: float
    substeps: int
    t: np.ndarray  # (K + 1,) tick times (s), K = steps * ticks
    tau: np.ndarray  # (ticks + 1,) times within a period (s)

    @classmethod
    def of(cls, scenario: Scenario, substeps: int) -> Clock:
        dt = scenario.controller.dt
        m = int(round(scenario.controller.ancillary_rate_hz * dt))
        h = dt / m
        k_total = scenario.steps * m
        return cls(steps=scenario.steps, ticks=m, h=h, substeps=substeps,
                   t=np.round(np.arange(k_total + 1) * h, 9), tau=np.arange(m + 1) * h)

    @property
    def plant_step(self) -> float:
        """RK4 step (s)."""
        return self.h / self.substeps


def saturate(v: tuple[float, float, float], limits: tuple[float, float, float],
             lower: tuple[float, float, float] | None = None) -> tuple[tuple[float, float, float], bool]:
    """Clip ``v`` to the box lower_i <= v_i <= limits_i (m/s, m/s, rad/s; ``lower`` None: −limits, the box
    |v_i| <= limits_i); return (v, whether it was clipped)."""
    if lower is None:
        lower = (-limits[0], -limits[1], -limits[2])
    if (lower[0] <= v[0] <= limits[0] and lower[1] <= v[1] <= limits[1] and lower[2] <= v[2] <= limits[2]):
        return v, False
    return tuple(min(max(vi, lo), li) for vi, lo, li in zip(v, lower, limits)), True


def status_text(status: Any) -> str:
    """A result status (a str-valued enum member or a str) as plain text."""
    return str(status.value) if isinstance(status, enum.Enum) else str(status)
