"""The "certify, or take a given certificate" step of the app (the core never imports verify).

:func:`certify_design` certifies a scenario with :func:`verify.certify` (or takes a certificate
already computed) and returns a :class:`CertifiedDesign`: the certificate and the tightening a
run uses, its best-effort one when not certified. Whether the design is certified is stored
once, in :attr:`Tightening.certified <tubekit.tightening.Tightening.certified>`;
:class:`CertifiedDesign` only reads it. The runs themselves are :func:`tubekit.loop.pipeline.certified_run`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Any

import verify

from tubekit.scenario import Scenario
from tubekit.tightening import Tightening

__all__ = ["CertifiedDesign", "certify_design"]

LOGGER = logging.getLogger(__name__)


@dataclass(frozen=True)
class CertifiedDesign:
    """A certificate, the tightening the runs use and the time certifying took (s)."""

    certificate: Any
    tightening: Tightening
    certify_s: float

    @property
    def certified(self) -> bool:
        """The verdict, read from the tightening (its one store)."""
        return bool(self.tightening.certified)


def certify_design(scenario: Scenario, certificate: Any = None) -> CertifiedDesign:
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
