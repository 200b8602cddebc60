"""The design key: a canonical SHA-256 of everything the certificate's theorem reads.

A certificate (:func:`verify.certify`) holds for one design: the scenario fields the
theorem reads, the ancillary law, the gain σ and the theorem's version. The key binds
a :class:`tubekit.tightening.Tightening` to that design, so a run can refuse a
tightening issued for another one (:func:`require_matching`) before anything runs.

The fields (:func:`design_fields`, a flat dict of dotted names, numbers as floats):
``theorem_version``, ``law``, ``sigma``; ``limits.*``, ``trajectory.*``, ``epsilon``,
``region.*``, ``disturbance.amplitude``, ``disturbance.constant``,
``disturbance.sway.{gain, amplitude, bound}``, ``obstacles[i].{center, radius}``,
``vehicle_radius``, ``sensing_range``, ``workspace``, ``duration`` (the target must stay in
the workspace over the run, ``target_in_workspace``),
``controller.{dt, horizon_steps, ancillary_rate_hz}``, ``plant.*`` (``plant.kind`` only
on the kinematic plant; on the dynamic plant every vehicle parameter, intervals included, but not
``plant.truth``: the coefficients of the plant as simulated may be any point of the box the
certificate covers). A run shorter than the certified duration is covered
(:func:`require_matching` accepts it). The backup law and its safe set are derived from
these (ω̄, V, the ancillary rate, the margins), so they need no field of their own. Not in
the key, because the theorem does not read them: the name, the current's and the sway's
periods, the initial state (each run's start is checked by the run itself), the FHOCP
weights and modes. numpy and the standard library only: the loop checks the key without
importing :mod:`verify`.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Any

from tubekit.exceptions import ConfigError

__all__ = ["THEOREM_VERSION", "design_fields", "design_key", "first_difference", "require_matching"]

#: Version of the theorem a certificate states; a certificate of another version is not this design (5: the ramped
#: backup blends the last applied command and a rate-limited run starts at rest).
THEOREM_VERSION = "sampled-data-tube+backup+velocity-loop/5"

_SCENARIO_KEYS = ("limits", "trajectory", "epsilon", "region", "obstacles", "vehicle_radius", "sensing_range",
                  "workspace", "duration")
_CONTROLLER_KEYS = ("dt", "horizon_steps", "ancillary_rate_hz")
_SWAY_KEYS = ("gain", "amplitude", "bound")


def _canonical(value: Any) -> Any:
    """Numbers as floats (non-finite as text), tuples as lists, nested containers alike."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, (int, float)) or hasattr(value, "__float__") and not hasattr(value, "__len__"):
        x = float(value)
        return x if math.isfinite(x) else repr(x)
    if isinstance(value, dict):
        return {str(k): _canonical(v) for k, v in value.items()}
    return [_canonical(v) for v in value]


def _flatten(prefix: str, value: Any, out: dict[str, Any]) -> None:
    """Dicts and lists of dicts into dotted / indexed names; other values kept whole."""
    if isinstance(value, dict):
        for k in value:
            _flatten(f"{prefix}.{k}", value[k], out)
    elif isinstance(value, (list, tuple)) and value and all(isinstance(v, dict) for v in value):
        for i, v in enumerate(value):
            _flatten(f"{prefix}[{i}]", v, out)
    else:
        out[prefix] = _canonical(value)


def design_fields(scenario: Any, law: str, sigma: float) -> dict[str, Any]:
    """The flat, canonical dict of what the theorem reads (module doc).

    Parameters
    ----------
    scenario : tubekit.scenario.Scenario
        The scenario (only its ``to_dict()`` is read).
    law : str
        Ancillary law name.
    sigma : float
        Ancillary gain σ of the design (1/s).
    """
    d = scenario.to_dict()
    out: dict[str, Any] = {"theorem_version": THEOREM_VERSION, "law": str(law), "sigma": _canonical(sigma)}
    for key in _SCENARIO_KEYS:
        if key == "obstacles" and not d.get(key):
            out["obstacles"] = []
            continue
        _flatten(key, d.get(key), out)
    dist = d["disturbance"]
    out["disturbance.amplitude"] = _canonical(dist["amplitude"])
    out["disturbance.constant"] = _canonical(dist["constant"])
    for k in _SWAY_KEYS:
        out[f"disturbance.sway.{k}"] = _canonical(dist["sway"][k])
    for k in _CONTROLLER_KEYS:
        out[f"controller.{k}"] = _canonical(d["controller"][k])
    plant = d.get("plant", {"kind": "kinematic"})
    if plant.get("kind", "kinematic") == "kinematic":
        out["plant.kind"] = "kinematic"
    else:  # the plant as simulated (``truth``) is any point of the coefficient box the theorem covers
        _flatten("plant", {k: v for k, v in plant.items() if k != "truth"}, out)
    return out


def design_key(fields: dict[str, Any]) -> str:
    """SHA-256 (hex) of ``fields`` as canonical JSON (keys sorted, no spaces)."""
    text = json.dumps(_canonical(fields), sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def first_difference(found: dict[str, Any], stored: dict[str, Any]) -> tuple[str, Any, Any] | None:
    """``(name, found value, stored value)`` of the first field that differs (``"absent"`` if missing)."""
    for name in list(found) + [k for k in stored if k not in found]:
        a, b = found.get(name, "absent"), stored.get(name, "absent")
        if _canonical(a) != _canonical(b):
            return name, a, b
    return None


def _shorter_run_is_covered(found: dict[str, Any], stored: dict[str, Any]) -> None:
    """A run no longer than the certified duration is covered (the target stays in the workspace over a
    sub-interval too): ``found["duration"]`` takes the stored value then."""
    a, b = found.get("duration"), stored.get("duration")
    if isinstance(a, float) and isinstance(b, float) and a <= b:
        found["duration"] = b


def require_matching(scenario: Any, tightening: Any, law: str | None = None, sigma: float | None = None) -> None:
    """Refuse a tightening certified for another design than ``scenario``'s (nothing runs then).

    Parameters
    ----------
    scenario : tubekit.scenario.Scenario
        The scenario about to run.
    tightening : tubekit.tightening.Tightening
        Its tightening; one without a design key (the untightened baseline) is not checked.
    law : str, optional
        The law the run uses (default the scenario's).
    sigma : float, optional
        The σ the run uses (1/s); default the scenario's declared σ, else the tightening's; a safe-only
        tightening (``tiers == {"safe": True, "tracking": False}``) runs at its own σ = 0.

    Raises
    ------
    ConfigError
        ``design_key.<field>`` naming the first differing field, with the scenario's and the
        certificate's values.
    """
    stored_key = getattr(tightening, "design_key", None)
    if stored_key is None:
        return
    declared = scenario.controller.sigma
    safe_only = getattr(tightening, "tiers", None) == {"safe": True, "tracking": False}
    if sigma is not None:
        run_sigma = sigma
    else:
        run_sigma = tightening.sigma if safe_only or declared is None else declared
    found = design_fields(scenario, law if law is not None else scenario.controller.law, float(run_sigma))
    stored = dict(getattr(tightening, "design_fields", None) or {})
    _shorter_run_is_covered(found, stored)
    if design_key(found) == stored_key:
        return
    diff = first_difference(found, stored)
    if diff is None:
        raise ConfigError("design_key", f"the key of the scenario's design ({design_key(found)[:16]}...)",
                          stored_key, "the certificate's key does not match its own fields: it was edited")
    name, here, there = diff
    raise ConfigError(f"design_key.{name}", f"the certificate's value {there!r} (it was issued for another design)",
                      here, "the scenario and law the run uses differ from those the certificate was issued for; "
                            "certify this scenario (tubekit certify) and use that certificate")
