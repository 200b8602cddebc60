"""Tightened constraint data handed from the verifier to the FHOCP and the closed loop.

The verifier (:func:`verify.certify`) produces one :class:`Tightening` from a
certificate; :meth:`Tightening.untightened` is the baseline (no tube).

Two layers of data:

* the FHOCP's node constraints (scalars ``e_d_min`` ... ``obstacle_margin``,
  uniform over the horizon and at least the largest per-arc margin plus an
  inter-node allowance, so a plan meeting them usually passes the arc check);
* the certificate's per-arc margins ``margins`` (N, 4) (columns e_d, e_z, e_o,
  position), its nominal-arc rate bounds ``rates`` (4,) and its one-period tube
  ``tube`` (3,) per axis, used by :mod:`tubekit.loop.plan_check` to accept a plan
  exactly along its arcs and by the run's promise checks;
* the bounds it holds over, by name: :class:`RegionBounds` (R) and
  :class:`DisturbanceBound` (ω̄_xy, ω̄_z, γ̄);
* what it was certified for: ``design`` (:class:`tubekit.design_inputs.DesignInputs`, the design the
  certificate's theorem read, σ included) and ``tiers`` (:class:`tubekit.tiers.Tiers`). The loop calls
  :meth:`Tightening.require` once, before any tick: a run of another design — another start included —
  is refused naming the first field that differs. The untightened baseline carries no design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from tubekit.design_inputs import DesignInputs
from tubekit.exceptions import ConfigError
from tubekit.model.backup import BackupPlan
from tubekit.model.terminal_law import TerminalLaw
from tubekit.scenario import Scenario
from tubekit.tiers import Tiers

__all__ = ["Tightening", "MARGIN_COLUMNS", "RegionBounds", "DisturbanceBound"]

#: Columns of :attr:`Tightening.margins` and :attr:`Tightening.rates`.
MARGIN_COLUMNS: tuple[str, ...] = ("e_d", "e_z", "e_o", "position")


def _numbers(name: str, value: Any, n: int) -> list[float]:
    """``n`` finite floats from a sequence (or a named record's ``as_tuple()``), else ConfigError."""
    if hasattr(value, "as_tuple"):
        value = value.as_tuple()
    try:
        out = [float(x) for x in np.asarray(value, dtype=float).reshape(-1)]
    except (TypeError, ValueError):
        raise ConfigError(name, f"{n} numbers", value) from None
    if len(out) != n or not all(math.isfinite(x) for x in out):
        raise ConfigError(name, f"{n} finite numbers", value)
    return out


class _NamedNumbers:
    """A frozen record of floats that also reads from (and gives) the plain numbers in field order."""

    _FIELD = "tightening"

    @classmethod
    def of(cls, value: Any) -> Any:
        """The record itself, or one built from its numbers in field order (ConfigError otherwise)."""
        return value if isinstance(value, cls) else cls(*_numbers(cls._FIELD, value, len(fields(cls))))

    def as_tuple(self) -> tuple[float, ...]:
        """The numbers in field order."""
        return tuple(getattr(self, f.name) for f in fields(self))


@dataclass(frozen=True)
class RegionBounds(_NamedNumbers):
    """R as the loop uses it: e_d in [epsilon, e_d_max] (m), |e_z| <= e_z_max (m), |e_o| <= e_o_max."""

    _FIELD = "tightening.region"

    epsilon: float = 0.0
    e_d_max: float = 0.0
    e_z_max: float = 0.0
    e_o_max: float = 0.0


@dataclass(frozen=True)
class DisturbanceBound(_NamedNumbers):
    """The certificate's ω̄_xy, ω̄_z and sway bound γ̄ (m/s); zeros for the baseline."""

    _FIELD = "tightening.disturbance"

    omega_xy: float = 0.0
    omega_z: float = 0.0
    sway: float = 0.0


@dataclass(frozen=True)
class Tightening:
    """Constraints of the FHOCP on the nominal system, and the certificate's tube.

    Attributes
    ----------
    v_max : array (3,)
        V-bar: nominal input box [u, w, r] limits (m/s, m/s, rad/s).
    e_d_min, e_d_max : float
        Nominal e_d bounds at the FHOCP nodes (m).
    e_o_max : float
        Nominal |e_o| bound at the nodes.
    e_z_max : float
        Nominal |e_z| bound at the nodes (m).
    obstacle_margin : float
        Added to vehicle radius + obstacle radius for the nominal position at the nodes (m).
    sigma : float
        Ancillary gain (1/s); 0 disables the feedback.
    margins : array (N, 4)
        Per-arc margins (e_d, e_z, e_o, position) relative to the state a plan starts from;
        empty for the baseline (no arc check).
    rates : array (4,)
        Bounds on |ė_d|, |ė_z|, |ė_o|, ‖ṗ‖ along a nominal arc (spacing margin of the arc check).
    tube : array (3,)
        Certified one-period per-axis bounds on |e - ê| (m, m, -); zeros for the baseline.
    region : RegionBounds
        R: ``epsilon``, ``e_d_max``, ``e_z_max``, ``e_o_max`` (4 numbers in that order are accepted).
    disturbance : DisturbanceBound
        The certificate's ``omega_xy``, ``omega_z`` and ``sway`` bound γ̄ (m/s); zeros for the baseline
        (3 numbers in that order are accepted).
    design : DesignInputs or None
        The design it was certified for (σ included); None: the baseline, nothing to check.
    backup : BackupPlan or None
        The backup law and safe set (certified when ``tiers.safe``; a best-effort tightening
        carries the uncertified design). None: no backup (the untightened baseline).
    tiers : Tiers
        Which tiers of promise the certificate gives (none by default: the baseline or a best-effort run).
        A safe-only tightening (tracking False) has σ = 0, ``v_max`` = V, a zero tube and margins
        whose e-columns are zero (not enforced: only the position constraints are checked).
    velocity_loop : (3,) floats or None
        Dynamic plant: the certificate's derived bound on the velocity loop's error
        |u_b − u|, |w_b − w|, |r_b − r| (m/s, m/s, rad/s), checked in every run (promise
        ``velocity_loop``); None otherwise.
    terminal_law : TerminalLaw or None
        The tracking theorem's terminal set and law (``docs/verify.md``, step 17): every accepted plan ends in
        its set X_f, and the candidate is completed by its law, so a plan is always available. Given only with
        the tracking tier; None otherwise (then ``recursive_feasibility`` stays a premise of tracking).
    v_min : array (3,) or None
        The nominal box's lower corner (m/s, m/s, rad/s) when it is not −``v_max``: with a minimum surge
        (``limits.u_min``) v̂_u >= u_min + κ̄_u, so v = v̂ + κ never falls below u_min. None: −``v_max``
        (read it through :attr:`v_low`).
    """

    v_max: np.ndarray
    e_d_min: float
    e_o_max: float
    e_z_max: float
    e_d_max: float
    obstacle_margin: float
    sigma: float
    margins: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    rates: np.ndarray = field(default_factory=lambda: np.zeros(4))
    tube: np.ndarray = field(default_factory=lambda: np.zeros(3))
    region: RegionBounds = field(default_factory=RegionBounds)
    disturbance: DisturbanceBound = field(default_factory=DisturbanceBound)
    design: DesignInputs | None = None
    backup: BackupPlan | None = None
    tiers: Tiers = field(default_factory=Tiers)
    velocity_loop: tuple[float, float, float] | None = None
    terminal_law: TerminalLaw | None = None
    v_min: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.v_min is not None:
            low = np.asarray(_numbers("tightening.v_min", self.v_min, 3), dtype=float)
            if np.any(low > np.asarray(self.v_max, dtype=float)):
                raise ConfigError("tightening.v_min", "a lower corner <= v_max component-wise", list(low))
            object.__setattr__(self, "v_min", low)
        if self.terminal_law is not None and not isinstance(self.terminal_law, TerminalLaw):
            raise ConfigError("tightening.terminal_law", "a tubekit.model.terminal_law.TerminalLaw or None",
                              type(self.terminal_law).__name__)
        if not isinstance(self.tiers, Tiers):
            raise ConfigError("tightening.tiers", "a tubekit.Tiers", type(self.tiers).__name__)
        if self.design is not None and not isinstance(self.design, DesignInputs):
            raise ConfigError("tightening.design", "a tubekit.DesignInputs or None", type(self.design).__name__)
        object.__setattr__(self, "region", RegionBounds.of(self.region))
        object.__setattr__(self, "disturbance", DisturbanceBound.of(self.disturbance))
        if self.velocity_loop is not None:
            loop = _numbers("tightening.velocity_loop", self.velocity_loop, 3)
            if min(loop) < 0.0:
                raise ConfigError("tightening.velocity_loop", "three numbers >= 0 (m/s, m/s, rad/s)", loop)
            object.__setattr__(self, "velocity_loop", tuple(loop))

    @property
    def v_low(self) -> np.ndarray:
        """The nominal box's lower corner (3,) (m/s, m/s, rad/s): ``v_min``, or −``v_max``."""
        return -np.asarray(self.v_max, dtype=float) if self.v_min is None else np.asarray(self.v_min, dtype=float)

    @property
    def surge_floor(self) -> float:
        """The smallest nominal surge a plan may command (m/s): ``v_low[0]``."""
        return float(self.v_low[0])

    @property
    def certified(self) -> bool:
        """True when the certificate gives the safe tier (``tiers`` says whether tracking too)."""
        return self.tiers.safe

    @property
    def law(self) -> str | None:
        """The ancillary law it was certified for (None: the baseline)."""
        return None if self.design is None else self.design.law

    @property
    def design_key(self) -> str | None:
        """SHA-256 of the design (:meth:`DesignInputs.key`); None for the baseline."""
        return None if self.design is None else self.design.key()

    @property
    def rho_tilde(self) -> float:
        """Euclidean norm of the per-axis tube ``tube`` (plots); 0 without a tube."""
        return float(np.linalg.norm(np.asarray(self.tube, dtype=float)))

    @property
    def plan_always_available(self) -> bool:
        """True when recursive feasibility is a theorem here: the tracking tier with its terminal law (every run
        then follows a plan at every period; a lapse is a broken promise, not a failed premise)."""
        return self.tiers.tracking and self.terminal_law is not None and self.horizon_arcs > 0

    @property
    def proven_terminal_law(self) -> TerminalLaw | None:
        """The terminal law when :attr:`plan_always_available` (the candidate completes plans with it, the FHOCP
        aims at its set), else None."""
        return self.terminal_law if self.plan_always_available else None

    @property
    def terminal_backup(self) -> BackupPlan | None:
        """The backup whose safe set every accepted plan must end in (the terminal condition).

        None without a backup, and None for a backup the certificate did not certify (``tiers.safe``
        False, e.g. a best-effort tightening): its law still replaces the zero input once a
        replayed plan is exhausted, but a safe set that is not proved cannot make plans wait for it.
        """
        return self.backup if self.tiers.safe else None

    def require(self, scenario: Scenario) -> None:
        """Refuse a run of ``scenario`` this tightening was not certified for (nothing runs then).

        The run's design is the scenario's (its start included) under its own law at this tightening's σ;
        the certified design must cover it (:meth:`DesignInputs.covers`: a shorter run is covered). A σ the
        scenario declares must be the certified one, unless the certificate gives the safe tier alone (which
        runs at σ = 0). The baseline (no design) is not checked.

        Raises
        ------
        ConfigError
            ``design_key.<field>`` naming the first field that differs, with the scenario's and the
            certificate's values.
        """
        stored = self.design
        if stored is None:
            return
        declared = scenario.controller.sigma
        if declared is not None and not self.tiers.safe_only and float(declared) != float(self.sigma):
            raise ConfigError("design_key.sigma", f"the certificate's value {self.sigma!r} (it was issued for "
                              "another design)", declared, "the scenario declares another sigma than the "
                              "certificate's; certify this scenario (tubekit certify) and use that certificate")
        diff = stored.uncovered(DesignInputs.of(scenario, sigma=self.sigma))
        if diff is None:
            return
        name, here, there = diff
        raise ConfigError(f"design_key.{name}", f"the certificate's value {there!r} (it was issued for another "
                          "design)", here, "the scenario and law the run uses differ from those the certificate "
                          "was issued for; certify this scenario (tubekit certify) and use that certificate")

    @property
    def recovers(self) -> bool:
        """True when a plan whose error leaves R may still be followed for safety (a *recovery* plan, tracking not
        in force while it is): the certificate gives the safe tier and runs at σ = 0, so κ = 0 and the position
        margins, V̄ and the backup's hand-over, all derived from (ω̄, δ, the heading error) alone, hold whatever e
        is; a plan then only needs the safe part of the check (``docs/verify.md``, phase 2b)."""
        return self.tiers.safe and self.sigma == 0.0 and self.horizon_arcs > 0

    @property
    def terminal_rest(self) -> bool:
        """True when a plan must end near the backup's hand-over command, |v̂_{N−1} − :attr:`terminal_command`| <= J
        (at rest for station keeping, at the loiter's surge): a terminal backup that starts from its own command
        instead of blending from the last applied one (:attr:`tubekit.model.backup.StationKeeping.blends`)."""
        backup = self.terminal_backup
        return backup is not None and not backup.law.blends

    @property
    def terminal_command(self) -> np.ndarray:
        """(3,) the command a plan's last row must be within J of when :attr:`terminal_rest` (m/s, m/s, rad/s):
        the terminal backup's ``handover_command`` — 0 for station keeping, (u_l, 0, 0) for the loiter — projected
        onto the plans' box [:attr:`v_low`, ``v_max``] (a loiter at ū under a tube's κ̄_u is entered from ū − κ̄_u;
        on the dynamic plant σ = 0 and the box is V, which holds the command: nothing moves there)."""
        backup = self.terminal_backup
        if backup is None:
            return np.clip(np.zeros(3), self.v_low, np.asarray(self.v_max, dtype=float))
        return np.clip(np.asarray(backup.law.handover_command, dtype=float), self.v_low,
                       np.asarray(self.v_max, dtype=float))

    @property
    def horizon_arcs(self) -> int:
        """Number of arcs with certified margins (0: no arc check)."""
        return int(np.asarray(self.margins).shape[0])

    @classmethod
    def untightened(cls, scenario: Scenario) -> "Tightening":
        """The baseline's sets: V, e_d >= epsilon, region bounds, no margin, no feedback."""
        reg = scenario.region
        return cls(v_max=scenario.limits.vector.copy(), e_d_min=scenario.epsilon, e_o_max=reg.e_o_max,
                   e_z_max=reg.e_z_max, e_d_max=reg.e_d_max, obstacle_margin=0.0, sigma=0.0,
                   region=RegionBounds(scenario.epsilon, reg.e_d_max, reg.e_z_max, reg.e_o_max),
                   v_min=None if scenario.limits.u_min is None else scenario.limits.lower)
