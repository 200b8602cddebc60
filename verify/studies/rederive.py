"""The re-derivation behind :func:`verify.studies.recheck.recheck`: every input and output of the theorem from the scenario.

:func:`rederive` rebuilds the design from the stored scenario with the functions
:func:`verify.certify` uses (no second implementation of the theorem) and compares each
stored number with the derived one in the direction that matters (:class:`Ledger`):
``at_least`` for upper bounds (tube, margins, κ̄, ω̄, arc rates), ``at_most`` for what the
certificate grants (V̄, the upper ends of Ē), ``equal`` for the theorem's inputs (region,
limits, N, δ, σ, the problem's entries, premises, assumptions).

On the dynamic plant (:func:`_plant_bounds`) everything is derived for the *stored* backup law and safe set:
the fixed point's assumption E_a is the scenario's (:func:`verify.vehicle.compose.solve_dynamic`, the one number
the certificate does not store exactly), and at it :func:`verify.vehicle.compose.loop_for_law` derives ω̄, the
stored law's per-tick jumps (its ramp, fades, bands and their command rate), the loop bound E and the plant's
conditions (``loop_consistent``: E < E_a). Every stored ``velocity_loop`` field is compared in its direction
(:func:`_loop_fields`) and every derived plant condition must be in the stored ``plant_conditions`` and in the
loop's own list, with a verdict not stronger than derived (:func:`_listed`).
"""

from __future__ import annotations

from dataclasses import replace

from tubekit.design_inputs import THEOREM_VERSION, DesignInputs, handed_sigma
from tubekit.exceptions import ConfigError
from tubekit.scenario import Scenario

from verify.certificate.record import CertificateRecord
from verify.studies.ledger import Ledger
from verify.kernel.region import Region
from verify.theorem.design import Condition, Design, DisturbanceBounds
from verify.theorem.sampled import TubeProblem
from verify.vehicle.result import LoopBound

__all__ = ["Ledger", "rederive"]


def _region(scenario: Scenario, cert: CertificateRecord) -> Region:
    """R of the stored design: the scenario's, with the stored override."""
    kw = {k: tuple(v) if isinstance(v, (list, tuple)) else v for k, v in cert.inputs.region_override}
    return Region.from_scenario(scenario, **kw)


def _key(raw: dict, cert: CertificateRecord, led: Ledger, sigma: float) -> None:
    """The stored key against the key of the stored design, and that design against the one re-derived: the stored
    scenario and law at the derived σ of the tightening handed out (:func:`tubekit.design_inputs.handed_sigma`)."""
    stored_key = raw.get("design_key")
    led.check("design_key", stored_key == cert.design_key, stored_key, cert.design_key,
              "the hash of the stored design inputs", by="design key")
    derived = DesignInputs(cert.inputs.scenario, cert.law, sigma, cert.inputs.region_override)
    diff = cert.inputs.first_difference(derived)
    name = "inputs" if diff is None else f"inputs.{diff[0]}"
    led.check(name, diff is None and derived.key() == cert.design_key, None if diff is None else diff[2],
              None if diff is None else diff[1], "the design of the stored scenario, law and derived sigma",
              by="design key")
    led.equal("theorem_version", raw.get("theorem_version"), THEOREM_VERSION)


def _inputs(raw: dict, cert: CertificateRecord, scenario: Scenario, region: Region, dist: DisturbanceBounds,
            led: Ledger) -> None:
    """R, the theorem's text and the disturbance bounds (V, N and δ are read from the one stored design)."""
    from verify.certificate.record import THEOREM
    led.equal("scenario", raw.get("scenario"), scenario.name)
    led.equal("law", raw.get("law"), cert.law)
    led.equal("theorem", raw.get("theorem"), THEOREM)
    for k, v in region.to_dict().items():
        if k != "bearing":
            led.equal(f"region.{k}", cert.region.to_dict()[k], v)
    free, source = replace(cert.inputs, sigma=None).sigma_candidates()
    declared = cert.sigma_source == "controller.sigma"
    sigmas = (cert.design.sigma,) if declared else free
    led.check("sigma.value", cert.design.sigma in sigmas, cert.design.sigma, list(sigmas),
              "the declared sigma, or one of the candidates")
    if not declared:
        led.equal("sigma.source", cert.sigma_source, source)
    for k in ("omega_xy", "omega_z", "gamma", "yaw_rate_error"):
        led.at_least(f"disturbance.{k}", getattr(cert.disturbance, k), getattr(dist, k))
    led.equal("disturbance.declared_sway", cert.disturbance.declared_sway, dist.declared_sway)


def _gains(cert: CertificateRecord, region: Region, boxes: int, led: Ledger) -> None:
    from verify.theorem.gains import prove_gain_bounds
    for proof in prove_gain_bounds(cert.law, region, cert.gains, boxes):
        led.check(proof.name, proof.status == "proved", proof.stored, f"{proof.status} (sampled {proof.witness:.6g})",
                  f"proved in Arb within {boxes} boxes")


def _problem(cert: CertificateRecord, derived: TubeProblem, led: Ledger) -> None:
    stored = cert.design.problem.to_dict()
    for k, v in derived.to_dict().items():
        if k in ("omega_xy", "omega_z", "yaw_rate_error"):
            led.at_least(f"problem.{k}", stored[k], v)
        else:
            led.equal(f"problem.{k}", stored[k], v)


def _tube(raw: dict, cert: CertificateRecord, design: Design, led: Ledger) -> None:
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


def _e_bar(raw: dict, region: Region, design: Design, led: Ledger) -> None:
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


def _verdicts(raw: dict, cert: CertificateRecord, design: Design, derived: tuple, scenario: Scenario,
              led: Ledger) -> None:
    """Each condition's verdict (``derived``: every derived condition, the tiers'), the failure list, the
    certified flag, the premises and assumptions."""
    from verify.certificate.certify import assumptions_of
    from verify.certificate.record import PREMISES
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
    led.equal("assumptions", list(cert.assumptions), list(assumptions_of(scenario.plant.dynamic, dist)))
    led.equal("premises", list(cert.premises), list(PREMISES))
    trial = next((t for t in cert.tried if t.sigma == cert.design.sigma), None)
    led.check("sigma.tried", trial is not None and (not trial.certified or design.certified),
              None if trial is None else trial.certified, design.certified,
              "the chosen sigma among those tried, its verdict not stronger than derived")


def _listed(name: str, stored: tuple[Condition, ...], derived: tuple[Condition, ...], led: Ledger) -> None:
    """Every derived condition present in the stored list ``name`` (a missing one is a disagreement), with a verdict
    not stronger than derived."""
    have = {c.condition: c for c in stored}
    for c in derived:
        s = have.get(c.condition)
        if s is None:
            led.check(f"{name}[{c.condition}]", False, "missing", c.ok, "every derived condition stored")
        else:
            led.check(f"{name}[{c.condition}].ok", not (s.ok is True and c.ok is not True), s.ok, c.ok,
                      "a verdict not stronger than derived")


#: The loop bound's upper bounds (stored >= derived) and what it grants (stored <= derived: lower bounds).
_LOOP_BOUNDS = ("jump_tick", "jump_period", "error", "a_bound", "z_bound", "accel_bound", "w_start", "w_rate", "w_n",
                "thrust_peak")
_LOOP_GRANTED = ("authority", "thrust_floor")
_ROWS = ("e", "a", "z", "ydot")


def _loop_fields(stored: LoopBound, derived: LoopBound, led: Ledger) -> None:
    """Every stored ``velocity_loop`` field against the bound derived for the stored law: the inputs (V, h, δ, the
    slopes λ, the terms summed) equal; the first command's box (None: V), the jumps, E, the other bounds, the sway,
    the fixed point's assumption and the response sums at least derived (a smaller assumption claims the state never reaches it: stronger); the
    authority and the thrust floor at most derived; the loop's conditions listed. ``iterations`` and ``reason``
    are reports (the conditions carry the verdicts)."""
    led.equal("velocity_loop.v_max", list(stored.v_max), list(derived.v_max))
    led.equal("velocity_loop.tick", stored.tick, derived.tick)
    led.equal("velocity_loop.period", stored.period, derived.period)
    led.equal("velocity_loop.slope", list(stored.slope), list(derived.slope))
    led.each("at_least", "velocity_loop.first_command", list(stored.first_command or stored.v_max),
             list(derived.first_command or derived.v_max))
    for k in _LOOP_BOUNDS:
        led.each("at_least", f"velocity_loop.{k}", list(getattr(stored, k)), list(getattr(derived, k)))
    for k in _LOOP_GRANTED:
        led.each("at_most", f"velocity_loop.{k}", list(getattr(stored, k)), list(getattr(derived, k)))
    led.at_least("velocity_loop.sway", stored.sway, derived.sway)
    led.check("velocity_loop.assumed (length)", len(stored.assumed) == len(derived.assumed), len(stored.assumed),
              len(derived.assumed), "one row per channel")
    for i, (s, d) in enumerate(zip(stored.assumed, derived.assumed)):
        led.each("at_least", f"velocity_loop.assumed[{i}]", list(s), list(d))
    for i, (s, d) in enumerate(zip(stored.gains, derived.gains)):
        where = f"velocity_loop.gains[{i}]"
        for group in ("tick", "period", "peak"):
            for o, row in enumerate(_ROWS):
                led.each("at_least", f"{where}.{group}.{row}", list(getattr(s, group)[o]), list(getattr(d, group)[o]))
        led.at_least(f"{where}.rho", s.rho, d.rho)
        led.equal(f"{where}.terms", s.terms, d.terms)
    _listed("velocity_loop.conditions", stored.conditions, derived.conditions, led)


def _plant_bounds(cert: CertificateRecord, scenario: Scenario, region: Region, sigma: float, led: Ledger
                  ) -> tuple[DisturbanceBounds, tuple[Condition, ...]]:
    """Dynamic plant: the fixed point re-derived for the stored backup law (module doc); every stored
    ``velocity_loop`` field and plant condition compared. Returns the derived ω̄ and the plant's conditions."""
    from verify.vehicle.compose import loop_for_law, solve_dynamic
    sol = solve_dynamic(scenario, region, cert.gains, (sigma,))  # E_a: the scenario's fixed point
    dist, loop, plant = sol.dist, sol.loop, sol.conditions
    if cert.backup is not None:  # a missing backup is named by the backup's check
        given = loop_for_law(scenario, cert.backup.law, cert.backup.safe_set, sol.assumed, sigma, sol.assumed_sway)
        dist, loop, plant = given.dist, given.loop, given.conditions
    if cert.velocity_loop is None:
        led.check("velocity_loop", False, None, "a velocity_loop block", "a dynamic certificate carries its loop bound")
    else:
        _loop_fields(cert.velocity_loop, loop, led)
    _listed("plant_conditions", cert.plant_conditions, plant, led)
    return dist, plant


def _tracking_bounds(scenario: Scenario, dist: DisturbanceBounds) -> DisturbanceBounds:
    """The bound the tracking design is derived at: on the dynamic plant the plans-only loop bound's
    (:func:`verify.vehicle.compose.tracking_disturbance`, ``docs/verify.md`` step 17d), else ``dist``."""
    if not scenario.plant.dynamic:
        return dist
    from verify.vehicle.compose import tracking_disturbance
    track = tracking_disturbance(scenario)
    return dist if track is None else track


def rederive(raw: dict, cert: CertificateRecord, led: Ledger, gain_boxes: int) -> None:
    """Every re-check after the checksum (module doc), appended to ``led`` in order."""
    from verify.theorem.design import disturbance_bounds, tube_problem
    from verify.studies.rederive_tiers import check_tiers, derive_tiers
    from verify.theorem.tiers import tier_conditions, tiers_of, tracking_design
    from tubekit.model.ancillary import get_law
    scenario = cert.inputs.scenario
    try:
        get_law(cert.law)
    except ConfigError as exc:
        raise ConfigError("certificate.law", exc.expected, exc.received) from None
    try:
        region = _region(scenario, cert)
    except ConfigError as exc:
        raise ConfigError(f"certificate.inputs.region_override ({exc.field})", exc.expected,
                          exc.received) from None
    sigma = cert.design.sigma
    dist, plant = _plant_bounds(cert, scenario, region, sigma, led) if scenario.plant.dynamic else (
        disturbance_bounds(scenario), ())
    track = _tracking_bounds(scenario, dist)
    design = tracking_design(scenario, region, cert.gains, sigma, track)
    tiers = derive_tiers(cert, scenario, region, dist, design)
    design = tiers.design or design
    safe, backup = tiers.safe, tiers.backup
    _key(raw, cert, led, handed_sigma(tiers_of(design, safe, backup, plant), sigma))
    _inputs(raw, cert, scenario, region, dist, led)
    _gains(cert, region, gain_boxes, led)
    _problem(cert, tube_problem(scenario, region, cert.gains, sigma, track), led)
    _tube(raw, cert, design, led)
    _e_bar(raw, region, design, led)
    led.equal("terminal", None if cert.design.terminal is None else cert.design.terminal.to_dict(),
              None if design.terminal is None else design.terminal.to_dict())
    check_tiers(raw, cert, design, tiers, led, plant)
    derived = tier_conditions(design, safe, backup, plant)
    backup_part = derived["tracking"][len(design.conditions):]
    every = design.conditions + (safe.conditions if safe is not None else ()) + backup_part
    _verdicts(raw, cert, design, every, scenario, led)
