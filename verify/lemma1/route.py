"""The paper's route: Lemma 1's σ and tube radius from the certified L1, L2, J_lower, ξ̄ (a report, not the verdict).

Lemma 1 of the paper (continuous time, Lyapunov function ‖ρ‖²/2, ρ = e − ê):
with ‖h(e, v̂) − h(ê, v̂)‖ <= L1‖ρ‖, ‖ζ(e) − ζ(ê)‖ <= L2‖ρ‖, ‖ξ(e, ω)‖ <= ξ̄ and
ρᵀ J K ρ >= J_lower ‖ρ‖² (Remark 1, here for a law κ = −σ K(e) ρ; K = I is the paper's),

    σ > (L1 + L2) / J_lower  (eq. sigma)  gives  ‖ρ(t)‖ <= ρ̃ = ξ̄ / (σ J_lower − L1 − L2)  for all t.

:func:`paper_route` takes the four certified bounds of :func:`verify.lemma1.bounds.compute_bounds`
(each with its sampled value and gap) and evaluates these two formulas in Arb, rounded in the
safe direction (σ_min up, ρ̃ up). When J_lower's certified bound is not positive the formula
gives no σ and no tube, and the route says why. The route is reported beside the certificate's
sampled-data tube (:mod:`verify.theorem.sampled`), which is the verdict: :attr:`PaperRoute.why_not_the_verdict`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.model.ancillary import LAWS
from tubekit.scenario import Scenario

from verify.kernel.intervals import upper
from verify.lemma1.bounds import BoundResult, compute_bounds
from verify.kernel.parts import bound, flag, integer, item, number, text
from verify.kernel.region import Region

__all__ = ["PaperRoute", "RouteQuantity", "paper_route", "ROUTE_NAMES", "ROUTE_BUDGET", "ROUTE_GAP"]

#: Lemma 1's four quantities, in the order the paper uses them.
ROUTE_NAMES = ("L1", "L2", "J_lower", "xi_bar")
#: Branch-and-bound budget per quantity (boxes: a work unit, never the clock).
ROUTE_BUDGET = 200
#: Target relative gap between the sampled and the certified value.
ROUTE_GAP = 0.05
#: The σ rule when neither ``sigma`` nor the scenario's ``controller.sigma`` is given.
_TWICE = "twice (L1 + L2) / J_lower: the paper leaves sigma free above it"


@dataclass(frozen=True)
class RouteQuantity:
    """One of Lemma 1's quantities: the certified bound, a value attained at a point, their gap.

    Attributes
    ----------
    name : str
        ``L1`` (1/s), ``L2`` (1/s), ``J_lower`` (-) or ``xi_bar`` (m/s in e_d, 1/s in e_o).
    bound : float
        Certified: >= the true sup (L1, L2, xi_bar), <= the true inf (J_lower).
    sampled : float
        Attained at a point of the region (the true sup / inf lies between it and ``bound``).
    gap : float
        |bound − sampled| / |sampled|.
    converged : bool
        Whether the target gap was reached within the budget.
    boxes : int
        Boxes the branch-and-bound evaluated (work, not time).
    quantity, holds_over : str
        What is bounded, and over which set.
    """

    name: str
    bound: float
    sampled: float
    gap: float
    converged: bool
    boxes: int
    quantity: str
    holds_over: str

    @classmethod
    def of(cls, b: BoundResult) -> "RouteQuantity":
        """From a :class:`verify.lemma1.bounds.BoundResult` (drops its wall time and argmax)."""
        return cls(name=b.name, bound=b.bound, sampled=b.sampled, gap=b.gap, converged=b.converged, boxes=b.boxes,
                   quantity=b.quantity, holds_over=b.holds_over)

    def to_dict(self) -> dict:
        """``{bound, sampled, gap, converged, boxes, quantity, holds_over}`` (non-finite numbers as None)."""
        return {"bound": _num(self.bound), "sampled": _num(self.sampled), "gap": _num(self.gap),
                "converged": self.converged, "boxes": self.boxes, "quantity": self.quantity,
                "holds_over": self.holds_over}

    @classmethod
    def from_dict(cls, name: str, d: Any, where: str) -> "RouteQuantity":
        """Inverse of :meth:`to_dict`; ConfigError naming the key on a malformed block."""
        lo = -math.inf if name == "J_lower" else math.inf
        return cls(name=name, bound=bound(d, "bound", where, none=lo),
                   sampled=bound(d, "sampled", where, none=math.nan),
                   gap=bound(d, "gap", where), converged=bool(flag(d, "converged", where)),
                   boxes=integer(d, "boxes", where), quantity=text(d, "quantity", where),
                   holds_over=text(d, "holds_over", where))

    def line(self) -> str:
        """``name  certified <= bound  sampled ...  gap ...``."""
        rel = ">=" if self.name == "J_lower" else "<="
        return (f"{self.name:<8} certified {rel} {self.bound:<10.5g} sampled {self.sampled:<10.5g} "
                f"gap {100 * self.gap:.1f}%{'' if self.converged else ' (budget reached)'}")


@dataclass(frozen=True)
class PaperRoute:
    """Lemma 1 evaluated on the certified bounds: σ_min, σ, ρ̃ — or the reason the formula gives none.

    Attributes
    ----------
    law : str
        The ancillary law (K of κ = −σ K(e) ρ; J_lower is λ_min of the symmetric part of J K).
    quantities : tuple of RouteQuantity
        L1, L2, J_lower, xi_bar (:data:`ROUTE_NAMES` order).
    sigma_min : float or None
        (L1 + L2) / J_lower from the certified bounds, rounded up (1/s); eq. sigma needs σ > it.
    sigma : float or None
        The σ the radius is evaluated at (1/s); :attr:`sigma_rule` says where it comes from.
    sigma_rule : str
        ``argument``, ``scenario controller.sigma`` or the rule of twice σ_min.
    tube_radius : float or None
        ρ̃ = ξ̄ / (σ J_lower − L1 − L2), rounded up: a bound on the Euclidean ‖e − ê‖ (mixed units).
    reason : str or None
        Why there is no σ or no radius (None when both are given).
    why_not_the_verdict : str
        Why the certificate's sampled-data tube, not ρ̃, is the verdict.
    budget : int
        Branch-and-bound boxes per quantity.
    """

    law: str
    quantities: tuple[RouteQuantity, ...]
    sigma_min: float | None
    sigma: float | None
    sigma_rule: str
    tube_radius: float | None
    reason: str | None
    why_not_the_verdict: str
    budget: int

    def __getitem__(self, name: str) -> RouteQuantity:
        for q in self.quantities:
            if q.name == name:
                return q
        raise KeyError(name)

    @property
    def gives_tube(self) -> bool:
        """True when the paper's formula gives a σ and a finite radius."""
        return self.tube_radius is not None

    def to_dict(self) -> dict:
        """JSON-friendly; :meth:`from_dict` is its exact inverse."""
        return {"law": self.law, "quantities": {q.name: q.to_dict() for q in self.quantities},
                "sigma_min": self.sigma_min, "sigma": self.sigma, "sigma_rule": self.sigma_rule,
                "tube_radius": self.tube_radius, "reason": self.reason,
                "why_not_the_verdict": self.why_not_the_verdict, "budget": self.budget}

    @classmethod
    def from_dict(cls, d: Any, where: str = "certificate.paper_route") -> "PaperRoute":
        """Inverse of :meth:`to_dict`; ConfigError naming the key (``certificate.paper_route.sigma``) when malformed."""
        qd = item(d, "quantities", where)
        if not isinstance(qd, dict):
            raise ConfigError(f"{where}.quantities", "a JSON object", type(qd).__name__)
        quantities = tuple(RouteQuantity.from_dict(n, item(qd, n, f"{where}.quantities"), f"{where}.quantities.{n}")
                           for n in ROUTE_NAMES)
        return cls(law=text(d, "law", where), quantities=quantities, sigma_min=_optional(d, "sigma_min", where),
                   sigma=_optional(d, "sigma", where), sigma_rule=text(d, "sigma_rule", where),
                   tube_radius=_optional(d, "tube_radius", where), reason=_optional_text(d, "reason", where),
                   why_not_the_verdict=text(d, "why_not_the_verdict", where), budget=integer(d, "budget", where))

    def summary_lines(self) -> list[str]:
        """Printable lines: the four quantities, σ and ρ̃ (or why none), and why they are not the verdict."""
        lines = [f"paper's route (Lemma 1, continuous time; a reference, not the verdict), law {self.law!r}, "
                 f"budget {self.budget} boxes per quantity:"]
        lines += ["  " + q.line() for q in self.quantities]
        if self.sigma_min is not None:
            lines.append(f"  eq. sigma: sigma > (L1 + L2) / J_lower = {self.sigma_min:.5g} 1/s")
        if self.tube_radius is not None:
            lines.append(f"  at sigma = {self.sigma:.5g} 1/s ({self.sigma_rule}): rho_tilde = xi_bar / "
                         f"(sigma J_lower - L1 - L2) = {self.tube_radius:.5g} (bounds ||e - e_hat||)")
        else:
            lines.append(f"  no tube from Lemma 1: {self.reason}")
        lines.append(f"  why the sampled-data tube is the verdict: {self.why_not_the_verdict}")
        return lines


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def _optional(d: Any, key: str, where: str) -> float | None:
    return None if item(d, key, where) is None else number(d, key, where)


def _optional_text(d: Any, key: str, where: str) -> str | None:
    return None if item(d, key, where) is None else text(d, key, where)


# --------------------------------------------------------------------------- the paper's formula
def _sigma_min(q: dict[str, RouteQuantity]) -> tuple[float | None, str | None]:
    """(L1 + L2) / J_lower rounded up, or (None, why not)."""
    jl = q["J_lower"]
    lip = q["L1"].bound + q["L2"].bound
    if not all(math.isfinite(x) for x in (jl.bound, q["L1"].bound, q["L2"].bound)):
        return None, "a certified bound is not finite over the region (the branch-and-bound met a singularity)"
    if jl.bound > 0:
        return upper((arb(q["L1"].bound) + arb(q["L2"].bound)) / arb(jl.bound)), None
    if jl.sampled < 0:
        return None, (f"J_lower < 0: lambda_min((J K + (J K)^T)/2) = {jl.sampled:.4g} is attained in the region "
                      f"(Remark 1 is false for this law), so no sigma > 0 gives sigma J_lower > L1 + L2 = {lip:.4g}")
    return None, (f"J_lower's certified lower bound {jl.bound:.4g} is not positive (sampled {jl.sampled:.4g}; "
                  "raise the budget): eq. sigma cannot be met with it")


def _radius(q: dict[str, RouteQuantity], sigma: float) -> tuple[float | None, str | None]:
    """ξ̄ / (σ J_lower − L1 − L2) rounded up, or (None, why not)."""
    den = arb(sigma) * arb(q["J_lower"].bound) - arb(q["L1"].bound) - arb(q["L2"].bound)
    if not den > 0:
        return None, (f"sigma = {sigma:.5g} 1/s does not exceed (L1 + L2) / J_lower: sigma J_lower - L1 - L2 is not "
                      "positive, so Lemma 1 gives no radius")
    return upper(arb(q["xi_bar"].bound) / den), None


def _lemma1(q: dict[str, RouteQuantity], sigma: float | None, scenario_sigma: float | None
           ) -> tuple[float | None, float | None, str, float | None, str | None]:
    """(σ_min, σ, σ rule, ρ̃, reason) of Lemma 1 from the certified quantities ``q``."""
    s_min, why = _sigma_min(q)
    if sigma is not None:
        rule = "argument"
    elif scenario_sigma is not None:
        sigma, rule = float(scenario_sigma), "scenario controller.sigma"
    else:
        rule = _TWICE
        if s_min is not None:
            sigma = upper(arb(2) * arb(s_min))
    if s_min is None:
        return None, sigma, rule, None, why
    radius, why = _radius(q, float(sigma))
    return s_min, float(sigma), rule, radius, why


# --------------------------------------------------------------------------- why not the verdict
def _why_line(scenario: Scenario) -> str:
    """One line: what Lemma 1 assumes against what :mod:`tubekit.loop.closed_loop` runs (with the scenario's δ, h)."""
    c = scenario.controller
    h = 1.0 / c.ancillary_rate_hz
    return (f"Lemma 1 bounds a continuous-time loop (kappa = -sigma K(e)(e - e_hat) applied at every instant, "
            f"e_hat never reset, ||omega|| <= omega_bar); the loop that runs resets e_hat to the measured e every "
            f"delta = {c.dt:g} s and holds kappa_i = -sigma K(e_i)(e_i - e_hat_i) for h = {h:g} s ticks (ZOH), so "
            f"rho moves by (I - sigma h J K) rho_i plus the inter-tick drift (J(e) - J(e_i)) kappa_i, which Lemma 1 "
            f"omits (its rho_tilde -> 0 as sigma -> inf, while a held tick contracts only while |1 - sigma h g| < 1 "
            f"on the diagonal g of J K); the one-period box tube of verify.theorem.sampled bounds that loop (F(x) < x in "
            f"Arb, docs/verify.md section 3).")


# --------------------------------------------------------------------------- entry point
def paper_route(scenario: Scenario, law: str | None = None, *, region: Region | None = None,
                budget: int = ROUTE_BUDGET, sigma: float | None = None) -> PaperRoute:
    """Lemma 1's quantities over R, certified, and the σ and tube radius the paper's formula gives from them.

    Parameters
    ----------
    scenario : Scenario
        Supplies R (:meth:`verify.Region.from_scenario`), δ and the ancillary rate.
    law : str, optional
        Ancillary law name with a symbolic gain; default the scenario's ``controller.law``.
    region : Region, optional
        The set the bounds hold over; default the scenario's.
    budget : int
        Branch-and-bound boxes per quantity (a work unit: the same result on any machine).
    sigma : float, optional
        σ (1/s) to evaluate ρ̃ at; default ``controller.sigma``, else 2 (L1 + L2) / J_lower.

    Returns
    -------
    PaperRoute
    """
    if not isinstance(scenario, Scenario):
        raise ConfigError("scenario", "a tubekit.scenario.Scenario", type(scenario).__name__)
    law = scenario.controller.law if law is None else law
    if not isinstance(law, str) or law not in LAWS:
        raise ConfigError("law", f"one of {tuple(LAWS)}", law)
    if region is None:
        region = Region.from_scenario(scenario)
    elif not isinstance(region, Region):
        raise ConfigError("region", "a verify.Region", type(region).__name__)
    if not isinstance(budget, int) or isinstance(budget, bool) or budget < 1:
        raise ConfigError("budget", "an integer >= 1 (boxes per quantity)", budget)
    if sigma is not None and (isinstance(sigma, bool) or not isinstance(sigma, (int, float))
                              or not math.isfinite(sigma) or sigma <= 0):
        raise ConfigError("sigma", "a finite number > 0 (1/s)", sigma)
    bounds = compute_bounds(region, law, gap=ROUTE_GAP, max_boxes=budget, names=ROUTE_NAMES)
    q = {n: RouteQuantity.of(bounds[n]) for n in ROUTE_NAMES}
    s_min, s, rule, radius, reason = _lemma1(q, sigma, scenario.controller.sigma)
    return PaperRoute(law=law, quantities=tuple(q[n] for n in ROUTE_NAMES), sigma_min=s_min, sigma=s,
                      sigma_rule=rule, tube_radius=radius, reason=reason,
                      why_not_the_verdict=_why_line(scenario), budget=budget)
