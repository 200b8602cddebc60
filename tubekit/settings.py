"""The settings of one scenario, component by component: obstacles, the current, the controller, the region.

Each is a frozen, validated dataclass (a bad value raises :class:`~tubekit.exceptions.ConfigError` naming its
field); :class:`tubekit.scenario.Scenario` composes them. The FHOCP mode, the terminal mode and the heading
hemisphere are str-valued enums (:class:`FhocpMode`, :class:`TerminalMode`, :class:`Heading`): a member equals
its string, so TOML and JSON keep plain strings. The law stays a registered name (users register laws).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.model.kinematics import SwayModel
from tubekit.validation import (StrChoice, as_vector, choice, gain, nonnegative, positive, speed_bound,
                                ticks_per_period)

__all__ = ["FhocpMode", "TerminalMode", "Heading", "LAW_NAMES", "HEADINGS", "HEMISPHERE_SIGN", "Obstacle",
           "Disturbance", "ControllerSettings", "RegionSettings"]


class FhocpMode(StrChoice):
    """FHOCP mode: one warm-started convex solve per step, or SCP to convergence."""

    REALTIME = "realtime"
    CONVERGED = "converged"


class TerminalMode(StrChoice):
    """Terminal set F: exact penalty, hard constraint, or none."""

    SOFT = "soft"
    HARD = "hard"
    OFF = "off"


class Heading(StrChoice):
    """Heading hemisphere of the region: cos(psi - theta) < 0 ("toward"), > 0 ("away"), or either."""

    TOWARD = "toward"
    AWAY = "away"
    BOTH = "both"


LAW_NAMES = ("paper", "corrected")
HEADINGS: tuple[str, ...] = Heading.values()
#: Sign of cos(psi - theta) in each heading hemisphere (0: either).
HEMISPHERE_SIGN: dict[str, int] = {Heading.TOWARD: -1, Heading.AWAY: 1, Heading.BOTH: 0}


@dataclass(frozen=True)
class Obstacle:
    """A spherical obstacle B(center, radius) (m)."""

    center: tuple[float, float, float]
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", tuple(float(c) for c in as_vector("obstacle.center", self.center, 3)))
        object.__setattr__(self, "radius", positive("obstacle.radius", self.radius))


@dataclass(frozen=True)
class Disturbance:
    """Current delta(t) plus sway; the total omega has ||omega|| <= omega_bar.

    ``delta(t) = amplitude * [sin(a), cos(a), sin(a)] + constant``,
    ``a = 2 pi t / period``; the paper uses amplitude 0.1 m/s, period 15 s.
    Evaluated by :class:`tubekit.plant.kinematic.Plant` (this class only holds the settings
    and their bounds).

    Parameters
    ----------
    amplitude : array (3,)
        Current amplitudes along x, y, z (m/s).
    period : float
        Current period (s).
    constant : array (3,)
        Constant current (m/s).
    sway : SwayModel
        Unactuated sway model.
    """

    amplitude: tuple[float, float, float] = (0.1, 0.1, 0.1)
    period: float = 15.0
    constant: tuple[float, float, float] = (0.0, 0.0, 0.0)
    sway: SwayModel = field(default_factory=SwayModel)

    def __post_init__(self) -> None:
        amp = as_vector("disturbance.amplitude", self.amplitude, 3)
        if np.any(amp < 0):
            raise ConfigError("disturbance.amplitude", "three numbers >= 0", self.amplitude)
        object.__setattr__(self, "amplitude", tuple(float(a) for a in amp))
        object.__setattr__(self, "period", positive("disturbance.period", self.period))
        object.__setattr__(self, "constant",
                           tuple(float(c) for c in as_vector("disturbance.constant", self.constant, 3)))
        speed_bound("disturbance.amplitude", max(math.hypot(*amp[::2]), amp[1]), list(self.amplitude))
        speed_bound("disturbance.constant", math.hypot(*self.constant), list(self.constant))

    @property
    def current_bound(self) -> float:
        """delta-bar: exact max over t of ||delta(t)|| for zero constant, else a triangle bound (m/s)."""
        a1, a2, a3 = self.amplitude
        periodic = math.sqrt(max(a1 * a1 + a3 * a3, a2 * a2))
        return periodic + float(np.linalg.norm(self.constant))

    @property
    def omega_bar(self) -> float:
        """omega-bar = delta-bar + gamma-bar (eq. Wset), m/s."""
        return self.current_bound + self.sway.bound


@dataclass(frozen=True)
class ControllerSettings:
    """Tube-MPC settings.

    Parameters
    ----------
    dt : float
        FHOCP sampling period delta_t (s).
    horizon_steps : int
        N; the horizon is T = N dt (s).
    Q, R, P : array (3,)
        Diagonals of the stage, input and terminal weights.
    law : str
        Ancillary law: a name in :data:`tubekit.model.ancillary.LAWS` (built-in: :data:`LAW_NAMES`).
    sigma : float or None
        Ancillary gain; ``None`` lets the verifier choose it.
    ancillary_rate_hz : float
        Rate of the ancillary feedback kappa (Hz); a multiple of 1/dt.
    terminal_level : float
        epsilon-bar of the terminal set F = {||e||_P <= epsilon-bar}.
    fhocp_mode : FhocpMode
        ``"realtime"`` (one convex solve per step, warm-started) or ``"converged"``
        (sequential convex programming to convergence), see :mod:`tubekit.fhocp`.
    terminal_mode : TerminalMode
        Terminal set F: ``"soft"`` (exact penalty), ``"hard"`` or ``"off"``.
    fhocp_backend : str
        FHOCP solver: a name in :func:`tubekit.fhocp.registry.backends` (``"scp"``, ``"ipopt"``);
        checked when the solver is built. Left out of :meth:`Scenario.to_dict` when ``"scp"``.
    candidate : bool
        When the solver's plan is refused or rejected, try the shifted candidate (the last accepted plan
        shifted, completed by a pursuit input: :mod:`tubekit.loop.candidate`) through the same exact check
        before replaying the old plan. Not read by the certificate (any plan that passes the check is
        covered). Left out of :meth:`Scenario.to_dict` when True.
    recovery : bool
        When no tracking plan is left to follow, accept a plan that meets the safe part of the check only (its
        error may leave R: a recovery plan, tracking not in force while it is followed) instead of holding the
        backup; only under a certificate that allows it (``Tightening.recovers``: σ = 0). Not a certificate
        input. Left out of :meth:`Scenario.to_dict` when True.
    backup : str
        The backup law's kind (a key of :data:`tubekit.model.backup.BACKUP_LAWS`): ``"station_keeping"`` (hold
        station, surging ahead or astern; the default) or ``"loiter"`` (circle about the anchor at a constant
        surge: :mod:`tubekit.model.loiter`). The certificate designs and proves a law of this kind. Left out of
        :meth:`Scenario.to_dict` when ``"station_keeping"``.
    lookahead : float
        lambda_f >= 0: the FHOCP asks node k of a plan to keep lambda_f k/N of the backup's footprint from every
        known obstacle too, not only the plan's end (``tubekit.fhocp.nlp.FhocpNlp.lookahead_margins``), so a plan
        turns away before its end is trapped against an obstacle. A planning preference, not a certificate input:
        plans are still accepted by the exact check alone. 0 (default): off; left out of :meth:`Scenario.to_dict`
        when 0.
    """

    dt: float = 0.1
    horizon_steps: int = 8
    Q: tuple[float, float, float] = (1.0, 1.0, 0.5)
    R: tuple[float, float, float] = (0.5, 0.5, 0.1)
    P: tuple[float, float, float] = (5.0, 5.0, 2.5)
    law: str = "corrected"
    sigma: float | None = None
    ancillary_rate_hz: float = 100.0
    terminal_level: float = 2.0
    fhocp_mode: FhocpMode = FhocpMode.REALTIME
    terminal_mode: TerminalMode = TerminalMode.SOFT
    fhocp_backend: str = "scp"
    candidate: bool = True
    recovery: bool = True
    backup: str = "station_keeping"
    lookahead: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "dt", positive("controller.dt", self.dt))
        object.__setattr__(self, "lookahead", nonnegative("controller.lookahead", self.lookahead))
        for name in ("candidate", "recovery"):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(f"controller.{name}", "true or false", getattr(self, name))
        if not isinstance(self.horizon_steps, int) or isinstance(self.horizon_steps, bool) or self.horizon_steps < 1:
            raise ConfigError("controller.horizon_steps", "an integer >= 1", self.horizon_steps)
        for name in ("Q", "R", "P"):
            vec = as_vector(f"controller.{name}", getattr(self, name), 3)
            if np.any(vec <= 0):
                raise ConfigError(f"controller.{name}", "three numbers > 0 (a positive diagonal)",
                                  getattr(self, name))
            object.__setattr__(self, name, tuple(float(x) for x in vec))
        from tubekit.model.ancillary import LAWS  # the registry: built-in laws plus registered ones
        if not isinstance(self.law, str) or self.law not in LAWS:
            raise ConfigError("controller.law", f"one of {tuple(LAWS)}", self.law)
        if self.sigma is not None:
            object.__setattr__(self, "sigma", gain("controller.sigma", self.sigma))
        object.__setattr__(self, "ancillary_rate_hz",
                           positive("controller.ancillary_rate_hz", self.ancillary_rate_hz))
        ticks_per_period("controller.ancillary_rate_hz", self.ancillary_rate_hz, "controller.dt", self.dt)
        object.__setattr__(self, "terminal_level", positive("controller.terminal_level", self.terminal_level))
        object.__setattr__(self, "fhocp_mode", choice("controller.fhocp_mode", FhocpMode, self.fhocp_mode))
        object.__setattr__(self, "terminal_mode", choice("controller.terminal_mode", TerminalMode,
                                                         self.terminal_mode))
        from tubekit.model.backup import BACKUP_LAWS  # the registry: station keeping, loiter, registered ones
        if not isinstance(self.backup, str) or self.backup not in BACKUP_LAWS:
            raise ConfigError("controller.backup", f"one of {tuple(BACKUP_LAWS)}", self.backup)
        if not isinstance(self.fhocp_backend, str) or not self.fhocp_backend:
            raise ConfigError("controller.fhocp_backend", "a backend name (e.g. 'scp' or 'ipopt')",
                              self.fhocp_backend)

    @property
    def horizon(self) -> float:
        """Prediction horizon T = N dt (s)."""
        return self.horizon_steps * self.dt


@dataclass(frozen=True)
class RegionSettings:
    """The error region the verifier's bounds must hold over.

    e_d in [epsilon, e_d_max], |e_z| <= e_z_max, |e_o| <= e_o_max, heading
    hemisphere "toward" (cos(psi - bearing) < 0: the vehicle points at the
    target), "away" or "both". The FHOCP keeps the nominal inside the region
    shrunk by the tube, so the bounds apply along the closed loop.
    """

    e_d_max: float = 3.0
    e_z_max: float = 1.0
    e_o_max: float = 0.9
    heading: Heading = Heading.TOWARD

    def __post_init__(self) -> None:
        object.__setattr__(self, "e_d_max", positive("region.e_d_max", self.e_d_max))
        object.__setattr__(self, "e_z_max", positive("region.e_z_max", self.e_z_max))
        eo = positive("region.e_o_max", self.e_o_max)
        if eo >= 1.0:
            raise ConfigError("region.e_o_max", "a number in (0, 1) (|e_o| = 1 makes J singular)", eo)
        object.__setattr__(self, "e_o_max", eo)
        object.__setattr__(self, "heading", choice("region.heading", Heading, self.heading))
