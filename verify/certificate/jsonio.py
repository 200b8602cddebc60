"""A certificate as JSON and back: :meth:`Certificate.to_dict` / :meth:`Certificate.from_dict`, and the checksum.

The dict holds the typed parts (each with its own ``to_dict`` / ``from_dict``), the
numbers derived from them (``certified``, ``scenario``, ``law``, ``kappa_bar``, ``e_bar``, ``failures``,
``not_evaluated``, ``tiers``: written for readers, recomputed on reading, re-checked by
:mod:`verify.studies.recheck`), the design it holds for (``inputs``: :meth:`DesignInputs.to_dict`, stored
once) with its key (``design_key``) and a
``checksum``: SHA-256 over the canonical JSON of every other entry but ``elapsed_s``
(keys sorted, no spaces, numbers as Python writes them). The checksum is an integrity
check, not a signature: anyone can recompute it after an edit; it tells an accidental or
naive edit from the issued file, and :mod:`verify.studies.recheck` re-derives everything else.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import TYPE_CHECKING, Any, TypeVar

from tubekit.design_inputs import THEOREM_VERSION, DesignInputs
from tubekit.exceptions import ConfigError
from tubekit.jsonable import to_jsonable
from tubekit.model.terminal_law import TerminalLaw

from verify.backup import BackupCertificate
from verify.theorem.tiers import SAFE_PREFIX
from verify.theorem.design import Condition, Design, DisturbanceBounds
from verify.theorem.gains import GainBounds
from verify.certificate.record import CertificateRecord
from verify.kernel.parts import SigmaChoice, block, item, number, numbers, texts
from verify.kernel.region import Region
from verify.theorem.sampled import HorizonMargins, PeriodTube, TubeProblem

if TYPE_CHECKING:
    from verify.lemma1.route import PaperRoute
    from verify.vehicle.bound import LoopBound

#: The record type :func:`certificate_from_dict` builds (``Certificate`` or the bare record).
R = TypeVar("R", bound=CertificateRecord)

__all__ = ["certificate_to_dict", "certificate_from_dict", "checksum_of", "design_to_dict", "design_from_dict",
           "tiers_to_dict", "NOT_CHECKSUMMED", "TUBE_FORM"]

#: Entries outside the checksum: the checksum itself and the wall time (the one non-deterministic number).
NOT_CHECKSUMMED = ("checksum", "elapsed_s")
#: What the tube block describes (written beside the numbers).
TUBE_FORM = "box: |e_j - e_hat_j| <= rho_j within every FHOCP period (deviation restarts at 0)"


def checksum_of(d: dict) -> str:
    """SHA-256 (hex) of the canonical JSON of ``d`` without :data:`NOT_CHECKSUMMED`."""
    content = {k: v for k, v in d.items() if k not in NOT_CHECKSUMMED}
    text_ = json.dumps(content, sort_keys=True, separators=(",", ":"), allow_nan=False, ensure_ascii=False)
    return hashlib.sha256(text_.encode("utf-8")).hexdigest()


def certificate_to_dict(cert: CertificateRecord) -> dict:
    """The JSON dict of a :class:`verify.certificate.certify.Certificate` (module doc)."""
    d = cert.design
    tube = d.tube.to_dict()
    tube["form"] = TUBE_FORM
    e_bar = cert.e_bar
    out = to_jsonable({
        "certified": cert.certified, "scenario": cert.scenario_name, "law": cert.law, "theorem": cert.theorem,
        "theorem_version": THEOREM_VERSION, "region": cert.region.to_dict(),
        "disturbance": cert.disturbance.to_dict(), "gains": cert.gains.to_dict(), "sigma": cert.sigma.to_dict(),
        "problem": d.problem.to_dict(), "tube": tube,
        "margins": None if d.margins is None else d.margins.to_dict(), "v_bar": cert.v_bar,
        "kappa_bar": cert.kappa_bar, "e_bar": None if e_bar is None else e_bar.to_dict(),
        "arc_rates": list(d.rates), "terminal": None if d.terminal is None else d.terminal.to_dict(),
        "conditions": [c.to_dict() for c in cert.conditions],
        "failures": [{k: v for k, v in c.to_dict().items() if k != "ok"} for c in cert.failures],
        "not_evaluated": list(cert.not_evaluated), "assumptions": list(cert.assumptions),
        "premises": list(cert.premises), "inputs": cert.inputs.to_dict(), "design_key": cert.design_key,
        "elapsed_s": round(cert.elapsed_s, 3),
        "backup": None if cert.backup is None else cert.backup.to_dict(),
        "safe_design": None if cert.safe_design is None else design_to_dict(cert.safe_design),
        "tiers": tiers_to_dict(cert),
        "velocity_loop": None if cert.velocity_loop is None else cert.velocity_loop.to_dict(),
        "plant_conditions": [c.to_dict() for c in cert.plant_conditions],
    })
    if cert.paper_route is not None:
        out["paper_route"] = to_jsonable(cert.paper_route.to_dict())
    out["checksum"] = checksum_of(out)
    return out


def tiers_to_dict(cert: CertificateRecord) -> dict:
    """``{safe, tracking, depends_on: {tier: [names]}, failed: {tier: [names]}}`` (derived; re-checked by recheck)."""
    tc = cert.tier_conditions
    return {**cert.tiers.to_dict(), "depends_on": {k: [c.condition for c in v] for k, v in tc.items()},
            "failed": {k: list(v) for k, v in cert.tier_failures.items()}}


def design_to_dict(d: Design) -> dict:
    """A design as its own block (the safe-only design): σ, problem, tube, margins, V̄, conditions, arc rates."""
    return {"sigma": d.sigma, "problem": d.problem.to_dict(), "tube": d.tube.to_dict(),
            "margins": None if d.margins is None else d.margins.to_dict(),
            "v_bar": None if d.v_bar is None else list(d.v_bar), "conditions": [c.to_dict() for c in d.conditions],
            "arc_rates": list(d.rates)}


def design_from_dict(d: Any, where: str = "certificate.safe_design") -> Design:
    """Inverse of :func:`design_to_dict` (score -inf: a design outside the σ sweep)."""
    margins, v_bar = item(d, "margins", where), item(d, "v_bar", where)
    return Design(sigma=number(d, "sigma", where), problem=TubeProblem.from_dict(block(d, "problem", where)),
                  tube=PeriodTube.from_dict(block(d, "tube", where)),
                  margins=None if margins is None else HorizonMargins.from_dict(block(d, "margins", where)),
                  v_bar=None if v_bar is None else numbers(d, "v_bar", where, 3, none=None),
                  conditions=_conditions(d, where), score=-math.inf, rates=numbers(d, "arc_rates", where, 4))


def _conditions(d: dict, where: str = "certificate") -> tuple[Condition, ...]:
    conds = item(d, "conditions", where)
    if not isinstance(conds, list):
        raise ConfigError(f"{where}.conditions", "a list of conditions", type(conds).__name__)
    return tuple(Condition.from_dict(c, f"{where}.conditions[{i}]") for i, c in enumerate(conds))


def _plant_conditions(d: dict) -> tuple[Condition, ...]:
    """The dynamic plant's conditions (``plant_conditions``; absent in a kinematic certificate's dict: none)."""
    if item(d, "plant_conditions", "certificate") is None:
        return ()
    return _conditions({"conditions": d["plant_conditions"]}, "certificate.plant_conditions")


def _velocity_loop(d: dict) -> LoopBound | None:
    if item(d, "velocity_loop", "certificate") is None:
        return None
    from verify.vehicle.bound import LoopBound
    return LoopBound.from_dict(block(d, "velocity_loop", "certificate"))


def _design_conditions(d: dict) -> tuple[Condition, ...]:
    """The chosen design's conditions: the stored list without the safe-only (``safe_only.*``), backup
    (``backup*``) and dynamic plant ones, which their own blocks hold."""
    plant = {c.condition for c in _plant_conditions(d)}
    return tuple(c for c in _conditions(d) if not c.condition.startswith((SAFE_PREFIX, "backup"))
                 and c.condition not in plant)


def _design(d: dict, sigma: SigmaChoice) -> Design:
    """The chosen design: σ, problem, tube, margins, V̄, conditions, its score (from ``tried``), arc rates."""
    margins = item(d, "margins", "certificate")
    v_bar = item(d, "v_bar", "certificate")
    score = next((t.score for t in sigma.tried if t.sigma == sigma.value), None)
    return Design(sigma=sigma.value, problem=TubeProblem.from_dict(block(d, "problem", "certificate")),
                  tube=PeriodTube.from_dict(block(d, "tube", "certificate")),
                  margins=None if margins is None else HorizonMargins.from_dict(block(d, "margins", "certificate")),
                  v_bar=None if v_bar is None else numbers(d, "v_bar", "certificate", 3, none=None),
                  conditions=_design_conditions(d), score=-math.inf if score is None else score,
                  rates=numbers(d, "arc_rates", "certificate", 4), terminal=_terminal(d))


def _terminal(d: dict) -> TerminalLaw | None:
    """The tracking theorem's terminal set and law (``terminal``; None: not certified)."""
    if item(d, "terminal", "certificate") is None:
        return None
    return TerminalLaw.from_dict(d["terminal"], "certificate.terminal")


def _route(d: dict) -> PaperRoute | None:
    if d.get("paper_route") is None:
        return None
    from verify.lemma1.route import PaperRoute
    return PaperRoute.from_dict(block(d, "paper_route", "certificate"))


def certificate_from_dict(cls: type[R], d: Any) -> R:
    """The ``cls`` (:class:`verify.certificate.artefact.Certificate`) of :func:`certificate_to_dict`'s dict
    (exact inverse).

    Raises
    ------
    ConfigError
        Naming the first missing or mistyped key (``certificate.<key>``).
    """
    if not isinstance(d, dict):
        raise ConfigError("certificate", "a JSON object", type(d).__name__)
    sigma = SigmaChoice.from_dict(block(d, "sigma", "certificate"))
    return cls(
        inputs=DesignInputs.from_dict(block(d, "inputs", "certificate"), "certificate.inputs"),
        region=Region.from_dict(block(d, "region", "certificate")),
        gains=GainBounds.from_dict(block(d, "gains", "certificate")),
        disturbance=DisturbanceBounds.from_dict(block(d, "disturbance", "certificate")),
        design=_design(d, sigma), tried=sigma.tried, sigma_source=sigma.source,
        elapsed_s=number(d, "elapsed_s", "certificate"),
        assumptions=texts(d, "assumptions", "certificate"), premises=texts(d, "premises", "certificate"),
        paper_route=_route(d),
        backup=None if item(d, "backup", "certificate") is None else BackupCertificate.from_dict(
            block(d, "backup", "certificate")),
        safe_design=None if item(d, "safe_design", "certificate") is None else design_from_dict(
            block(d, "safe_design", "certificate")),
        velocity_loop=_velocity_loop(d), plant_conditions=_plant_conditions(d))
