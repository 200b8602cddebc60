"""The certificate: a theorem about the loop that runs (sampled-data tube under the nominal reset).

:func:`certify` is a short pipeline of named steps:

1. :func:`verify.gains.gain_bounds` — entry bounds of the law's K and G = J K over R;
2. :func:`verify.design.disturbance_bounds` — ω̄_xy, ω̄_z, γ̄ from the models;
3. :func:`sigma_candidates` then :func:`verify.design.evaluate_design` for each σ —
   the one-period tube, the per-arc margins, V̄ and every named condition;
   (:func:`verify.tiers.tracking_design`: with the workspace conditions of :mod:`verify.workspace`);
4. :func:`choose_design` — the certified design with the largest normalised slack
   (or, when none certifies, the best uncertified one, for a best-effort run);
5. :func:`verify.tiers.safe_only_design` — when the chosen design does not certify, the
   safe tier's own design at σ = 0 (position margins only);
6. :func:`verify.tiers.backup_of` — the backup law and its safe set
   (:func:`verify.backup.design_backup`), proved for the hand-over of the margins in use.

The theorem (``docs/verify.md``, section 3) has two tiers (:attr:`Certificate.tiers`):
**safe** — in the loop of :mod:`tubekit.loop.closed_loop` (plans accepted only when
:mod:`tubekit.loop.plan_check` verifies their arcs and the terminal condition, the
previous plan replayed otherwise, the backup law once the replay is exhausted) the
vehicle ball never touches an obstacle nor leaves the workspace and v ∈ V is never
clipped, for all time, given only the disturbance bound; **tracking** — while a plan is
followed, the real error stays in R, e_d >= ε and |e_j - ê_j| <= tube_j within every
period, given the premises (:attr:`Certificate.premises`).
"""

from __future__ import annotations

import importlib.util
import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from tubekit.design_key import design_fields, design_key
from tubekit.model.ancillary import AncillaryLaw, get_law, register_law
from tubekit.exceptions import ConfigError, TubekitError
from tubekit.jsonable import to_jsonable
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

from verify.backup import BackupCertificate
from verify.design import Condition, Design, DisturbanceBounds, choose_design, disturbance_bounds
from verify.gains import GainBounds, gain_bounds
from verify.parts import EBar, SigmaChoice, SigmaTrial
from verify.region import Region
from verify.sampled import HorizonMargins, PeriodTube
from verify.tiers import key_sigma, solve_tiers, tier_conditions

if TYPE_CHECKING:  # the dynamic plant's modules load only when a dynamic scenario is certified
    from verify.vehicle.bound import LoopBound

#: Why σ = 0 on the dynamic plant (:mod:`verify.vehicle.compose`).
DYNAMIC_SIGMA_SOURCE = "dynamic plant: sigma = 0 (kappa = 0, so the velocity loop sees only bounded command jumps)"

__all__ = ["Condition", "Certificate", "NotCertifiedError", "certify", "sigma_candidates", "choose_design",
           "certificate_fields", "paper_route_of", "ASSUMPTIONS", "PREMISES", "THEOREM"]

THEOREM = ("sampled-data tube under the nominal reset: one-period box tube (verify.sampled), per-arc margins of "
           "the replayed candidate (verify.sampled.horizon_margins), exact arc acceptance with the terminal "
           "condition (tubekit.loop.plan_check), the certified station-keeping backup (verify.backup); tiers "
           "safe and tracking (verify.tiers)")

#: Outside the model: what no certificate about eq. (11) can check.
ASSUMPTIONS = (
    "The plant is the kinematic model eq. (11) with omega = current + sway term; the error dynamics are the sympy "
    "derivation of tubekit.model.derivation (not the printed eqs. 15-18). A real vehicle's dynamics are not covered.",
    "The simulator integrates eq. (11) with RK4 at a fixed step; the certificate bounds the exact solution, not "
    "the integration error (below 1e-9 m at the default 5 ms step).",
    "Sensing is exact: obstacle centres and radii, the state and the target trajectory are known without noise.",
)

#: Premises of the theorem that depend on the run, checked in every run (tubekit.loop.promises).
PREMISES = (
    "recursive_feasibility (tracking tier only): the tracking promises hold while a plan is followed (accepted, "
    "or replayed for at most N - 1 samples); while the backup law is active only the safe tier is promised. "
    "The safe tier does not depend on it.",
    "disturbance (both tiers): ||omega_xy(t)|| <= omega_bar_xy and |omega_z(t)| <= omega_bar_z at all times "
    "(the supremum over each period, not only at the ticks).",
)


class NotCertifiedError(TubekitError):
    """Raised by :meth:`Certificate.tightening` when the design is not certified."""


@dataclass(frozen=True)
class Certificate:
    """Result of :func:`certify`. ``certified`` is True only if every condition of the chosen design holds.

    Every part is typed; :meth:`to_dict` / :meth:`from_dict` are exact inverses
    (``Certificate.from_dict(c.to_dict()) == c``, :mod:`verify.certificate_json`).

    Attributes
    ----------
    scenario_name, law : str
        What was certified.
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
    horizon_steps, dt : int, float
        N and δ (s).
    limits : (3,) floats
        V of the scenario (m/s, m/s, rad/s).
    scenario_data : dict
        The scenario as JSON (``Scenario.to_dict()``).
    design_fields : dict
        What the theorem read (:func:`tubekit.design_key.design_fields`, plus ``region_override``
        when ``certify`` was given another region); :attr:`design_key` is their hash.
    paper_route : object or None
        The paper's Lemma-1 route (``verify.lemma1.route.PaperRoute``) when available: a report, not the verdict.
    backup : BackupCertificate or None
        The backup law, its safe set and the proof (``backup_*`` conditions).
    safe_design : Design or None
        The safe tier's design at σ = 0 when the chosen (tracking) design does not certify, else None.
    velocity_loop : LoopBound or None
        Dynamic plant: the velocity loop's derived error bound (:mod:`verify.vehicle.bound`), else None.
    plant_conditions : tuple of Condition
        Dynamic plant: the loop's conditions and the fixed point's (:func:`verify.vehicle.compose.solve_dynamic`);
        both tiers depend on them.
    """

    scenario_name: str
    law: str
    region: Region
    gains: GainBounds
    disturbance: DisturbanceBounds
    design: Design
    tried: tuple[SigmaTrial, ...]
    sigma_source: str
    elapsed_s: float
    horizon_steps: int = 8
    dt: float = 0.1
    assumptions: tuple[str, ...] = ASSUMPTIONS
    premises: tuple[str, ...] = PREMISES
    limits: tuple[float, float, float] = field(default=(0.4, 0.3, 0.5))
    scenario_data: dict = field(default_factory=dict)
    design_fields: dict = field(default_factory=dict)
    paper_route: Any = None
    backup: BackupCertificate | None = None
    safe_design: Design | None = None
    velocity_loop: "LoopBound | None" = None
    plant_conditions: tuple[Condition, ...] = ()

    # ------------------------------------------------------------------ status
    @property
    def conditions(self) -> tuple[Condition, ...]:
        """Every checked inequality: the chosen design's, the safe-only design's (``safe_only.*``), the backup's."""
        extra = self.safe_design.conditions if self.safe_design is not None else ()
        return (self.design.conditions + extra + (self.backup.conditions if self.backup is not None else ())
                + self.plant_conditions)

    @property
    def tier_conditions(self) -> dict[str, tuple[Condition, ...]]:
        """For each tier (``safe``, ``tracking``) the conditions it depends on (``verify.tiers.tier_conditions``)."""
        return tier_conditions(self.design, self.safe_design, self.backup, self.plant_conditions)

    @property
    def tiers(self) -> dict[str, bool]:
        """``{"safe": bool, "tracking": bool}``: a tier is certified when every condition it depends on holds."""
        return {k: all(c.ok is True for c in v) for k, v in self.tier_conditions.items()}

    @property
    def key_sigma(self) -> float:
        """σ (1/s) of the tightening handed out, the one :attr:`design_fields` holds (0 for a safe-only one)."""
        return key_sigma(self.design, self.safe_design, self.backup, self.plant_conditions)

    @property
    def tier_failures(self) -> dict[str, tuple[str, ...]]:
        """For each tier, the names of the conditions it depends on that do not hold."""
        return {k: tuple(c.condition for c in v if c.ok is not True) for k, v in self.tier_conditions.items()}

    @property
    def certified(self) -> bool:
        """True when both tiers are certified (every condition holds; none failed, none left unevaluated)."""
        return all(self.tiers.values())

    @property
    def is_certified(self) -> bool:
        """Alias of :attr:`certified`."""
        return self.certified

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
    def design_key(self) -> str:
        """SHA-256 of :attr:`design_fields` (:func:`tubekit.design_key.design_key`)."""
        return design_key(self.design_fields)

    @property
    def sigma(self) -> SigmaChoice:
        """σ (1/s), why it was chosen, every σ tried."""
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

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """JSON-ready dict: verdict, theorem, its inputs, tube, margins, conditions, design key, checksum."""
        from verify.certificate_json import certificate_to_dict
        return certificate_to_dict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Certificate":
        """The certificate of a :meth:`to_dict` dict (ConfigError naming the key when one is missing or mistyped)."""
        from verify.certificate_json import certificate_from_dict
        return certificate_from_dict(cls, d)

    def summary(self) -> str:
        """Human-readable certificate."""
        from verify.report import certificate_text  # plain text, no plotting
        return certificate_text(self)

    # ------------------------------------------------------------------ hand-off to the FHOCP
    @property
    def tightening(self) -> Tightening:
        """The certified :class:`tubekit.tightening.Tightening` (see :mod:`verify.handoff`).

        Raises :class:`NotCertifiedError` when not even the safe tier is certified: use
        :meth:`best_effort_tightening` for a run that carries no guarantee. When only the safe tier
        is certified, the safe-only tightening (``tiers == {"safe": True, "tracking": False}``).
        """
        from verify.handoff import tightening_of
        if not self.tiers["safe"]:
            names = ", ".join(f.condition for f in self.failures) or ", ".join(self.not_evaluated)
            raise NotCertifiedError(f"scenario '{self.scenario_name}' with law '{self.law}' is not certified "
                                    f"(failed: {names}); use best_effort_tightening() for a run without a "
                                    "guarantee")
        return tightening_of(self)

    def best_effort_tightening(self, min_input_fraction: float = 0.5) -> Tightening:
        """The certified tightening when a tier is certified; otherwise a best-effort one, flagged ``certified=False``.

        Parameters
        ----------
        min_input_fraction : float
            In (0, 1]: each best-effort input limit keeps at least this fraction of V.
        """
        from verify.handoff import tightening_of
        if isinstance(min_input_fraction, bool) or not isinstance(min_input_fraction, (int, float)) \
                or not (0 < min_input_fraction <= 1):
            raise ConfigError("min_input_fraction", "a number in (0, 1]", min_input_fraction)
        return tightening_of(self, float(min_input_fraction))


# --------------------------------------------------------------------------- certify
def sigma_candidates(scenario: Scenario) -> tuple[tuple[float, ...], str]:
    """σ values to try (1/s): the scenario's, else 0 and f / 2^k, k = 5..0 (f = ancillary rate)."""
    ctrl = scenario.controller
    if ctrl.sigma is not None:
        return (float(ctrl.sigma),), "controller.sigma"
    if _is_dynamic(scenario):
        return (0.0,), DYNAMIC_SIGMA_SOURCE
    f = float(ctrl.ancillary_rate_hz)
    return (0.0,) + tuple(f / 2 ** k for k in range(5, -1, -1)), "largest slack among the certified ones tried"


def _resolve_law(scenario: Scenario, law: str | AncillaryLaw | None) -> str:
    law = scenario.controller.law if law is None else law
    if isinstance(law, AncillaryLaw):
        law = register_law(law).name
    get_law(law)
    return law


def _is_dynamic(scenario: Scenario) -> bool:
    plant = getattr(scenario, "plant", None)
    return getattr(plant, "kind", "kinematic") == "dynamic"


def _dynamic_assumptions(scenario: Scenario, dist: DisturbanceBounds) -> tuple[str, ...]:
    """What the certificate takes from the dynamic plant's model (docs/plant.md)."""
    return ("Dynamic plant: the 4-DOF model of docs/plant.md (surge, sway, heave, yaw; no roll or pitch; the "
            "current's own acceleration neglected in the relative-velocity dynamics) with every hydrodynamic "
            "coefficient anywhere in its interval; the controller's feedforward uses the midpoints. The velocity "
            "loop's error and the hull's sway are derived from it (verify.vehicle.bound, "
            f"gamma_bar = {dist.gamma:.4g} m/s), not assumed.",
            "Dynamic plant: the run starts trimmed (body velocities equal to the first command, thrust equal to "
            "the feedforward).")


def _solve(scenario: Scenario, region: Region, gains: GainBounds, sigmas: tuple[float, ...]):
    """(dist, designs, best, safe, backup, loop, plant conditions): kinematic directly, dynamic by the fixed point."""
    if _is_dynamic(scenario):
        from verify.vehicle.compose import solve_dynamic
        sol = solve_dynamic(scenario, region, gains, sigmas)
        return sol.dist, list(sol.designs), sol.best, sol.safe, sol.backup, sol.loop, sol.conditions
    dist = disturbance_bounds(scenario)
    designs, best, safe, backup = solve_tiers(scenario, region, gains, sigmas, dist)
    return dist, list(designs), best, safe, backup, None, ()


def certify(scenario: Scenario, law: str | AncillaryLaw | None = None, *, region: Region | None = None,
            max_boxes: int = 4000) -> Certificate:
    """Certify ``scenario`` for an ancillary law (steps in the module doc).

    Parameters
    ----------
    scenario : Scenario
        Vehicle, limits, disturbance, trajectory, obstacles, sensing, ε, horizon, rates.
    law : str or AncillaryLaw, optional
        A registered law name or an :class:`AncillaryLaw` with ``symbolic_gain``; default the scenario's.
    region : Region, optional
        R; default :meth:`Region.from_scenario`.
    max_boxes : int
        Branch-and-bound budget per gain entry (boxes: a work unit, so the verdict is the same on any machine).

    Returns
    -------
    Certificate
    """
    t0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.scenario.Scenario", type(scenario).__name__)
    if not isinstance(max_boxes, int) or isinstance(max_boxes, bool) or max_boxes < 1:
        raise ConfigError("max_boxes", "an integer >= 1", max_boxes)
    law = _resolve_law(scenario, law)
    if region is None:
        region = Region.from_scenario(scenario)
    elif not isinstance(region, Region):
        raise ConfigError("region", "a verify.Region", type(region).__name__)
    gains = gain_bounds(law, region, max_boxes=max_boxes)
    sigmas, source = sigma_candidates(scenario)
    dist, designs, best, safe, backup, loop, plant_conds = _solve(scenario, region, gains, sigmas)
    tried = tuple(SigmaTrial(sigma=d.sigma, certified=d.certified, score=d.score if math.isfinite(d.score) else None,
                             failed=tuple(c.condition for c in d.failures)) for d in designs)
    ctrl = scenario.controller
    assumptions = ASSUMPTIONS + (_dynamic_assumptions(scenario, dist) if _is_dynamic(scenario) else ())
    return Certificate(scenario_name=scenario.name, law=law, region=region, gains=gains, disturbance=dist,
                       design=best, tried=tried, sigma_source=source,
                       elapsed_s=round(time.perf_counter() - t0, 3), horizon_steps=ctrl.horizon_steps, dt=ctrl.dt,
                       limits=tuple(float(x) for x in scenario.limits.vector),
                       scenario_data=to_jsonable(scenario.to_dict()), assumptions=assumptions,
                       design_fields=certificate_fields(scenario, law, key_sigma(best, safe, backup, plant_conds),
                                                        region),
                       paper_route=paper_route_of(scenario, law, region), backup=backup, safe_design=safe,
                       velocity_loop=loop, plant_conditions=plant_conds)


def certificate_fields(scenario: Scenario, law: str, sigma: float, region: Region) -> dict:
    """:func:`tubekit.design_key.design_fields`, plus ``region_override`` (the entries of ``region`` that differ
    from :meth:`Region.from_scenario`) when the certificate holds over another region than the scenario's."""
    fields = design_fields(scenario, law, sigma)
    default, used = Region.from_scenario(scenario).to_dict(), region.to_dict()
    override = {k: v for k, v in used.items() if k != "bearing" and v != default[k]}
    if override:
        fields["region_override"] = to_jsonable(override)
    return fields


def paper_route_of(scenario: Scenario, law: str, region: Region | None = None) -> Any:
    """The paper's Lemma-1 route over ``region`` (``verify.lemma1.route.paper_route``) when that module is
    present, else None.

    A report beside the verdict, never part of it (see ``docs/verify.md``).
    """
    if importlib.util.find_spec("verify.lemma1.route") is None:
        return None
    from verify.lemma1.route import paper_route
    return paper_route(scenario, law, region=region)
