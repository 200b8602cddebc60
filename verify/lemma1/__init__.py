"""The paper's continuous-time Lemma 1: L1, L2, J_lower, ξ̄ and the σ and tube radius they give (a reference)."""

from __future__ import annotations

from verify.lemma1.bounds import BOUND_NAMES, BoundResult, Bounds, compute_bounds
from verify.lemma1.polar import PolarModel, law_gain, polar_model
from verify.lemma1.route import ROUTE_BUDGET, ROUTE_NAMES, PaperRoute, RouteQuantity, paper_route

__all__ = ["compute_bounds", "Bounds", "BoundResult", "BOUND_NAMES", "PolarModel", "polar_model", "law_gain",
           "paper_route", "PaperRoute", "RouteQuantity", "ROUTE_NAMES", "ROUTE_BUDGET"]
