"""The certificate as an artefact people hand on: the record with its views (JSON, text, hand-off to the loop).

:class:`Certificate` is :class:`verify.certificate.record.CertificateRecord` plus the methods that use its
views: :meth:`Certificate.to_dict` / :meth:`Certificate.from_dict` (:mod:`verify.certificate.jsonio`,
exact inverses), :meth:`Certificate.summary` (:mod:`verify.certificate.report`: short, or full with
``verbose``) and the tightening a run uses (:mod:`verify.certificate.handoff`). The views import the record,
never this module, so the package has no import cycle and no untyped certificate.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from tubekit.exceptions import ConfigError, TubekitError
from tubekit.tightening import Tightening

from verify.certificate.handoff import tightening_of
from verify.certificate.jsonio import certificate_from_dict, certificate_to_dict
from verify.certificate.record import CertificateRecord
from verify.certificate.report import certificate_text, summary_text

__all__ = ["Certificate", "NotCertifiedError"]


class NotCertifiedError(TubekitError):
    """Raised by :attr:`Certificate.tightening` when not even the safe tier is certified."""


@dataclass(frozen=True)
class Certificate(CertificateRecord):
    """The result of :func:`verify.certify` (every part typed, see :class:`CertificateRecord`).

    ``Certificate.from_dict(c.to_dict()) == c``.
    """

    @property
    def is_certified(self) -> bool:
        """Alias of :attr:`certified`."""
        return self.certified

    # ------------------------------------------------------------------ output
    def to_dict(self) -> dict:
        """JSON-ready dict: verdict, theorem, its inputs, tube, margins, conditions, design key, checksum."""
        return certificate_to_dict(self)

    @classmethod
    def from_dict(cls, d: Any) -> "Certificate":
        """The certificate of a :meth:`to_dict` dict (ConfigError naming the key when one is missing or mistyped)."""
        return certificate_from_dict(cls, d)

    def summary(self, verbose: bool = False) -> str:
        """Human-readable certificate: the short one (at most about 25 lines: the verdict, each failed condition
        with the field and value that would make it hold, the tube, the backup, the design key), or with
        ``verbose`` the full text (every number, condition, premise and assumption)."""
        return certificate_text(self) if verbose else summary_text(self)

    # ------------------------------------------------------------------ hand-off to the FHOCP
    @property
    def tightening(self) -> Tightening:
        """The certified :class:`tubekit.tightening.Tightening` (see :mod:`verify.certificate.handoff`).

        Raises :class:`NotCertifiedError` when not even the safe tier is certified: use
        :meth:`best_effort_tightening` for a run that carries no guarantee. When only the safe tier
        is certified, the safe-only tightening (``tiers.safe_only``).
        """
        if not self.tiers.safe:
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
        if isinstance(min_input_fraction, bool) or not isinstance(min_input_fraction, (int, float)) \
                or not (0 < min_input_fraction <= 1):
            raise ConfigError("min_input_fraction", "a number in (0, 1]", min_input_fraction)
        return tightening_of(self, float(min_input_fraction))
