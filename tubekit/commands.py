"""``tubekit reproduce`` and ``tubekit simulate``: the closed-loop study (issue 5).

Both run the same study on a scenario: certify it with :func:`verify.certify`
(written even when it does not certify), run the tube controller with the
certificate's (best-effort) tightened sets and gain, run the baseline (nominal
MPC alone: no κ, no tightening) under the same disturbance, then write into
the output directory:

* ``trajectory.csv`` / ``baseline_trajectory.csv`` (columns: see
  :data:`tubekit.closed_loop.CSV_COLUMNS`),
* ``metrics.json`` (tube metrics at the top level, ``baseline`` nested,
  ``acceptance`` for ``reproduce``),
* ``certificate.json`` and ``certificate.txt``, ``scenario.json``,
* the figures of :data:`tubekit.plots.FIGURE_FILES`.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from .closed_loop import SimulationResult, simulate
from .exceptions import ConfigError, NotAvailableError
from .metrics import compute_metrics
from .plots import plot_all
from .scenario import Scenario, load_scenario, paper_scenario
from .tightening import Tightening

__all__ = [
    "configure_reproduce",
    "run_reproduce",
    "configure_simulate",
    "run_simulate",
    "run_study",
    "acceptance",
    "QUICK_DURATION_S",
    "OUTPUT_FILES",
]

#: Simulated seconds of ``--quick``.
QUICK_DURATION_S = 10.0
#: Files (besides figures) every study writes.
OUTPUT_FILES: tuple[str, ...] = ("trajectory.csv", "baseline_trajectory.csv", "metrics.json", "certificate.json",
                                 "certificate.txt", "scenario.json")


def _common_options(parser: argparse.ArgumentParser, default_out: str | None) -> None:
    parser.add_argument("--out", metavar="DIR", default=default_out,
                        help="output directory" + (f" (default: {default_out})" if default_out else
                                                   " (default: results/<scenario name>)"))
    length = parser.add_mutually_exclusive_group()
    length.add_argument("--duration", type=float, metavar="S", default=None,
                        help="simulated time in seconds (default: the scenario's)")
    length.add_argument("--quick", action="store_true",
                        help=f"shorthand for --duration {QUICK_DURATION_S:g} (smoke test)")
    parser.add_argument("--law", choices=("paper", "corrected"), default=None,
                        help="ancillary law (default: the scenario's controller.law)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def configure_reproduce(parser: argparse.ArgumentParser) -> None:
    """Options of ``tubekit reproduce``."""
    _common_options(parser, "results/reproduce")


def configure_simulate(parser: argparse.ArgumentParser) -> None:
    """Options of ``tubekit simulate CONFIG``."""
    parser.add_argument("config", metavar="CONFIG", help="scenario TOML file (schema: docs/scenario.md)")
    _common_options(parser, None)


def _apply_overrides(scenario: Scenario, args: argparse.Namespace) -> Scenario:
    duration = QUICK_DURATION_S if getattr(args, "quick", False) else getattr(args, "duration", None)
    if duration is not None:
        if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration > 0):
            raise ConfigError("--duration", "a number of seconds > 0", duration)
        scenario = scenario.with_changes(duration=float(duration))
        if scenario.steps < 1:
            raise ConfigError("--duration", f"at least one FHOCP period ({scenario.controller.dt:g} s)", duration)
    if getattr(args, "law", None):
        scenario = scenario.with_changes(controller=replace(scenario.controller, law=args.law))
    return scenario


def _certify(scenario: Scenario):
    try:
        import verify
        certify = verify.certify
    except (ImportError, AttributeError):
        raise NotAvailableError("verify.certify is not available in this installation") from None
    return certify(scenario, law=scenario.controller.law)


def _json_default(o: Any):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.floating,)):
        return float(o) if math.isfinite(o) else None
    if isinstance(o, (np.bool_,)):
        return bool(o)
    if isinstance(o, (set, tuple)):
        return list(o)
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def _clean(o: Any) -> Any:
    """Replace non-finite floats by None (strict JSON)."""
    if isinstance(o, float) and not math.isfinite(o):
        return None
    if isinstance(o, dict):
        return {k: _clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v) for v in o]
    return o


def _write_json(path: Path, data: Any) -> None:
    text = json.dumps(_clean(json.loads(json.dumps(data, default=_json_default))), indent=2, allow_nan=False)
    path.write_text(text + "\n")


def acceptance(metrics: dict[str, Any], total_wall_s: float) -> dict[str, Any]:
    """Issue 5 item 7 on the tube run: each criterion with the number it rests on."""
    enc, enc_d = metrics.get("encirclements"), metrics.get("desired_encirclements")
    passes = metrics.get("obstacle_passes")
    return {
        "no_collision": not metrics["collision"],
        "inputs_within_V": bool(metrics["inputs_within_limits"]),
        "two_encirclements": bool(passes) and all(p >= 2 for p in passes),
        "e_d_at_least_epsilon": not metrics["e_d_below_epsilon"],
        "under_60_s": total_wall_s < 60.0,
        "notes": {
            "encirclements": enc, "desired_encirclements": enc_d, "obstacle_passes": passes,
            "min_clearance": metrics["min_clearance"],
            "min_e_d": metrics["min_e_d"], "epsilon": metrics["epsilon"],
            "e_d_below_epsilon": metrics["e_d_below_epsilon"], "total_wall_s": total_wall_s,
            "saturated_steps": metrics["saturated_steps"],
            "rule": ("two_encirclements: every obstacle passed at least twice (the paper: 'two encirclements, "
                     "which means that it should avoid the obstacles twice each'); collision: clearance < 0; "
                     "inputs_within_V: applied inputs (after any counted saturation) inside V"),
        },
    }


def _fmt(v: Any) -> str:
    if v is None:
        return "null"
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _table(tube: dict, base: dict) -> str:
    keys = ("min_clearance", "min_e_d", "max_input_ratio", "saturated_steps", "fallback_steps", "encirclements",
            "tracking_rmse", "max_rho", "step_ms_median", "step_ms_p95", "wall_s")
    lines = [f"{'metric':<18}{'tube':>12}{'baseline':>12}"]
    lines += [f"{k:<18}{_fmt(tube.get(k)):>12}{_fmt(base.get(k)):>12}" for k in keys]
    return "\n".join(lines)


def run_study(scenario: Scenario, out: Path, *, progress: bool = True, with_acceptance: bool = False,
              log=print) -> dict[str, Any]:
    """Certify, run tube + baseline, write every output; returns the metrics dict."""
    t0 = time.perf_counter()
    if scenario.steps < 1:
        raise ConfigError("duration", f"at least one FHOCP period ({scenario.controller.dt:g} s)", scenario.duration)
    out.mkdir(parents=True, exist_ok=True)
    _write_json(out / "scenario.json", scenario.to_dict())

    log(f"certifying {scenario.name!r} (law {scenario.controller.law}) ...")
    tc = time.perf_counter()
    cert = _certify(scenario)
    cert_s = time.perf_counter() - tc
    certified = bool(cert.certified)
    _write_json(out / "certificate.json", cert.to_dict())
    (out / "certificate.txt").write_text(str(cert.summary()) + "\n")
    tightening: Tightening = cert.tightening(allow_uncertified=True)
    log(f"  {'certified' if certified else 'NOT certified (best-effort tightening used)'} in {cert_s:.1f} s; "
        f"sigma = {tightening.sigma:.4g}, rho_tilde = {tightening.rho_tilde:.4g}")

    log(f"tube run ({scenario.duration:g} s simulated) ...")
    tube = simulate(scenario, tightening=tightening, tube=True, progress=progress, label="tube")
    log(f"  {tube.summary()}")
    log("baseline run (nominal MPC alone) ...")
    base = simulate(scenario, tightening=Tightening.untightened(scenario), tube=False, progress=progress,
                    label="baseline")
    log(f"  {base.summary()}")

    tube.write_csv(out / "trajectory.csv")
    base.write_csv(out / "baseline_trajectory.csv")
    tube_cols, base_cols = tube.columns(), base.columns()
    rho_bound = float(tightening.rho_tilde) if certified else None
    metrics = compute_metrics(tube_cols, scenario, rho_bound=rho_bound, extra=_extra(tube))
    metrics["baseline"] = compute_metrics(base_cols, scenario, rho_bound=None, extra=_extra(base))
    plot_all(out, scenario, [("tube", tube_cols), ("baseline", base_cols)],
             rho_tilde=float(tightening.rho_tilde), certified=certified)
    metrics["certified"] = certified
    metrics["rho_tilde_used"] = float(tightening.rho_tilde)
    metrics["certify_s"] = cert_s
    metrics["closed_loop"] = {
        "plant": f"eq. (11), classical RK4, fixed step {tube.plant_step_s * 1e3:g} ms, input held over each tick",
        "ancillary": f"kappa at {scenario.controller.ancillary_rate_hz:g} Hz, zero-order hold",
        "fhocp": f"every {scenario.controller.dt:g} s, nominal reset to the measured state, first input held",
        "sensing": "obstacle known once its surface is within sensing_range of the vehicle centre; remembered",
        "saturation": "v = v_hat + kappa clipped to V only when outside V; counted per tick and per period",
    }
    total = time.perf_counter() - t0
    metrics["total_wall_s"] = total
    if with_acceptance:
        metrics["acceptance"] = acceptance(metrics, total)
    _write_json(out / "metrics.json", metrics)
    log(_table(metrics, metrics["baseline"]))
    if with_acceptance:
        acc = metrics["acceptance"]
        log("acceptance: " + ", ".join(f"{k}={v}" for k, v in acc.items() if k != "notes"))
        for iv in metrics["e_d_below_epsilon"]:
            log(f"  e_d < epsilon from t={iv['t_start']:.2f} s to {iv['t_end']:.2f} s, "
                f"min {iv['min']:.4f} m at t={iv['t_min']:.2f} s (by {iv['depth']:.4f} m)")
        for iv in metrics["collisions"]:
            log(f"  collision from t={iv['t_start']:.2f} s to {iv['t_end']:.2f} s, "
                f"penetration {iv['depth']:.4f} m at t={iv['t_min']:.2f} s")
    log(f"wrote {out} in {total:.1f} s")
    return metrics


def _extra(run: SimulationResult) -> dict[str, Any]:
    return {"tube": run.tube, "law": run.law if run.tube else None, "sigma": run.sigma,
            "kappa_failures": run.kappa_failures, "checks": run.checks}


def _log(msg: str) -> None:
    print(msg, flush=True)


def run_reproduce(args: argparse.Namespace) -> int:
    """``tubekit reproduce``: Section VI of the paper, tube against baseline."""
    scenario = _apply_overrides(paper_scenario(), args)
    out = Path(args.out or "results/reproduce")
    run_study(scenario, out, progress=not args.no_progress, with_acceptance=True, log=_log)
    return 0


def run_simulate(args: argparse.Namespace) -> int:
    """``tubekit simulate CONFIG``: the same study on a scenario from TOML."""
    scenario = _apply_overrides(load_scenario(args.config), args)
    out = Path(args.out) if args.out else Path("results") / _safe_name(scenario.name)
    run_study(scenario, out, progress=not args.no_progress, with_acceptance=False, log=_log)
    return 0


def _safe_name(name: str) -> str:
    keep = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in name)
    return keep or "scenario"

