"""The design contract: everything the certificate's theorem reads, as one frozen value.

A certificate (:func:`verify.certify`) is a theorem about one design. :class:`DesignInputs` holds it,
built from a scenario, the ancillary law and σ:

* ``scenario`` — the scenario reduced to what the theorem reads: the limits (and their rate), the
  trajectory, ε, the region, the obstacles, the vehicle radius, the sensing range, the workspace, the
  duration, **the start** (``initial_state``), the current's amplitude and constant, the sway model's
  gain, amplitude and bound, the controller's δ, N, ancillary rate and backup law's kind, and the plant (every vehicle
  parameter on the dynamic plant, intervals included). Every other field — the current's and the
  sway's periods, the FHOCP weights, modes, terminal level and backend, the declared σ and law, the
  plant as simulated (``plant.truth``: any point of the coefficient box is covered) — is reset to its
  default, so a certificate cannot depend on it. The name is kept as a label, outside the key;
* ``law`` — the ancillary law (a registered name);
* ``sigma`` — σ (1/s) of the design; ``None`` lets :func:`verify.certify` choose among
  :meth:`DesignInputs.sigma_candidates`, and a certificate stores the σ it hands out;
* ``region_override`` — the entries of the region R that differ from the scenario's, when the
  certificate was asked for another one.

Its derived values (``dt``, ``horizon_steps``, ``ticks_per_period``, ``tick``, ``v_max``, ``jump``,
``dynamic``) are the ones every part of the theorem and of the loop uses. :meth:`DesignInputs.key`
is the SHA-256 binding a certificate and its tightening to the design, :meth:`first_difference`
names the first field that differs and :meth:`covers` is the rule that a shorter run is covered.

The σ rules live here and nowhere else: :meth:`DesignInputs.sigma_candidates` (a declared σ is the
only candidate; the dynamic plant runs at σ = 0; otherwise 0 and f / 2^k) and :func:`handed_sigma`
(the safe tier alone hands out σ = 0). numpy and the standard library only: the loop checks the
contract without importing :mod:`verify`.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from tubekit.exceptions import ConfigError
from tubekit.jsonable import to_jsonable
from tubekit.model.kinematics import SwayModel
from tubekit.scenario import ControllerSettings, Disturbance, Scenario, scenario_from_dict
from tubekit.tiers import Tiers

__all__ = ["DesignInputs", "THEOREM_VERSION", "RATE_TOLERANCE", "ARC_SAMPLES", "DYNAMIC_SIGMA_SOURCE", "handed_sigma",
           "canonical"]

#: Version of the theorem a certificate states; a certificate of another version is not this design (6: the start
#: is part of the design; a plan is used with exactly N rows, projected onto V̄ and checked against V̄ exactly; 8: the
#: backup's anchor may be placed within its certified reach of the plan's end; 10: a vehicle with lateral thrust
#: regulates its sway by a loop of its own, whose error bound is the sway in omega_bar; 12: X_f's row faces cover
#: rate-limited plans, the backup is smooth under them; 13: the terminal set's search is refined where the coarse grid
#: has no set, so the same scenario may get another set; 14: a bearing face narrows the path's footprint to the sector
#: behind the target, and "none" is a backup kind; 15: the velocity loop's bound also takes the mass mismatch into the
#: state, so the same vehicle may get a smaller E and another backup; 16: it also splits each channel's own mass and
#: damping coefficients into cells, each cell's centre in the loop's matrix, so E shrinks again; 17: a bearing face
#: narrows the completion's lateral bound, and composes with the row faces under rate-limited plans, so the same
#: scenario may get another terminal set; 18: the yaw screen r_bar >= omega_bar_xy / epsilon is no condition where
#: step 17 covers the design, so a design it refused may certify; 19: under rate-limited plans the terminal law may
#: feed the line of sight's turn forward into its yaw row, a field of the terminal law).
THEOREM_VERSION = "sampled-data-tube+backup+velocity-loop+terminal/19"
#: Absolute tolerance (m/s, rad/s) of the plan check's rate rows (round-off only). The proof carries it: the
#: dynamic plant's velocity loop is bounded for command jumps of J + RATE_TOLERANCE (``verify.vehicle.compose``).
RATE_TOLERANCE = 1e-9
#: Points per arc at which a plan is checked (plus the arc's end, ``tubekit.loop.plan_check``); the theorem's
#: terminal ingredients pad each constraint by rate · (δ / ARC_SAMPLES) / 2 as the check does.
ARC_SAMPLES = 10
#: Why σ = 0 on the dynamic plant.
DYNAMIC_SIGMA_SOURCE = "dynamic plant: sigma = 0 (kappa = 0, so the velocity loop sees only bounded command jumps)"
#: Controller settings the theorem reads; the others are the FHOCP's own.
_READ_CONTROLLER = ("dt", "horizon_steps", "ancillary_rate_hz", "backup")


def canonical(value: Any) -> Any:
    """Numbers as floats (non-finite as text), tuples as lists, nested containers alike (JSON-ready)."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, (int, float, np.floating, np.integer)):
        x = float(value)
        return x if math.isfinite(x) else repr(x)
    if isinstance(value, dict):
        return {str(k): canonical(v) for k, v in value.items()}
    return [canonical(v) for v in value]


def _flatten(prefix: str, value: Any, out: dict[str, Any]) -> None:
    """Dicts and lists of dicts into dotted / indexed names; other values kept whole."""
    if isinstance(value, dict):
        for k in value:
            _flatten(f"{prefix}.{k}" if prefix else str(k), value[k], out)
    elif isinstance(value, (list, tuple)) and value and all(isinstance(v, dict) for v in value):
        for i, v in enumerate(value):
            _flatten(f"{prefix}[{i}]", v, out)
    else:
        out[prefix] = canonical(value)


def _what_is_read(scenario: Scenario) -> Scenario:
    """``scenario`` with every field the theorem does not read reset to its default (module doc)."""
    dist = scenario.disturbance
    sway = replace(dist.sway, period=SwayModel().period)
    ctrl = scenario.controller
    read_ctrl = replace(ControllerSettings(), **{k: getattr(ctrl, k) for k in _READ_CONTROLLER})
    return replace(scenario, disturbance=replace(dist, period=Disturbance().period, sway=sway),
                   controller=read_ctrl, plant=replace(scenario.plant, truth=()))


def handed_sigma(tiers: Tiers, chosen: float) -> float:
    """σ (1/s) of the tightening a certificate hands out: 0 when it gives the safe tier alone (the safe-only
    design runs without feedback), else the chosen design's σ."""
    return 0.0 if tiers.safe_only else float(chosen)


@dataclass(frozen=True)
class DesignInputs:
    """What the theorem reads (module doc). Build it with :meth:`of`.

    Attributes
    ----------
    scenario : Scenario
        The scenario reduced to what the theorem reads (other fields at their defaults).
    law : str
        The ancillary law's registered name.
    sigma : float or None
        σ (1/s); None: to be chosen by ``verify.certify``.
    region_override : tuple of (str, value)
        The region entries that differ from the scenario's (sorted by name; empty: the scenario's region).
    """

    scenario: Scenario
    law: str
    sigma: float | None = None
    region_override: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.scenario, Scenario):
            raise ConfigError("design.scenario", "a tubekit.Scenario", type(self.scenario).__name__)
        if not isinstance(self.law, str) or not self.law:
            raise ConfigError("design.law", "an ancillary law's name", self.law)
        if self.sigma is not None:
            if isinstance(self.sigma, bool) or not isinstance(self.sigma, (int, float)) \
                    or not (math.isfinite(self.sigma) and self.sigma >= 0):
                raise ConfigError("design.sigma", "a finite number >= 0 (1/s) or None", self.sigma)
            object.__setattr__(self, "sigma", float(self.sigma))
        object.__setattr__(self, "scenario", _what_is_read(self.scenario))
        object.__setattr__(self, "region_override", tuple(sorted((str(k), _frozen(v))
                                                                 for k, v in dict(self.region_override).items())))

    @classmethod
    def of(cls, scenario: Scenario, law: str | None = None, sigma: float | None = None, *,
           declared: bool = True, region_override: dict[str, Any] | None = None) -> "DesignInputs":
        """The design of ``scenario`` under ``law`` (default its own) at ``sigma`` (default: the scenario's
        declared σ when ``declared``, else None)."""
        if not isinstance(scenario, Scenario):
            raise ConfigError("scenario", "a tubekit.Scenario", type(scenario).__name__)
        if sigma is None and declared:
            sigma = scenario.controller.sigma
        return cls(scenario, scenario.controller.law if law is None else law, sigma,
                   tuple((region_override or {}).items()))

    def with_sigma(self, sigma: float) -> "DesignInputs":
        """The same design at ``sigma`` (1/s)."""
        return replace(self, sigma=sigma)

    # ------------------------------------------------------------------ derived values
    @property
    def name(self) -> str:
        """The scenario's label (not part of the key)."""
        return self.scenario.name

    @property
    def dt(self) -> float:
        """δ, the FHOCP period (s)."""
        return self.scenario.controller.dt

    @property
    def horizon_steps(self) -> int:
        """N, the number of arcs of a plan."""
        return self.scenario.controller.horizon_steps

    @property
    def ticks_per_period(self) -> int:
        """Ancillary ticks per FHOCP period."""
        return int(round(self.scenario.controller.ancillary_rate_hz * self.dt))

    @property
    def tick(self) -> float:
        """The ancillary tick 1 / f (s)."""
        return 1.0 / float(self.scenario.controller.ancillary_rate_hz)

    @property
    def v_max(self) -> np.ndarray:
        """V: [u_max, w_max, r_max] (m/s, m/s, rad/s)."""
        return self.scenario.limits.vector

    @property
    def jump(self) -> np.ndarray | None:
        """J = rate δ (3,): the largest change of the plans' command per period; None without a rate limit."""
        return self.scenario.limits.jump(self.dt)

    @property
    def dynamic(self) -> bool:
        """True on the dynamic (4-DOF) plant."""
        return self.scenario.plant.dynamic

    @property
    def start(self) -> tuple[float, float, float, float]:
        """The start [x, y, z, ψ] (m, rad)."""
        return self.scenario.initial_state

    # ------------------------------------------------------------------ the σ rule
    def sigma_candidates(self) -> tuple[tuple[float, ...], str]:
        """σ values to try (1/s) and why: the design's σ when set; 0 on the dynamic plant; else 0 and
        f / 2^k, k = 5..0 (f the ancillary rate in Hz)."""
        if self.sigma is not None:
            return (self.sigma,), "controller.sigma"
        if self.dynamic:
            return (0.0,), DYNAMIC_SIGMA_SOURCE
        f = float(self.scenario.controller.ancillary_rate_hz)
        return (0.0,) + tuple(f / 2 ** k for k in range(5, -1, -1)), "largest slack among the certified ones tried"

    # ------------------------------------------------------------------ the key
    def fields(self) -> dict[str, Any]:
        """The flat, canonical dict the key hashes: dotted names, numbers as floats."""
        data = self.scenario.to_dict()
        data.pop("name")
        data["controller"] = {k: data["controller"][k] for k in _READ_CONTROLLER if k in data["controller"]}
        data["disturbance"].pop("period")
        data["disturbance"]["sway"].pop("period")
        data.setdefault("plant", {"kind": "kinematic"})
        out: dict[str, Any] = {"theorem_version": THEOREM_VERSION, "law": self.law, "sigma": canonical(self.sigma)}
        for key in sorted(data):
            if key == "obstacles" and not data[key]:
                out["obstacles"] = []
            else:
                _flatten(key, data[key], out)
        if self.region_override:
            out["region_override"] = canonical(dict(self.region_override))
        return out

    def key(self) -> str:
        """SHA-256 (hex) of :meth:`fields` as canonical JSON (keys sorted, no spaces)."""
        return _hash(self.fields())

    def first_difference(self, other: "DesignInputs") -> tuple[str, Any, Any] | None:
        """``(name, other's value, this design's value)`` of the first field that differs, or None."""
        mine, theirs = self.fields(), other.fields()
        for name in list(theirs) + [k for k in mine if k not in theirs]:
            a, b = theirs.get(name, "absent"), mine.get(name, "absent")
            if canonical(a) != canonical(b):
                return name, a, b
        return None

    def covers(self, run: "DesignInputs") -> bool:
        """True when this (certified) design covers ``run``: the same design, or the same one run for a shorter
        time (the target stays in the workspace over a sub-interval too)."""
        return self.uncovered(run) is None

    def uncovered(self, run: "DesignInputs") -> tuple[str, Any, Any] | None:
        """The first field of ``run`` this design does not cover, as :meth:`first_difference` (None: covered)."""
        if run.scenario.duration <= self.scenario.duration:
            run = replace(run, scenario=replace(run.scenario, duration=self.scenario.duration))
        if run.key() == self.key():
            return None
        return self.first_difference(run) or ("design", "another design", "this design")

    # ------------------------------------------------------------------ JSON
    def to_dict(self) -> dict[str, Any]:
        """``{theorem_version, law, sigma, region_override, scenario}`` (the scenario as ``Scenario.to_dict``)."""
        return to_jsonable({"theorem_version": THEOREM_VERSION, "law": self.law, "sigma": self.sigma,
                            "region_override": dict(self.region_override), "scenario": self.scenario.to_dict()})

    @classmethod
    def from_dict(cls, d: Any, where: str = "design") -> "DesignInputs":
        """Inverse of :meth:`to_dict` (ConfigError naming ``where.<key>``; another theorem version is refused)."""
        if not isinstance(d, dict):
            raise ConfigError(where, "a JSON object", type(d).__name__)
        for key in ("theorem_version", "law", "sigma", "region_override", "scenario"):
            if key not in d:
                raise ConfigError(f"{where}.{key}", "present", "missing")
        if d["theorem_version"] != THEOREM_VERSION:
            raise ConfigError(f"{where}.theorem_version", THEOREM_VERSION, d["theorem_version"],
                              "a certificate of another theorem version: certify the scenario again")
        if not isinstance(d["region_override"], dict):
            raise ConfigError(f"{where}.region_override", "a JSON object", d["region_override"])
        try:
            scenario = scenario_from_dict(d["scenario"])
        except ConfigError as exc:
            raise ConfigError(f"{where}.scenario.{exc.field}", exc.expected, exc.received) from None
        sigma = d["sigma"]
        if sigma is not None and (isinstance(sigma, bool) or not isinstance(sigma, (int, float))):
            raise ConfigError(f"{where}.sigma", "a number or null", sigma)
        try:
            return cls(scenario, d["law"], sigma, tuple(d["region_override"].items()))
        except ConfigError as exc:
            name = exc.field[len("design."):] if exc.field.startswith("design.") else exc.field
            raise ConfigError(f"{where}.{name}", exc.expected, exc.received) from None


def _frozen(value: Any) -> Any:
    """Lists as tuples, recursively (a region entry stays hashable)."""
    return tuple(_frozen(v) for v in value) if isinstance(value, (list, tuple)) else value


def _hash(fields: dict[str, Any]) -> str:
    text = json.dumps(canonical(fields), sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()
