"""The paper as printed: its error dynamics (eqs. 17-18) and the audit against the derivation (sympy)."""

from __future__ import annotations

from tubekit.paper.audit import AuditReport, HemisphereCheck, TermAudit, audit, derived_terms
from tubekit.paper.equations import TERM_NAMES, printed_terms

__all__ = ["audit", "AuditReport", "TermAudit", "HemisphereCheck", "derived_terms", "printed_terms", "TERM_NAMES"]
