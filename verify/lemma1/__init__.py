"""The paper's continuous-time Lemma-1 quantities (L1, L2, J_lower, ξ̄): a reference, not the verdict."""

from __future__ import annotations

from verify.lemma1.bounds import BOUND_NAMES, BoundResult, Bounds, compute_bounds
from verify.lemma1.polar import PolarModel, law_gain, polar_model

__all__ = ["compute_bounds", "Bounds", "BoundResult", "BOUND_NAMES", "PolarModel", "polar_model", "law_gain"]
