"""The re-derivation behind :func:`verify.recheck.recheck`: every input and output of the theorem from the scenario.

:func:`rederive` rebuilds the design from the stored scenario with the functions
:func:`verify.certify` uses (no second implementation of the theorem) and compares each
stored number with the derived one in the direction that matters (:class:`Ledger`):
``at_least`` for upper bounds (tube, margins, κ̄, ω̄, arc rates), ``at_most`` for what the
certificate grants (V̄, the upper ends of Ē), ``equal`` for the theorem's inputs (region,
limits, N, δ, σ, the problem's entries, premises, assumptions).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from tubekit.design_key import THEOREM_VERSION, design_key, first_difference
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario, scenario_from_dict

__all__ = ["Ledger", "rederive"]

_BY = "re-derivation"


@dataclass
class Ledger:
    """The checks made so far (in order) and the notes on stored numbers weaker than derived."""

    checks: list[dict] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def check(self, name: str, ok: bool, stored: Any, derived: Any, rule: str, by: str = _BY) -> None:
        """Record one check: the stored and the derived value, the rule relating them, what makes it."""
        self.checks.append({"name": name, "ok": bool(ok), "stored": stored, "derived": derived, "rule": rule,
                            "by": by})

    def equal(self, name: str, stored: Any, derived: Any) -> None:
        """An input of the theorem: stored == derived."""
        self.check(name, _same(stored, derived), stored, derived, "an input of the theorem: equal")

    def at_least(self, name: str, stored: float | None, derived: float | None) -> None:
        """An upper bound: stored >= derived (smaller is stronger: a disagreement; larger: a note)."""
        s, d = _num(stored, math.inf), _num(derived, math.inf)
        self.check(name, s >= d, stored, derived, "a bound: stored >= derived (a smaller one is not proved)")
        if s > d:
            self.notes.append(f"{name}: stored {stored} is weaker than derived {derived}")

    def at_most(self, name: str, stored: float | None, derived: float | None) -> None:
        """What the certificate grants (V̄, an upper end of Ē): stored <= derived."""
        s, d = _num(stored, -math.inf), _num(derived, -math.inf)
        self.check(name, s <= d, stored, derived, "granted: stored <= derived (more is not proved)")
        if s < d:
            self.notes.append(f"{name}: stored {stored} is weaker than derived {derived}")

    def each(self, how: str, name: str, stored: Any, derived: Any) -> None:
        """``at_least`` / ``at_most`` per entry, after an equal-length check."""
        s, d = list(stored or []), list(derived or [])
        if len(s) != len(d):
            self.check(f"{name} (length)", False, len(s), len(d), "one entry per derived entry")
            return
        for i, (a, b) in enumerate(zip(s, d)):
            getattr(self, how)(f"{name}[{i}]", a, b)


def _num(x: Any, none: float) -> float:
    return none if x is None else float(x)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))


def _scenario(cert: Any) -> Scenario:
    try:
        return scenario_from_dict(cert.scenario_data)
    except ConfigError as exc:
        raise ConfigError(f"certificate.scenario_data.{exc.field}", exc.expected, exc.received) from None


def _region(scenario: Scenario, cert: Any):
    from verify.region import Region
    override = cert.design_fields.get("region_override") or {}
    if not isinstance(override, dict):
        raise ConfigError("certificate.design_fields.region_override", "a JSON object", override)
    kw = {k: tuple(v) if isinstance(v, list) else v for k, v in override.items()}
    return Region.from_scenario(scenario, **kw)


def _key(raw: dict, cert: Any, scenario: Scenario, region: Any, led: Ledger, sigma: float) -> None:
    """The stored key against its own fields and against the key of the stored scenario, law and the derived
    σ of the tightening handed out (:func:`verify.tiers.key_sigma`)."""
    from verify.certificate import certificate_fields
    stored_key = raw.get("design_key")
    led.check("design_key", stored_key == cert.design_key, stored_key, cert.design_key,
              "the hash of the stored design_fields", by="design key")
    derived = certificate_fields(scenario, cert.law, sigma, region)
    diff = first_difference(derived, cert.design_fields)
    name = "design_fields" if diff is None else f"design_fields.{diff[0]}"
    led.check(name, diff is None and design_key(derived) == cert.design_key, None if diff is None else diff[2],
              None if diff is None else diff[1], "the design of the stored scenario, law and sigma", by="design key")
    led.equal("theorem_version", raw.get("theorem_version"), THEOREM_VERSION)


def _inputs(raw: dict, cert: Any, scenario: Scenario, region: Any, dist: Any, led: Ledger) -> None:
    """R, V, N, δ, σ and the disturbance bounds."""
    from verify.certificate import THEOREM, sigma_candidates
    led.equal("scenario", cert.scenario_name, scenario.name)
    led.equal("theorem", raw.get("theorem"), THEOREM)
    for k, v in region.to_dict().items():
        if k != "bearing":
            led.equal(f"region.{k}", cert.region.to_dict()[k], v)
    led.equal("limits", list(cert.limits), [float(x) for x in scenario.limits.vector])
    led.equal("horizon.steps", cert.horizon_steps, scenario.controller.horizon_steps)
    led.equal("horizon.dt", cert.dt, scenario.controller.dt)
    sigmas, source = sigma_candidates(scenario)
    led.check("sigma.value", cert.design.sigma in sigmas, cert.design.sigma, list(sigmas), "one of the candidates")
    led.equal("sigma.source", cert.sigma_source, source)
    for k in ("omega_xy", "omega_z", "gamma", "yaw_rate_error"):
        led.at_least(f"disturbance.{k}", getattr(cert.disturbance, k), getattr(dist, k))
    led.equal("disturbance.declared_sway", cert.disturbance.declared_sway, dist.declared_sway)


def _gains(cert: Any, region: Any, boxes: int, led: Ledger) -> None:
    from verify.gains import prove_gain_bounds
    for proof in prove_gain_bounds(cert.law, region, cert.gains, boxes):
        led.check(proof.name, proof.status == "proved", proof.stored, f"{proof.status} (sampled {proof.witness:.6g})",
                  f"proved in Arb within {boxes} boxes")


def _problem(cert: Any, derived: Any, led: Ledger) -> None:
    stored = cert.design.problem.to_dict()
    for k, v in derived.to_dict().items():
        if k in ("omega_xy", "omega_z", "yaw_rate_error"):
            led.at_least(f"problem.{k}", stored[k], v)
        else:
            led.equal(f"problem.{k}", stored[k], v)


def _tube(raw: dict, cert: Any, design: Any, led: Ledger) -> None:
    st, dt = cert.design.tube, design.tube
    if st.certified:
        led.check("tube.certified", dt.certified, st.certified, dt.certified, "a finite tube derived")
    led.each("at_least", "tube.rho", st.rho, dt.rho)
    for k in ("theta", "p_xy", "p_z", "psi", "contraction"):
        led.at_least(f"tube.{k}", getattr(st, k), getattr(dt, k))
    led.each("at_least", "tube.kappa", st.kappa, dt.kappa)
    stored_kb, derived_kb = raw.get("kappa_bar"), list(dt.kappa) if dt.certified else None
    if stored_kb is None or derived_kb is None:
        led.check("kappa_bar", stored_kb is None, stored_kb, derived_kb, "null when no finite tube is derived")
    else:
        led.each("at_least", "kappa_bar", stored_kb, derived_kb)
    if cert.design.margins is not None or design.margins is not None:
        sm, dm = cert.design.margins, design.margins
        if sm is not None and dm is None:
            led.check("margins", False, "margins", None, "no margins without a finite derived tube")
        for k in ("e_d", "e_z", "e_o", "position"):
            led.each("at_least", f"margins.{k}", getattr(sm, k) if sm else [], getattr(dm, k) if dm else [])
    led.each("at_most", "v_bar", raw.get("v_bar") or [], list(design.v_bar or []))
    led.each("at_least", "arc_rates", list(cert.design.rates), list(design.rates))


def _e_bar(raw: dict, region: Any, design: Any, led: Ledger) -> None:
    stored, m = raw.get("e_bar"), design.margins
    if m is None:
        led.check("e_bar", stored is None, stored, None, "null when no margins are derived")
        return
    if not isinstance(stored, dict):
        led.check("e_bar", False, stored, "an E_bar", "an E_bar when margins are derived")
        return
    for k in ("e_d", "e_z", "e_o"):
        lo, hi = getattr(region, k)[0] + getattr(m, k)[-1], getattr(region, k)[1] - getattr(m, k)[-1]
        pair = stored.get(k) if isinstance(stored.get(k), list) and len(stored.get(k)) == 2 else [None, None]
        led.at_least(f"e_bar.{k}[0]", pair[0], lo)      # a lower end below the derived one claims more
        led.at_most(f"e_bar.{k}[1]", pair[1], hi)


def _verdicts(raw: dict, cert: Any, design: Any, derived: tuple, scenario: Scenario, led: Ledger) -> None:
    """Each condition's verdict (``derived``: every derived condition, the tiers'), the failure list, the
    certified flag, the premises and assumptions."""
    from verify.certificate import ASSUMPTIONS, PREMISES, _dynamic_assumptions, _is_dynamic
    stored = {c.condition: c for c in cert.conditions}
    for c in derived:
        s = stored.get(c.condition)
        if s is None:
            led.check(f"conditions[{c.condition}]", False, "missing", c.ok, "every condition of the theorem stored")
            continue
        led.check(f"conditions[{c.condition}].ok", not (s.ok is True and c.ok is not True), s.ok, c.ok,
                  "a verdict not stronger than derived")
        if s.ok is not True and c.ok is True:
            led.notes.append(f"conditions[{c.condition}]: stored {s.ok}, derived True")
    extra = sorted(set(stored) - {c.condition for c in derived})
    if extra:
        led.notes.append(f"stored conditions not in the theorem: {extra}")
    derived_failed = {c.condition for c in derived if c.ok is False}
    listed = {f.get("condition") for f in raw.get("failures") or [] if isinstance(f, dict)}
    led.check("failures", derived_failed <= listed, sorted(listed), sorted(derived_failed),
              "every derived failure listed")
    unevaluated = [c.condition for c in derived if c.ok is None]
    led.check("not_evaluated", set(unevaluated) <= set(raw.get("not_evaluated") or []), raw.get("not_evaluated"),
              unevaluated, "every condition not evaluated listed")
    claimed = raw.get("certified") is True
    everything = all(c.ok is True for c in derived)
    led.check("certified", not claimed or (everything and cert.certified), raw.get("certified"),
              everything, "not stronger than the derived conditions (both tiers)")
    dist = cert.disturbance
    assumptions = ASSUMPTIONS + (_dynamic_assumptions(scenario, dist) if _is_dynamic(scenario) else ())
    led.equal("assumptions", list(cert.assumptions), list(assumptions))
    led.equal("premises", list(cert.premises), list(PREMISES))
    trial = next((t for t in cert.tried if t.sigma == cert.design.sigma), None)
    led.check("sigma.tried", trial is not None and (not trial.certified or design.certified),
              None if trial is None else trial.certified, design.certified,
              "the chosen sigma among those tried, its verdict not stronger than derived")


def _plant_bounds(cert: Any, scenario: Any, region: Any, sigma: float, led: Ledger) -> tuple[Any, tuple]:
    """Dynamic plant: the loop bound's fixed point re-derived (:func:`verify.vehicle.compose.solve_dynamic`); the stored
    bound must be at least the derived one. Returns the derived ω̄ and the plant's conditions."""
    from verify.vehicle.compose import solve_dynamic
    sol = solve_dynamic(scenario, region, cert.gains, (sigma,))
    stored = cert.velocity_loop
    if stored is None:
        led.check("velocity_loop", False, None, "a velocity_loop block", "a dynamic certificate carries its loop bound")
    else:
        led.each("at_least", "velocity_loop.error", list(stored.error), list(sol.loop.error))
        led.at_least("velocity_loop.sway", stored.sway, sol.loop.sway)
    return sol.dist, sol.conditions


def rederive(raw: dict, cert: Any, led: Ledger, gain_boxes: int) -> None:
    """Every re-check after the checksum (module doc), appended to ``led`` in order."""
    from verify.design import disturbance_bounds, tube_problem
    from verify.rederive_tiers import check_tiers, derive_tiers
    from verify.tiers import key_sigma, tier_conditions, tracking_design
    from tubekit.model.ancillary import get_law
    scenario = _scenario(cert)
    try:
        get_law(cert.law)
    except ConfigError as exc:
        raise ConfigError("certificate.law", exc.expected, exc.received) from None
    try:
        region = _region(scenario, cert)
    except ConfigError as exc:
        raise ConfigError(f"certificate.design_fields.region_override ({exc.field})", exc.expected,
                          exc.received) from None
    sigma = cert.design.sigma
    dist, plant = _plant_bounds(cert, scenario, region, sigma, led) if scenario.plant.dynamic else (
        disturbance_bounds(scenario), ())
    design = tracking_design(scenario, region, cert.gains, sigma, dist)
    tiers = derive_tiers(cert, scenario, region, dist, design)
    safe, backup = tiers.safe, tiers.backup
    _key(raw, cert, scenario, region, led, key_sigma(design, safe, backup, plant))
    _inputs(raw, cert, scenario, region, dist, led)
    _gains(cert, region, gain_boxes, led)
    _problem(cert, tube_problem(scenario, region, cert.gains, sigma, dist), led)
    _tube(raw, cert, design, led)
    _e_bar(raw, region, design, led)
    check_tiers(raw, cert, design, tiers, led, plant)
    derived = tier_conditions(design, safe, backup, plant)
    backup_part = derived["tracking"][len(design.conditions):]
    every = design.conditions + (safe.conditions if safe is not None else ()) + backup_part
    _verdicts(raw, cert, design, every, scenario, led)
