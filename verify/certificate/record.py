"""The certificate's data record: every typed part of the theorem's answer, and what follows from them.

:class:`CertificateRecord` is the data a certificate carries; its views import it typed — the JSON
form (:mod:`verify.certificate.jsonio`), the hand-off to the loop (:mod:`verify.certificate.handoff`)
and the text report (:mod:`verify.certificate.report`) — and :class:`verify.certificate.artefact.Certificate`
adds the methods that use them. The design it holds for (:attr:`CertificateRecord.inputs`, a
:class:`tubekit.design_inputs.DesignInputs` with the σ it hands out) is stored once: the scenario's
name, the law, N, δ and V are read from it.

The theorem (``docs/verify.md``, section 3) has two tiers (:attr:`CertificateRecord.tiers`):
**safe** — in the loop of :mod:`tubekit.loop.closed_loop` (plans accepted only when
:mod:`tubekit.loop.plan_check` verifies their arcs and the terminal condition, the previous plan
replayed otherwise, the backup law once the replay is exhausted) the vehicle ball never touches an
obstacle nor leaves the workspace and v ∈ V is never clipped, for all time, given only the
disturbance bound; **tracking** — while a plan is followed, the real error stays in R, e_d >= ε and
|e_j - ê_j| <= tube_j within every period, given the premises (:attr:`CertificateRecord.premises`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from tubekit.design_inputs import DesignInputs
from tubekit.exceptions import ConfigError
from tubekit.tiers import Tiers

from verify.backup import BackupCertificate
from verify.kernel.parts import EBar, SigmaChoice, SigmaTrial
from verify.kernel.region import Region
from verify.theorem.design import Condition, Design, DisturbanceBounds
from verify.theorem.gains import GainBounds
from verify.theorem.sampled import HorizonMargins, PeriodTube
from verify.theorem.tiers import tier_conditions, tiers_of

if TYPE_CHECKING:  # loaded only when a dynamic scenario or the paper's route is certified
    from verify.lemma1.route import PaperRoute
    from verify.vehicle.bound import LoopBound

__all__ = ["CertificateRecord", "THEOREM", "ASSUMPTIONS", "EXACT_SENSING", "PREMISES"]

THEOREM = ("sampled-data tube under the nominal reset: one-period box tube (verify.theorem.sampled), per-arc margins "
           "of the replayed candidate (verify.theorem.sampled.horizon_margins), exact arc acceptance with the "
           "terminal condition about an anchor within the backup's certified reach of the plan's end "
           "(tubekit.loop.plan_check), the certified station-keeping backup (verify.backup); "
           "tiers safe and tracking (verify.theorem.tiers)")

#: Outside the model, whatever the plant.
EXACT_SENSING = ("Sensing is exact: obstacle centres and radii, the state and the target trajectory are known without "
                 "noise.")

#: Outside the model on the kinematic plant: what no certificate about eq. (11) can check. A dynamic plant's
#: certificate states its own (``verify.certificate.certify.assumptions_of``): it does not assume eq. (11).
ASSUMPTIONS = (
    "The plant is the kinematic model eq. (11) with omega = current + sway term; the error dynamics are the sympy "
    "derivation of tubekit.model.derivation (not the printed eqs. 15-18). A real vehicle's dynamics are not covered.",
    "The simulator integrates eq. (11) with RK4 at a fixed step; the certificate bounds the exact solution, not "
    "the integration error (below 1e-9 m at the default 5 ms step).",
    EXACT_SENSING,
)

#: Premises of the theorem that depend on the run, checked in every run (tubekit.loop.promises).
PREMISES = (
    "recursive_feasibility (tracking tier only): the tracking promises hold while a plan is followed (accepted, "
    "or replayed for at most N - 1 samples); while the backup law is active only the safe tier is promised. "
    "The safe tier does not depend on it.",
    "disturbance (both tiers): ||omega_xy(t)|| <= omega_bar_xy and |omega_z(t)| <= omega_bar_z at all times "
    "(the supremum over each period, not only at the ticks); on the dynamic plant only the water current is the "
    "premise (against its declared bound): the hull's sway and the velocity loop's error are derived, so a breach "
    "of either is a broken promise.",
    "plant_in_box (dynamic plant, both tiers): every coefficient of the vehicle as simulated lies in the "
    "certified coefficient box.",
)


@dataclass(frozen=True)
class CertificateRecord:
    """The typed parts of a certificate. ``certified`` is True only if every condition of both tiers holds.

    Attributes
    ----------
    inputs : DesignInputs
        The design the theorem read, with the σ of the tightening handed out (:func:`tubekit.design_inputs.handed_sigma`).
    region : Region
        R: the set every bound holds over.
    gains : GainBounds
        Entry bounds of K and J K over R.
    disturbance : DisturbanceBounds
        ω̄_xy, ω̄_z, γ̄ (m/s).
    design : Design
        The chosen σ with its tube, margins, V̄ and conditions.
    tried : tuple of SigmaTrial
        Every σ evaluated: ``sigma``, ``certified``, ``score``, ``failed``.
    sigma_source : str
        Why this σ.
    elapsed_s : float
        Wall time (s, rounded to ms): reported, never part of a verdict or of the checksum.
    assumptions, premises : tuple of str
        What the theorem assumes outside the model, and the premises every run checks.
    paper_route : PaperRoute or None
        The paper's Lemma-1 route: a report, not the verdict.
    backup : BackupCertificate or None
        The backup law, its safe set and the proof (``backup_*`` conditions).
    safe_design : Design or None
        The safe tier's design at σ = 0 when the chosen (tracking) design does not certify, else None.
    velocity_loop : LoopBound or None
        Dynamic plant: the velocity loop's derived error bound (:mod:`verify.vehicle.bound`), else None.
    plant_conditions : tuple of Condition
        Dynamic plant: the loop's conditions and the fixed point's; both tiers depend on them.
    """

    inputs: DesignInputs
    region: Region
    gains: GainBounds
    disturbance: DisturbanceBounds
    design: Design
    tried: tuple[SigmaTrial, ...]
    sigma_source: str
    elapsed_s: float
    assumptions: tuple[str, ...] = ASSUMPTIONS
    premises: tuple[str, ...] = PREMISES
    paper_route: PaperRoute | None = None
    backup: BackupCertificate | None = None
    safe_design: Design | None = None
    velocity_loop: LoopBound | None = None
    plant_conditions: tuple[Condition, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.inputs, DesignInputs):
            raise ConfigError("certificate.inputs", "a tubekit.DesignInputs", type(self.inputs).__name__)
        if self.inputs.sigma is None:
            raise ConfigError("certificate.inputs.sigma", "the sigma the certificate hands out (a number, 1/s)", None)

    # ------------------------------------------------------------------ the design, read from its one store
    @property
    def scenario_name(self) -> str:
        """The certified scenario's label."""
        return self.inputs.name

    @property
    def law(self) -> str:
        """The ancillary law certified."""
        return self.inputs.law

    @property
    def horizon_steps(self) -> int:
        """N."""
        return self.inputs.horizon_steps

    @property
    def dt(self) -> float:
        """δ, the FHOCP period (s)."""
        return self.inputs.dt

    @property
    def limits(self) -> tuple[float, float, float]:
        """V (m/s, m/s, rad/s)."""
        u, w, r = (float(x) for x in self.inputs.v_max)
        return u, w, r

    @property
    def design_key(self) -> str:
        """SHA-256 of the design (:meth:`tubekit.design_inputs.DesignInputs.key`)."""
        return self.inputs.key()

    # ------------------------------------------------------------------ status
    @property
    def conditions(self) -> tuple[Condition, ...]:
        """Every checked inequality: the chosen design's, the safe-only design's (``safe_only.*``), the backup's."""
        extra = self.safe_design.conditions if self.safe_design is not None else ()
        return (self.design.conditions + extra + (self.backup.conditions if self.backup is not None else ())
                + self.plant_conditions)

    @property
    def tier_conditions(self) -> dict[str, tuple[Condition, ...]]:
        """For each tier (``safe``, ``tracking``) the conditions it depends on (``verify.theorem.tiers.tier_conditions``)."""
        return tier_conditions(self.design, self.safe_design, self.backup, self.plant_conditions)

    @property
    def tiers(self) -> Tiers:
        """The tiers given: a tier is certified when every condition it depends on holds."""
        return tiers_of(self.design, self.safe_design, self.backup, self.plant_conditions)

    @property
    def tier_failures(self) -> dict[str, tuple[str, ...]]:
        """For each tier, the names of the conditions it depends on that do not hold."""
        return {k: tuple(c.condition for c in v if c.ok is not True) for k, v in self.tier_conditions.items()}

    @property
    def certified(self) -> bool:
        """True when both tiers are certified (every condition holds; none failed, none left unevaluated)."""
        return self.tiers.both

    @property
    def failures(self) -> tuple[Condition, ...]:
        """The failed conditions."""
        return tuple(c for c in self.conditions if c.ok is False)

    @property
    def not_evaluated(self) -> tuple[str, ...]:
        """Names of conditions that could not be evaluated."""
        return tuple(c.condition for c in self.conditions if c.ok is None)

    @property
    def theorem(self) -> str:
        """The theorem this certificate states (:data:`THEOREM`)."""
        return THEOREM

    @property
    def sigma(self) -> SigmaChoice:
        """σ (1/s) of the chosen design, why it was chosen, every σ tried."""
        return SigmaChoice(value=self.design.sigma, source=self.sigma_source, tried=self.tried)

    @property
    def tube(self) -> PeriodTube:
        """The one-period box tube (per-axis ``rho``, ``theta``, Cartesian bounds, ``kappa``)."""
        return self.design.tube

    @property
    def rho_tilde(self) -> float | None:
        """Euclidean norm of the per-axis tube (for plots), None when there is no finite tube."""
        t = self.design.tube
        return float(np.linalg.norm(t.rho)) if t.certified else None

    @property
    def v_bar(self) -> np.ndarray | None:
        """V̄ = V - κ̄ (m/s, m/s, rad/s) or None."""
        return None if self.design.v_bar is None else np.asarray(self.design.v_bar)

    @property
    def kappa_bar(self) -> np.ndarray | None:
        """sup |κ_i| (m/s, m/s, rad/s) or None."""
        return np.asarray(self.design.tube.kappa) if self.design.tube.certified else None

    @property
    def margins(self) -> HorizonMargins | None:
        """Per-arc margins (e_d, e_z, e_o, position) or None."""
        return self.design.margins

    @property
    def e_bar(self) -> EBar | None:
        """Ē on the last arc: R shrunk by the largest margin."""
        m, reg = self.design.margins, self.region
        if m is None:
            return None
        return EBar(e_d=(reg.e_d[0] + m.e_d[-1], reg.e_d[1] - m.e_d[-1]),
                    e_z=(reg.e_z[0] + m.e_z[-1], reg.e_z[1] - m.e_z[-1]),
                    e_o=(reg.e_o[0] + m.e_o[-1], reg.e_o[1] - m.e_o[-1]))
