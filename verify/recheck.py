"""Re-check a certificate from its JSON alone: no branch-and-bound, no fixed-point search.

:func:`recheck` takes what a certificate stores — the scenario, the theorem's
inputs (``problem``: limits, disturbance bounds, the law's gain bounds, σ, the
tick and period), the claimed tube, margins and V̄ — and re-derives, in Arb:

1. the disturbance bounds from the stored scenario (:func:`verify.design.disturbance_bounds`);
2. that the stored tube is a strict post-fixed point of the sampled-data map,
   F(x) < x (:func:`verify.sampled.tube_map`): the theorem's one-period claim;
3. that the stored per-arc margins cover the ones the stored tube implies
   (:func:`verify.sampled.horizon_margins`);
4. every condition, re-evaluated from those numbers (:func:`verify.design.input_tightening`,
   :func:`verify.design.state_conditions`), against the stored verdict;
5. the stored gain bounds against sampled values of K and J K (a sampled value above a stored
   bound refutes it; the bounds themselves are not re-proved here).

It shares the theorem's formulas with :mod:`verify.sampled` (one implementation of the
mathematics) and skips everything that searches: it confirms a certificate, it does not find one.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from flint import arb

from tubekit.exceptions import ConfigError
from tubekit.scenario import scenario_from_dict

from verify.design import disturbance_bounds, input_tightening, state_conditions, sway_condition
from verify.gains import gain_entries
from verify.intervals import upper
from verify.region import Region
from verify.sampled import HorizonMargins, PeriodTube, TubeProblem, horizon_margins, tube_map

__all__ = ["RecheckResult", "recheck", "recheck_file"]


@dataclass(frozen=True)
class RecheckResult:
    """Each re-check with its numbers; ``ok`` when all agree with the stored certificate."""

    checks: tuple[dict, ...]
    certified_claim: bool
    scenario: str = ""
    notes: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """Every re-check passed."""
        return all(c["ok"] for c in self.checks)

    @property
    def confirmed(self) -> bool:
        """The certificate claims 'certified' and every re-check agrees."""
        return self.certified_claim and self.ok

    def check(self) -> None:
        """Raise ConfigError naming the first re-check that failed."""
        for c in self.checks:
            if not c["ok"]:
                raise ConfigError(f"certificate.{c['name']}", c["expected"], c["found"])

    def summary(self) -> str:
        """One line per re-check, then the verdict."""
        lines = [f"recheck of '{self.scenario}' (claims {'CERTIFIED' if self.certified_claim else 'not certified'})"]
        lines += [f"  [{'ok  ' if c['ok'] else 'FAIL'}] {c['name']}: {c['found']} (expected {c['expected']})"
                  for c in self.checks]
        verdict = ("CONFIRMED" if self.confirmed else "agrees (not certified)" if self.ok else "DISAGREES")
        return "\n".join(lines + [f"verdict: {verdict}"])

    def to_dict(self) -> dict:
        """JSON-ready copy."""
        return {"scenario": self.scenario, "certified_claim": self.certified_claim, "ok": self.ok,
                "confirmed": self.confirmed, "checks": list(self.checks)}


def _check(name: str, ok: bool, found: Any, expected: str) -> dict:
    return {"name": name, "ok": bool(ok), "found": found, "expected": expected}


def _problem(d: dict) -> TubeProblem:
    p = dict(d)
    for k in ("k_abs", "g_off"):
        p[k] = tuple(tuple(float(x) for x in row) for row in p[k])
    for k in ("g_lo", "g_hi"):
        p[k] = tuple(float(x) for x in p[k])
    p["ticks"] = int(p["ticks"])
    return TubeProblem(**p)


def _tube_checks(p: TubeProblem, tube: dict, margins: dict | None, arcs: int) -> list[dict]:
    x = [arb(v) for v in (*tube["rho"], tube["theta"])]
    fx, cart = tube_map(p, x)
    strict = all(f < xi for f, xi in zip(fx, x))
    out = [_check("tube_post_fixed_point", strict, [upper(f) for f in fx], f"< stored {list(map(float, x))}")]
    kap_ok = all(upper(k) <= float(s) for k, s in zip(cart["kappa"], tube["kappa"]))
    out.append(_check("kappa_bar", kap_ok, [upper(k) for k in cart["kappa"]], f"<= stored {tube['kappa']}"))
    if margins is not None:
        pt = PeriodTube(rho=tuple(tube["rho"]), theta=tube["theta"], p_xy=tube["p_xy"], p_z=tube["p_z"],
                        psi=tube["psi"], kappa=tuple(tube["kappa"]), certified=True, iterations=0)
        again = horizon_margins(p, pt, arcs)
        cover = all(np.all(np.asarray(margins[k]) >= np.asarray(getattr(again, k)) - 1e-15) for k in margins)
        out.append(_check("margins", cover, again.to_dict(), "stored margins >= the ones the tube implies"))
    return out


def _gain_spot_checks(law: str, region: Region, gains: dict, n: int = 400) -> dict:
    """Sampled |K_jl| and G_jl must stay within the stored bounds (a refutation test, not a proof)."""
    rng = np.random.default_rng(0)
    ed = rng.uniform(region.e_d[0], region.e_d[1], n)
    eo = rng.uniform(region.e_o[0], region.e_o[1], n)
    worst = -math.inf
    for s in region.hemisphere_signs:
        K, G = gain_entries(law, s)
        for idx in range(9):
            j, l = divmod(idx, 3)
            fk = sp.lambdify(sp.symbols("e_d e_o", real=True), K[idx], "numpy")
            fg = sp.lambdify(sp.symbols("e_d e_o", real=True), G[idx], "numpy")
            kv = np.abs(np.broadcast_to(fk(ed, eo), ed.shape))
            gv = np.broadcast_to(fg(ed, eo), ed.shape)
            worst = max(worst, float(np.max(kv - gains["k_abs"][j][l])))
            if j == l:
                worst = max(worst, float(np.max(gv - gains["g_hi"][j])), float(np.max(gains["g_lo"][j] - gv)))
            else:
                worst = max(worst, float(np.max(np.abs(gv) - gains["g_off"][j][l])))
    return _check("gains_sampled", worst <= 1e-12, worst, "<= 0 (no sampled entry beyond its stored bound)")


def recheck(cert: dict) -> RecheckResult:
    """Re-check a certificate given as the dict of ``Certificate.to_dict()`` (module doc)."""
    try:
        scenario = scenario_from_dict(cert["scenario_data"])
        p = _problem(cert["problem"])
        region = Region(**{k: tuple(v) if isinstance(v, list) else v for k, v in cert["region"].items()
                           if k != "bearing"})
        claimed = bool(cert["certified"])
        tube, margins = cert["tube"], cert.get("margins")
    except (KeyError, TypeError, ValueError) as exc:
        raise ConfigError("certificate", "a certificate JSON written by tubekit certify --json", repr(exc)) from None
    dist = disturbance_bounds(scenario)
    checks = [_check("disturbance", dist.omega_xy <= p.omega_xy and dist.omega_z <= p.omega_z,
                     [dist.omega_xy, dist.omega_z], f"<= stored [{p.omega_xy}, {p.omega_z}]")]
    checks.append(_gain_spot_checks(cert["law"], region, cert["gains"]))
    if not tube.get("certified"):
        checks.append(_check("tube", not claimed, "no finite tube", "a certificate without a tube is not certified"))
        return RecheckResult(tuple(checks), claimed, cert.get("scenario", ""))
    arcs = int(cert["horizon"]["steps"])
    checks += _tube_checks(p, tube, margins, arcs)
    pt = PeriodTube(rho=tuple(tube["rho"]), theta=tube["theta"], p_xy=tube["p_xy"], p_z=tube["p_z"], psi=tube["psi"],
                    kappa=tuple(tube["kappa"]), certified=True, iterations=0)
    conds, v_bar = input_tightening(p, pt, dist)
    conds.insert(0, sway_condition(dist))
    m = HorizonMargins(**{k: tuple(v) for k, v in margins.items()})
    conds += state_conditions(scenario, region, p, m, v_bar)
    stored = {c["condition"]: c["ok"] for c in cert["conditions"]}
    for c in conds:
        checks.append(_check(f"condition {c.condition}", stored.get(c.condition) == c.ok, c.ok,
                             f"stored verdict {stored.get(c.condition)}"))
    all_hold = all(c.ok for c in conds) and all(c["ok"] for c in checks)
    checks.append(_check("verdict", all_hold == claimed, all_hold, f"stored certified = {claimed}"))
    return RecheckResult(tuple(checks), claimed, cert.get("scenario", ""))


def recheck_file(path: str | Path) -> RecheckResult:
    """:func:`recheck` of a certificate JSON file."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ConfigError("CERT", "a readable certificate JSON file", f"{path}: {exc}") from None
    if not isinstance(data, dict):
        raise ConfigError("CERT", "a JSON object", type(data).__name__)
    return recheck(data)
