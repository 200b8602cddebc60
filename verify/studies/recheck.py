"""Re-check a certificate JSON from its stored scenario up: checksum, design key, then every number re-derived.

:func:`recheck` reads the JSON into a typed :class:`verify.certificate.certify.Certificate`
(``Certificate.from_dict``: a missing block, a wrong type or text that is not JSON is a
:class:`ConfigError` naming the key, exit 2 on the CLI), then

1. **checksum** — SHA-256 of the canonical content (:func:`verify.certificate.jsonio.checksum_of`);
   a mismatch is reported first as "edited after issue" (an integrity check, not a signature);
2. **design key** — the key of the stored scenario, law and σ (:mod:`tubekit.design_key`)
   against the stored key and fields, naming the first field that differs;
3. **re-derivation** (:mod:`verify.studies.rederive`) — from the stored scenario alone, with the
   functions :func:`verify.certify` uses: R (:meth:`Region.from_scenario`), V, the target
   speeds, N and δ, the disturbance bounds (:func:`verify.theorem.design.disturbance_bounds`), the σ
   candidates, the stored gain bounds re-proved in Arb (:func:`verify.theorem.gains.prove_gain_bounds`,
   a smaller box budget), the tube fixed point, the per-arc margins, V̄, κ̄, Ē, the arc rates
   and every condition (:func:`verify.theorem.tiers.tracking_design`), the verdict, the premises and
   assumptions; the backup — the stored law and safe set re-certified with the re-derived bounds
   and margins — the safe-only design and the tiers (:mod:`verify.studies.rederive_tiers`); on the
   dynamic plant, the velocity loop's bound and the fixed point's conditions derived for the *stored*
   backup law (its ramp, fades, bands and the command rate they give: ``verify.vehicle.compose.loop_for_law``),
   every stored loop field compared in its direction and every derived plant condition required.

A stored number *stronger* than the derived one (a smaller bound, a larger V̄ or Ē, a
verdict ``ok`` where the derivation fails) is a disagreement naming the field (exit 3); a
*weaker* one is reported as a note, not an error. Recheck trusts the choice among the σ
candidates (any candidate is a theorem; the chosen one is re-derived) and the paper-route
report (never part of the verdict).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tubekit.exceptions import ConfigError

__all__ = ["RecheckResult", "recheck", "recheck_file", "GAIN_PROOF_BOXES"]

#: Box budget per gain entry of the Arb re-proof (certify uses 4000 to find the bounds).
GAIN_PROOF_BOXES = 1500


@dataclass(frozen=True)
class RecheckResult:
    """Each re-check (``name``, ``ok``, ``stored``, ``derived``, ``rule``, ``by``) and the notes on weaker numbers."""

    checks: tuple[dict, ...]
    certified_claim: bool
    scenario: str = ""
    notes: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """Every re-check passed."""
        return all(c["ok"] for c in self.checks)

    @property
    def edited(self) -> bool:
        """The checksum does not match the content: the file was edited after issue."""
        return any(c["name"] == "checksum" and not c["ok"] for c in self.checks)

    @property
    def confirmed(self) -> bool:
        """The certificate claims 'certified' and every re-check agrees."""
        return self.certified_claim and self.ok

    @property
    def failed(self) -> tuple[dict, ...]:
        """The re-checks that disagree, in order (checksum, design key, then the re-derivation)."""
        return tuple(c for c in self.checks if not c["ok"])

    def check(self) -> None:
        """Raise ConfigError naming the first re-check that failed."""
        for c in self.failed:
            raise ConfigError(f"certificate.{c['name']}", f"{c['rule']}; derived {c['derived']!r}", c["stored"])

    def summary(self) -> str:
        """The verdict's reasons: edited-after-issue first, each disagreement, the notes, then the verdict."""
        lines = [f"recheck of '{self.scenario}' (claims {'CERTIFIED' if self.certified_claim else 'not certified'})"]
        if self.edited:
            lines.append("  edited after issue: the checksum does not match the content")
        lines += [f"  [FAIL] {c['name']}: stored {c['stored']!r}, derived {c['derived']!r} ({c['rule']}; "
                  f"caught by {c['by']})" for c in self.failed]
        lines.append(f"  {sum(c['ok'] for c in self.checks)} of {len(self.checks)} re-checks agree")
        lines += [f"  note: {n}" for n in self.notes]
        verdict = "CONFIRMED" if self.confirmed else "agrees (not certified)" if self.ok else "DISAGREES"
        return "\n".join(lines + [f"verdict: {verdict}"])

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return {"scenario": self.scenario, "certified_claim": self.certified_claim, "ok": self.ok,
                "edited": self.edited, "confirmed": self.confirmed, "checks": list(self.checks),
                "notes": list(self.notes)}


def recheck(cert: dict, *, gain_boxes: int = GAIN_PROOF_BOXES) -> RecheckResult:
    """Re-check a certificate given as the dict of ``Certificate.to_dict()`` (module doc).

    Raises
    ------
    ConfigError
        The dict is not a complete certificate (names the key).
    """
    from verify.certificate.artefact import Certificate
    from verify.certificate.jsonio import checksum_of
    from verify.kernel.parts import flag, text
    from verify.studies.rederive import Ledger, rederive

    if not isinstance(cert, dict):
        raise ConfigError("certificate", "a JSON object written by tubekit certify --json", type(cert).__name__)
    stored_sum = text(cert, "checksum", "certificate")
    claimed = bool(flag(cert, "certified", "certificate"))
    typed = Certificate.from_dict(cert)
    ledger = Ledger()
    ledger.check("checksum", stored_sum == checksum_of(cert), stored_sum, checksum_of(cert),
                 "the SHA-256 of the content (else: edited after issue)", by="checksum")
    rederive(cert, typed, ledger, gain_boxes)
    return RecheckResult(tuple(ledger.checks), claimed, typed.scenario_name, tuple(ledger.notes))


def recheck_file(path: str | Path) -> RecheckResult:
    """:func:`recheck` of a certificate JSON file (ConfigError ``CERT`` when it is not a JSON object)."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ConfigError("CERT", "a readable certificate JSON file", f"{path}: {exc}") from None
    if not isinstance(data, dict):
        raise ConfigError("CERT", "a JSON object", type(data).__name__)
    return recheck(data)
