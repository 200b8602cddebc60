"""The certificate pipeline: :func:`certify` states a theorem about the loop that runs.

:func:`certify` is a short pipeline of named steps over the design (:class:`tubekit.design_inputs.DesignInputs`,
built from a scenario, the law and σ; the theorem reads nothing else):

1. :func:`verify.theorem.gains.gain_bounds` — entry bounds of the law's K and G = J K over R;
2. :func:`verify.theorem.design.disturbance_bounds` — ω̄_xy, ω̄_z, γ̄ from the models;
3. :meth:`DesignInputs.sigma_candidates` then :func:`verify.theorem.tiers.tracking_design` for each σ —
   the one-period tube, the per-arc margins, V̄ and every named condition, with the workspace conditions;
4. :func:`verify.theorem.design.choose_design` — the certified design with the largest normalised slack
   (or, when none certifies, the best uncertified one, for a best-effort run);
5. :func:`verify.theorem.tiers.safe_only_design` — when the chosen design does not certify, the
   safe tier's own design at σ = 0 (position margins only);
6. :func:`verify.theorem.tiers.backup_of` — the backup law and its safe set, proved for the hand-over of
   the margins in use; on the dynamic plant steps 2-6 are the fixed point of :mod:`verify.vehicle.compose`.

The answer is a :class:`verify.certificate.artefact.Certificate` holding the design with the σ it hands
out (:func:`tubekit.design_inputs.handed_sigma`).
"""

from __future__ import annotations

import importlib.util
from typing import TYPE_CHECKING
import math
import time

from tubekit.design_inputs import DesignInputs, handed_sigma
from tubekit.exceptions import ConfigError
from tubekit.model.ancillary import AncillaryLaw, get_law, register_law
from tubekit.scenario import Scenario

from verify.backup import BackupCertificate
from verify.certificate.artefact import Certificate, NotCertifiedError
from verify.certificate.record import ASSUMPTIONS, EXACT_SENSING, PREMISES, THEOREM
from verify.kernel.parts import SigmaTrial
from verify.kernel.region import Region
from verify.theorem.design import Condition, Design, DisturbanceBounds, disturbance_bounds
from verify.theorem.gains import GainBounds, gain_bounds
from verify.theorem.tiers import solve_tiers, tiers_of

if TYPE_CHECKING:  # loaded only when a dynamic scenario or the paper's route is certified
    from verify.lemma1.route import PaperRoute
    from verify.vehicle.bound import LoopBound

__all__ = ["certify", "resolve_law", "paper_route_of", "assumptions_of", "Certificate", "NotCertifiedError",
           "Condition", "ASSUMPTIONS", "PREMISES", "THEOREM"]


# --------------------------------------------------------------------------- certify
def resolve_law(law: str | AncillaryLaw) -> str:
    """The registered name of ``law`` (an :class:`AncillaryLaw` is registered first; ConfigError when unknown)."""
    if isinstance(law, AncillaryLaw):
        law = register_law(law).name
    get_law(law)
    return law


def _design_of(scenario: Scenario | DesignInputs, law: str | AncillaryLaw | None, region: Region | None
               ) -> tuple[DesignInputs, Region]:
    """The design to certify (the law resolved and registered, the region's override recorded) and its region R."""
    if isinstance(scenario, DesignInputs):
        inputs = scenario
        law = inputs.law if law is None else law
    elif isinstance(scenario, Scenario):
        inputs = DesignInputs.of(scenario)
    else:
        raise ConfigError("scenario", "a tubekit.Scenario or a tubekit.DesignInputs", type(scenario).__name__)
    law = resolve_law(inputs.law if law is None else law)
    default = Region.from_scenario(inputs.scenario)
    if region is None:
        region = default
    elif not isinstance(region, Region):
        raise ConfigError("region", "a verify.Region", type(region).__name__)
    used, base = region.to_dict(), default.to_dict()
    override = {k: v for k, v in used.items() if k != "bearing" and v != base[k]}
    return DesignInputs(inputs.scenario, law, inputs.sigma, tuple(override.items())), region


def _dynamic_assumptions(dist: DisturbanceBounds) -> tuple[str, ...]:
    """What the certificate takes from the dynamic plant's model (docs/plant.md): the whole list, eq. (11) not
    among it."""
    return ("Dynamic plant: the 4-DOF model of docs/plant.md (surge, sway, heave, yaw; no roll or pitch; the "
            "current's own acceleration neglected in the relative-velocity dynamics) with every hydrodynamic "
            "coefficient anywhere in its interval; the controller's feedforward uses the midpoints. The velocity "
            "loop's error and the sway (the hull's free sway, or with lateral thrust the sway loop's error) are "
            f"derived from it (verify.vehicle.bound, gamma_bar = {dist.gamma:.4g} m/s), not assumed.",
            "Dynamic plant: the run starts trimmed (body velocities equal to the first command, thrust equal to "
            "the feedforward).",
            "The simulator integrates the 4-DOF model with RK4 at a fixed step; the certificate bounds the exact "
            "solution, not the integration error.",
            EXACT_SENSING)


def assumptions_of(dynamic: bool, dist: DisturbanceBounds) -> tuple[str, ...]:
    """The assumptions outside the model a certificate states, by plant: :data:`ASSUMPTIONS` on the kinematic
    plant, the 4-DOF model's on the dynamic one (the one definition ``certify`` and ``recheck`` use)."""
    return _dynamic_assumptions(dist) if dynamic else ASSUMPTIONS


def _solve(scenario: Scenario, region: Region, gains: GainBounds, sigmas: tuple[float, ...]
           ) -> tuple[DisturbanceBounds, list[Design], Design, Design | None, BackupCertificate, LoopBound | None,
                      tuple[Condition, ...]]:
    """(dist, designs, best, safe, backup, loop, plant conditions): kinematic directly, dynamic by the fixed point."""
    if scenario.plant.dynamic:
        from verify.vehicle.compose import solve_dynamic
        sol = solve_dynamic(scenario, region, gains, sigmas)
        return sol.dist, list(sol.designs), sol.best, sol.safe, sol.backup, sol.loop, sol.conditions
    dist = disturbance_bounds(scenario)
    designs, best, safe, backup = solve_tiers(scenario, region, gains, sigmas, dist)
    return dist, list(designs), best, safe, backup, None, ()


def certify(scenario: Scenario | DesignInputs, law: str | AncillaryLaw | None = None, *,
            region: Region | None = None, max_boxes: int = 4000) -> Certificate:
    """Certify a design for an ancillary law (steps in the module doc).

    Parameters
    ----------
    scenario : Scenario or DesignInputs
        The design: a scenario (its own law and declared σ) or the design inputs themselves. The theorem
        reads only :class:`~tubekit.design_inputs.DesignInputs` (the start included).
    law : str or AncillaryLaw, optional
        A registered law name or an :class:`AncillaryLaw` with ``symbolic_gain``; default the design's.
    region : Region, optional
        R; default :meth:`Region.from_scenario`.
    max_boxes : int
        Branch-and-bound budget per gain entry (boxes: a work unit, so the verdict is the same on any machine).

    Returns
    -------
    Certificate
    """
    t0 = time.perf_counter()
    if not isinstance(max_boxes, int) or isinstance(max_boxes, bool) or max_boxes < 1:
        raise ConfigError("max_boxes", "an integer >= 1", max_boxes)
    inputs, region = _design_of(scenario, law, region)
    read = inputs.scenario
    gains = gain_bounds(inputs.law, region, max_boxes=max_boxes)
    sigmas, source = inputs.sigma_candidates()
    dist, designs, best, safe, backup, loop, plant_conds = _solve(read, region, gains, sigmas)
    tried = tuple(SigmaTrial(sigma=d.sigma, certified=d.certified, score=d.score if math.isfinite(d.score) else None,
                             failed=tuple(c.condition for c in d.failures)) for d in designs)
    assumptions = assumptions_of(inputs.dynamic, dist)
    handed = handed_sigma(tiers_of(best, safe, backup, plant_conds), best.sigma)
    return Certificate(inputs=inputs.with_sigma(handed), region=region, gains=gains, disturbance=dist, design=best,
                       tried=tried, sigma_source=source, elapsed_s=round(time.perf_counter() - t0, 3),
                       assumptions=assumptions, paper_route=paper_route_of(read, inputs.law, region), backup=backup,
                       safe_design=safe, velocity_loop=loop, plant_conditions=plant_conds)


def paper_route_of(scenario: Scenario, law: str, region: Region | None = None) -> PaperRoute | None:
    """The paper's Lemma-1 route over ``region`` (``verify.lemma1.route.paper_route``) when that module is
    present, else None.

    A report beside the verdict, never part of it (see ``docs/verify.md``).
    """
    if importlib.util.find_spec("verify.lemma1.route") is None:
        return None
    from verify.lemma1.route import paper_route
    return paper_route(scenario, law, region=region)
