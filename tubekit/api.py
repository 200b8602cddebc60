"""The short Python API: ``tubekit.simulate(scenario, certificate)``.

A certificate (from :func:`verify.certify`) is accepted directly; its certified
:class:`~tubekit.tightening.Tightening` is used, or :class:`tubekit.exceptions.ConfigError`
says what to do when it is not certified. With no certificate the nominal MPC alone runs
(no tightening, no ancillary feedback): the baseline of ``tubekit reproduce``.

>>> import tubekit, verify                                          # doctest: +SKIP
>>> sc = tubekit.load_scenario("verify/scenarios/paper_currents.toml")  # doctest: +SKIP
>>> run = tubekit.simulate(sc, verify.certify(sc), duration=20.0)    # doctest: +SKIP
>>> run.metrics["min_clearance"], all(p.ok for p in tubekit.check_promises(run))  # doctest: +SKIP
"""

from __future__ import annotations

import warnings
from typing import Protocol, runtime_checkable

from tubekit.checks import check_run_inputs, unit_hints
from tubekit.loop.closed_loop import run_closed_loop
from tubekit.exceptions import ConfigError, TubekitError
from tubekit.scenario import Scenario
from tubekit.loop.result import SimulationResult
from tubekit.tightening import Tightening
from tubekit.validation import duration_seconds

__all__ = ["simulate", "Certified"]


@runtime_checkable
class Certified(Protocol):
    """What a run needs of a certificate (``verify.Certificate`` has it): the tightening it hands out."""

    @property
    def tightening(self) -> Tightening:
        """The certified tightening (raises when not even the safe tier is certified)."""
        ...


def _tightening_of(certificate: Certified | Tightening) -> Tightening:
    """The Tightening of a certificate (or a Tightening given directly)."""
    if isinstance(certificate, Tightening):
        return certificate
    if not hasattr(type(certificate), "tightening"):
        raise ConfigError("certificate", "a verify.Certificate or a tubekit.Tightening",
                          type(certificate).__name__)
    try:
        tight = certificate.tightening
    except TubekitError as exc:
        raise ConfigError("certificate", "a certified certificate (or pass certificate.best_effort_tightening() "
                          "for a run without a guarantee)", "not certified", str(exc)) from None
    if not isinstance(tight, Tightening):
        raise ConfigError("certificate.tightening", "a tubekit.Tightening", type(tight).__name__)
    return tight


def simulate(scenario: Scenario, certificate: Certified | Tightening | None = None, duration: float | None = None,
             progress: bool = True) -> SimulationResult:
    """Run the closed loop of ``scenario`` (the tube controller when a certificate is given).

    Parameters
    ----------
    scenario : Scenario
        What to simulate.
    certificate : verify.Certificate or Tightening, optional
        The certified design; ``None`` runs the nominal MPC alone (no tube).
    duration : float, optional
        Simulated time (s); default the scenario's.
    progress : bool
        A progress bar on a terminal.

    Returns
    -------
    SimulationResult
        With ``metrics`` and ``to_csv(path)``; :func:`tubekit.check_promises` measures a tube run;
        its figure is ``run.plot()`` (:meth:`SimulationResult.plot`).
    """
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.Scenario", type(scenario).__name__)
    if duration is not None:
        scenario = scenario.with_changes(duration=duration_seconds("duration", duration))
    check_run_inputs(scenario)
    for hint in unit_hints(scenario):
        warnings.warn(hint, UserWarning, stacklevel=2)
    if certificate is None:
        return run_closed_loop(scenario, tube=False, progress=progress, label="baseline")
    tightening = _tightening_of(certificate)  # the loop refuses a certificate of another design before any tick
    return run_closed_loop(scenario, tightening, tube=True, progress=progress, label="tube")
