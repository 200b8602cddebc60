"""The "certify, or take a given certificate" step of the app (the core never imports verify).

:func:`certify_design` certifies a scenario with :func:`verify.certify` (or takes a certificate
already computed) and returns a :class:`CertifiedDesign`: the certificate and the tightening a
run uses, its best-effort one when not certified. Whether the design is certified is stored
once, in :attr:`Tightening.certified <tubekit.tightening.Tightening.certified>`;
:class:`CertifiedDesign` only reads it. The runs themselves are :func:`tubekit.loop.pipeline.certified_run`.

Campaigns certify on their workers (:func:`issue_certificate`) and keep each certificate by its
input key (:func:`input_key`: the key of :class:`tubekit.design_inputs.DesignInputs`, the one statement of
what :func:`verify.certify` reads, the start included). A stored certificate is used only through
:func:`load_certificate`: checksum, design key, then :meth:`tubekit.tightening.Tightening.require`
against the run's scenario.
"""

from __future__ import annotations

import json
import logging
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import verify
from verify.certificate import Certificate
from verify.certificate.jsonio import checksum_of

from tubekit.design_inputs import DesignInputs
from tubekit.exceptions import ConfigError
from tubekit.jsonable import write_json
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

__all__ = ["CertifiedDesign", "certify_design", "IssuedCertificate", "input_key", "issue_certificate",
           "load_certificate", "read_cached", "write_cached"]

LOGGER = logging.getLogger(__name__)


@dataclass(frozen=True)
class CertifiedDesign:
    """A certificate, the tightening the runs use and the time certifying took (s)."""

    certificate: Certificate
    tightening: Tightening
    certify_s: float

    @property
    def certified(self) -> bool:
        """The verdict, read from the tightening (its one store)."""
        return bool(self.tightening.certified)


def certify_design(scenario: Scenario, certificate: Certificate | None = None) -> CertifiedDesign:
    """Certify ``scenario`` with its own law (unless ``certificate`` is given); its best-effort tightening.

    Parameters
    ----------
    scenario : Scenario
        The design; ``scenario.controller.law`` is the law certified.
    certificate : verify.Certificate, optional
        A certificate already computed for ``scenario`` (then nothing is certified here).
    """
    started = time.perf_counter()
    if certificate is None:
        LOGGER.info("certifying %r (law %s) ...", scenario.name, scenario.controller.law)
        certificate = verify.certify(scenario, law=scenario.controller.law)
    tightening: Tightening = certificate.best_effort_tightening()
    design = CertifiedDesign(certificate, tightening, time.perf_counter() - started)
    LOGGER.info("  %s in %.1f s; sigma = %.4g, rho_tilde = %.4g",
                "certified" if design.certified else "NOT certified (best-effort tightening used)",
                design.certify_s, tightening.sigma, tightening.rho_tilde)
    return design


@dataclass(frozen=True)
class IssuedCertificate:
    """A certificate computed for one input key: its JSON dict (checksummed) and the tightening runs use."""

    key: str
    data: dict
    tightening: Tightening


def input_key(scenario: Scenario) -> str:
    """SHA-256 (hex) of what :func:`verify.certify` reads of ``scenario`` (:meth:`DesignInputs.key`, the declared σ
    included): equal keys share one certificate."""
    return DesignInputs.of(scenario).key()


def issue_certificate(scenario: Scenario) -> IssuedCertificate:
    """Certify ``scenario`` (a campaign worker's task): its key, certificate dict and best-effort tightening."""
    design = certify_design(scenario)
    return IssuedCertificate(input_key(scenario), design.certificate.to_dict(), design.tightening)


def load_certificate(data: Any, scenario: Scenario, where: str = "certificate") -> CertifiedDesign:
    """A stored certificate dict for ``scenario``, through the checks any given certificate passes.

    Raises
    ------
    ConfigError
        ``<where>.checksum`` (edited after issue), ``<where>.<key>`` (incomplete), ``<where>.design_key``
        (the key is not that of its design), ``design_key.<field>`` (issued for another design or start:
        :meth:`tubekit.tightening.Tightening.require`).
    """
    started = time.perf_counter()
    if not isinstance(data, dict):
        raise ConfigError(where, "a certificate JSON object", type(data).__name__)
    if data.get("checksum") != checksum_of(data):
        raise ConfigError(f"{where}.checksum", f"the SHA-256 of the content ({checksum_of(data)[:16]}...)",
                          data.get("checksum"), "the certificate was edited after issue")
    certificate = Certificate.from_dict(data)
    if certificate.design_key != data.get("design_key"):
        raise ConfigError(f"{where}.design_key", "the key of its design inputs", data.get("design_key"))
    tightening: Tightening = certificate.best_effort_tightening()
    tightening.require(scenario)
    return CertifiedDesign(certificate, tightening, time.perf_counter() - started)


def _cache_file(folder: Path, key: str) -> Path:
    return folder / f"{key}.json"


def read_cached(folder: str | Path, scenario: Scenario) -> CertifiedDesign | None:
    """The certificate of ``scenario`` stored in ``folder`` (None when absent), through :func:`load_certificate`."""
    path = _cache_file(Path(folder), input_key(scenario))
    if not path.exists():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ConfigError(str(path), "a certificate JSON file", str(exc), "delete it to certify again") from None
    return load_certificate(data, scenario, where=str(path))


def write_cached(folder: str | Path, issued: IssuedCertificate) -> Path:
    """Store ``issued`` as ``folder/<key>.json`` (atomic)."""
    Path(folder).mkdir(parents=True, exist_ok=True)
    return write_json(_cache_file(Path(folder), issued.key), issued.data)
