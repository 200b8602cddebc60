"""The closed-loop study behind ``tubekit reproduce`` and ``tubekit simulate`` (issue 5).

Both run the same study on a scenario: certify it with :func:`verify.certify`
(written even when it does not certify), run the tube controller with the
certificate's (best-effort) tightened sets and gain, run the baseline (nominal
MPC alone: no κ, no tightening) under the same disturbance, then write into
the output directory:

* ``trajectory.csv`` / ``baseline_trajectory.csv`` (columns: see
  :data:`tubekit.loop.closed_loop.CSV_COLUMNS`),
* ``metrics.json`` (tube metrics at the top level, ``baseline`` nested,
  ``acceptance`` for ``reproduce``),
* ``certificate.json`` and ``certificate.txt``, ``scenario.json``,
* the figures of :data:`tubekit.app.plots.FIGURE_FILES` (and, with
  ``animate=True``, the animation of :func:`tubekit.app.animate.animate_top_view`).

:func:`run_study` is the pipeline; each step is a function of its own. Every
input is checked first (:func:`tubekit.checks.check_run_inputs` and the output
path), then everything is written into a temporary directory next to ``out``
that replaces ``out`` in one rename at the end (:class:`StagedOutput`): a failed
or interrupted run leaves the previous results untouched. Diagnostics go to the
``logging`` logger of this module; the results (comparison table, promises,
acceptance, ``wrote ...``) are printed on stdout.
"""

from __future__ import annotations

import logging
import math
import os
import shutil
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

import verify

from tubekit.checks import check_run_inputs
from tubekit.loop.closed_loop import simulate
from tubekit.loop.result import SimulationResult
from tubekit.exceptions import ConfigError
from tubekit.jsonable import write_json, write_text
from tubekit.loop.metrics import compute_metrics
from tubekit.loop.promises import check_promises
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.app import QUICK_S
from tubekit.app.plots import plot_all

__all__ = [
    "run_study",
    "apply_overrides",
    "acceptance",
    "output_dir_name",
    "QUICK_DURATION_S",
    "OUTPUT_FILES",
    "StagedOutput",
    "check_output_dir",
]

LOGGER = logging.getLogger(__name__)

#: Simulated seconds of ``--quick``.
QUICK_DURATION_S = QUICK_S  # re-exported; the parser reads it from tubekit.app without importing the study
#: Files (besides figures) every study writes.
OUTPUT_FILES: tuple[str, ...] = ("trajectory.csv", "baseline_trajectory.csv", "metrics.json", "certificate.json",
                                 "certificate.txt", "scenario.json")

Echo = Callable[[str], None]


def apply_overrides(scenario: Scenario, *, duration: float | None = None, quick: bool = False,
                    law: str | None = None) -> Scenario:
    """The scenario with the command-line overrides applied.

    Parameters
    ----------
    duration : float, optional
        Simulated time (s); ``quick`` sets it to :data:`QUICK_DURATION_S`.
    law : str, optional
        Ancillary law replacing ``controller.law``.

    Raises
    ------
    ConfigError
        ``--duration`` not a positive number of seconds, or shorter than one FHOCP period.
    """
    duration = QUICK_DURATION_S if quick else duration
    if duration is not None:
        if not (isinstance(duration, (int, float)) and math.isfinite(duration) and duration > 0):
            raise ConfigError("--duration", "a number of seconds > 0", duration)
        scenario = scenario.with_changes(duration=float(duration))
        if scenario.steps < 1:
            raise ConfigError("--duration", f"at least one FHOCP period ({scenario.controller.dt:g} s)", duration)
    if law:
        scenario = scenario.with_changes(controller=replace(scenario.controller, law=law))
    return scenario


def output_dir_name(scenario_name: str) -> str:
    """A file-system-safe directory name for a scenario (``results/<name>`` of ``tubekit simulate``)."""
    keep = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in scenario_name)
    return keep or "scenario"


def e_d_peaks(e_d: np.ndarray, t: np.ndarray, prominence: float = 0.2) -> list[float]:
    """Times (s) of the e_d peaks that rise at least ``prominence`` (m) above both neighbouring valleys."""
    from scipy.signal import find_peaks
    idx, _ = find_peaks(np.asarray(e_d, dtype=float), prominence=prominence)
    return [float(t[i]) for i in idx]


def acceptance(metrics: dict[str, Any], total_wall_s: float) -> dict[str, Any]:
    """Issue 5 item 7 and issue 12's fidelity bar on the tube run: each criterion with the number it rests on."""
    enc, enc_d = metrics.get("encirclements"), metrics.get("desired_encirclements")
    passes = metrics.get("obstacle_passes")
    base_rmse = metrics["baseline"]["tracking_rmse"] if "baseline" in metrics else None
    ratio = metrics["tracking_rmse"] / base_rmse if base_rmse else None
    return {
        "four_e_d_peaks": len(metrics.get("e_d_peaks", [])) >= 4,
        "rmse_within_1_25_baseline": ratio is not None and ratio <= 1.25,
        "no_collision": not metrics["collision"],
        "inputs_within_V": bool(metrics["inputs_within_limits"]),
        "two_encirclements": bool(passes) and all(p >= 2 for p in passes),
        "e_d_at_least_epsilon": not metrics["e_d_below_epsilon"],
        "notes": {
            "encirclements": enc, "desired_encirclements": enc_d, "obstacle_passes": passes,
            "min_clearance": metrics["min_clearance"],
            "min_e_d": metrics["min_e_d"], "epsilon": metrics["epsilon"],
            "e_d_below_epsilon": metrics["e_d_below_epsilon"], "total_wall_s": total_wall_s,
            "saturated_steps": metrics["saturated_steps"],
            "e_d_peaks_s": metrics.get("e_d_peaks"), "tracking_rmse_ratio": ratio,
            "rule": ("two_encirclements: every obstacle passed at least twice (the paper: 'two encirclements, "
                     "which means that it should avoid the obstacles twice each'); collision: clearance < 0; "
                     "inputs_within_V: applied inputs (after any counted saturation) inside V; four_e_d_peaks: "
                     "e_d peaks rising >= 0.2 m above both neighbouring valleys (the paper's Fig. 3: four peaks, "
                     "e_d back down between obstacle passes); rmse_within_1_25_baseline: tube RMSE <= 1.25 x the "
                     "nominal-only baseline's"),
        },
    }


@dataclass(frozen=True)
class CertifiedDesign:
    """What the runs need from the certificate: the tightening, whether it is certified, and the time (s)."""

    tightening: Tightening
    certified: bool
    certify_s: float


def certify_and_write(scenario: Scenario, out: Path) -> CertifiedDesign:
    """Certify with :func:`verify.certify`; write ``certificate.json`` and ``certificate.txt``."""
    LOGGER.info("certifying %r (law %s) ...", scenario.name, scenario.controller.law)
    started = time.perf_counter()
    cert = verify.certify(scenario, law=scenario.controller.law)
    certify_s = time.perf_counter() - started
    certified = bool(cert.certified)
    write_json(out / "certificate.json", cert.to_dict())
    write_text(out / "certificate.txt", str(cert.summary()) + "\n")
    tightening: Tightening = cert.best_effort_tightening()
    LOGGER.info("  %s in %.1f s; sigma = %.4g, rho_tilde = %.4g",
                "certified" if certified else "NOT certified (best-effort tightening used)", certify_s,
                tightening.sigma, tightening.rho_tilde)
    return CertifiedDesign(tightening, certified, certify_s)


def run_tube_and_baseline(scenario: Scenario, tightening: Tightening,
                          progress: bool) -> tuple[SimulationResult, SimulationResult]:
    """The tube controller with ``tightening``, then the baseline (untightened, no κ) under the same disturbance."""
    LOGGER.info("tube run (%g s simulated) ...", scenario.duration)
    tube = simulate(scenario, tightening=tightening, tube=True, progress=progress, label="tube")
    LOGGER.info("  %s", tube.summary())
    LOGGER.info("baseline run (nominal MPC alone) ...")
    base = simulate(scenario, tightening=Tightening.untightened(scenario), tube=False, progress=progress,
                    label="baseline")
    LOGGER.info("  %s", base.summary())
    return tube, base


def _run_facts(run: SimulationResult) -> dict[str, Any]:
    return {"tube": run.tube, "law": run.law if run.tube else None, "sigma": run.sigma,
            "kappa_failures": run.kappa_failures, "checks": run.checks}


def closed_loop_notes(scenario: Scenario, tube: SimulationResult) -> dict[str, str]:
    """How the closed loop was simulated, in words (``metrics.json["closed_loop"]``)."""
    return {
        "plant": f"eq. (11), classical RK4, fixed step {tube.plant_step_s * 1e3:g} ms, input held over each tick",
        "ancillary": f"kappa at {scenario.controller.ancillary_rate_hz:g} Hz, zero-order hold",
        "fhocp": f"every {scenario.controller.dt:g} s, nominal reset to the measured state, first input held",
        "sensing": "obstacle known once its surface is within sensing_range of the vehicle centre; remembered",
        "saturation": "v = v_hat + kappa clipped to V only when outside V; counted per tick and per period",
    }


def write_runs(out: Path, scenario: Scenario, design: CertifiedDesign, tube: SimulationResult,
               base: SimulationResult) -> dict[str, Any]:
    """Write both CSVs and the figures; return the metrics of both runs (baseline nested)."""
    tube.write_csv(out / "trajectory.csv")
    base.write_csv(out / "baseline_trajectory.csv")
    tube_cols, base_cols = tube.columns(), base.columns()
    rho_tilde = float(design.tightening.rho_tilde)
    metrics = compute_metrics(tube_cols, scenario, rho_bound=rho_tilde if design.certified else None,
                              extra=_run_facts(tube))
    metrics["baseline"] = compute_metrics(base_cols, scenario, rho_bound=None, extra=_run_facts(base))
    metrics["e_d_peaks"] = e_d_peaks(tube_cols["e_d"], tube_cols["t"])
    plot_all(out, scenario, [("tube", tube_cols), ("baseline", base_cols)], rho_tilde=rho_tilde,
             certified=design.certified, tightening=design.tightening)
    metrics["certified"] = design.certified
    metrics["rho_tilde_used"] = rho_tilde
    promises = check_promises(tube)
    metrics["promises"] = [p.to_dict() for p in promises]
    metrics["promises_kept"] = all(p.ok for p in promises)
    metrics["max_rho_ratio"] = promises[0].observed if promises[0].name == "tube" else None
    metrics["tube_box"] = [float(x) for x in design.tightening.tube]
    metrics["certify_s"] = design.certify_s
    metrics["closed_loop"] = closed_loop_notes(scenario, tube)
    return metrics


def _fmt(v: Any) -> str:
    if v is None:
        return "null"
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def comparison_table(tube: dict[str, Any], base: dict[str, Any]) -> str:
    """Tube against baseline, one metric per line."""
    keys = ("min_clearance", "min_e_d", "max_input_ratio", "saturated_steps", "fallback_steps", "encirclements",
            "tracking_rmse", "max_rho", "step_ms_median", "step_ms_p95", "wall_s")
    lines = [f"{'metric':<18}{'tube':>12}{'baseline':>12}"]
    lines += [f"{k:<18}{_fmt(tube.get(k)):>12}{_fmt(base.get(k)):>12}" for k in keys]
    return "\n".join(lines)


def log_promises(metrics: dict[str, Any], log: Echo = print) -> None:
    """Each promise of the certificate with its numbers; says plainly when a certified one is broken."""
    certified = metrics["certified"]
    head = ("promises of the certificate (certified):" if certified
            else "figures a certificate would promise (NOT certified: nothing is claimed):")
    log(head)
    for p in metrics["promises"]:
        mark = "ok  " if p["ok"] else ("BROKEN" if certified else "no  ")
        log(f"  [{mark}] {p['name']}: {_fmt(p['observed'])} vs {_fmt(p['bound'])}  ({p['detail']})")
    if certified and not metrics["promises_kept"]:
        log("CERTIFIED PROMISE BROKEN: the run violates what the certificate guarantees (exit 4)")


def log_acceptance(metrics: dict[str, Any], log: Echo = print) -> None:
    """The acceptance verdicts, then every e_d < ε interval and every collision."""
    log("acceptance: " + ", ".join(f"{k}={v}" for k, v in metrics["acceptance"].items() if k != "notes"))
    for iv in metrics["e_d_below_epsilon"]:
        log(f"  e_d < epsilon from t={iv['t_start']:.2f} s to {iv['t_end']:.2f} s, "
            f"min {iv['min']:.4f} m at t={iv['t_min']:.2f} s (by {iv['depth']:.4f} m)")
    for iv in metrics["collisions"]:
        log(f"  collision from t={iv['t_start']:.2f} s to {iv['t_end']:.2f} s, "
            f"penetration {iv['depth']:.4f} m at t={iv['t_min']:.2f} s")


class StagedOutput:
    """An output directory written atomically: a temporary directory next to it, then one rename.

    Use as a context manager; :attr:`path` is the staging directory to write into.
    On a clean exit it replaces ``target`` (the previous contents are removed only
    after the new ones are in place); on any exception, ``KeyboardInterrupt``
    included, the staging directory is removed and ``target`` is untouched.
    """

    def __init__(self, target: Path) -> None:
        self.target = Path(target)
        self.path = self.target

    def __enter__(self) -> "StagedOutput":
        parent = self.target.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self.path = Path(tempfile.mkdtemp(prefix=f".{self.target.name}.tmp-", dir=parent))
            umask = os.umask(0)
            os.umask(umask)
            self.path.chmod(0o777 & ~umask)
        except OSError as exc:
            raise ConfigError("--out", "a directory that can be created and written", str(self.target),
                              exc.strerror or str(exc)) from None
        return self

    def __exit__(self, kind: type | None, error: BaseException | None, trace: Any) -> None:
        if kind is not None:
            shutil.rmtree(self.path, ignore_errors=True)
            return
        self._commit()

    def _commit(self) -> None:
        """Swap the staging directory in; the old ``target`` goes only after the new one is in place."""
        old = None
        try:
            if self.target.exists():
                old = self.target.with_name(f".{self.target.name}.old-{os.getpid()}-{time.time_ns()}")
                os.replace(self.target, old)
            os.replace(self.path, self.target)
        except OSError as exc:
            if old is not None and not self.target.exists():
                os.replace(old, self.target)
            shutil.rmtree(self.path, ignore_errors=True)
            raise ConfigError("--out", "a directory that can be replaced", str(self.target),
                              exc.strerror or str(exc)) from None
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def check_output_dir(out: Path) -> None:
    """Raise ``ConfigError('--out', ...)`` unless ``out`` can become a results directory; creates nothing.

    ``out`` must be a directory or not exist; its nearest existing ancestor must be a
    writable directory (the staging directory is created next to ``out``).
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ConfigError("--out", "a directory (or a path that does not exist yet)", str(out),
                          "It names an existing file.")
    ancestor = out.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise ConfigError("--out", "a path under a directory", str(out), f"{ancestor} is a file.")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise ConfigError("--out", "a path in a writable directory", str(out), f"{ancestor} is not writable.")
    if out.exists() and not os.access(out, os.W_OK | os.X_OK):
        raise ConfigError("--out", "a writable directory", str(out), "permission denied")


def _write_study(scenario: Scenario, out: Path, staging: Path, progress: bool, with_acceptance: bool,
                 animate: bool, started: float, dynamic: bool = False) -> dict[str, Any]:
    """Certify, run, and write every file of the study into ``staging``; returns the metrics."""
    write_json(staging / "scenario.json", scenario.to_dict())
    design = certify_and_write(scenario, staging)
    tube, base = run_tube_and_baseline(scenario, design.tightening, progress)
    metrics = write_runs(staging, scenario, design, tube, base)
    if dynamic:
        from tubekit.app.dynamic_study import run_dynamic

        LOGGER.info("tube run on the dynamic plant (%s) ...", scenario.plant.vehicle)
        metrics["dynamic"] = run_dynamic(scenario, staging, tube, progress)
    if animate:
        from tubekit.app.animate import animate_top_view

        for path in animate_top_view(staging, scenario, [("tube", tube.columns()), ("baseline", base.columns())]):
            LOGGER.info("animation written: %s", out / path.name)
    total = time.perf_counter() - started
    metrics["total_wall_s"] = total
    if with_acceptance:
        metrics["acceptance"] = acceptance(metrics, total)
    write_json(staging / "metrics.json", metrics)
    return metrics


def run_study(scenario: Scenario, out: Path, *, progress: bool = True, with_acceptance: bool = False,
              animate: bool = False, dynamic: bool = False, echo: Echo = print) -> dict[str, Any]:
    """Check every input, certify, run tube + baseline, write every output into ``out``; returns the metrics.

    Parameters
    ----------
    out : Path
        Results directory; replaced atomically at the end (see :class:`StagedOutput`).
    animate : bool
        Also write the top-view animation (GIF; MP4 where ffmpeg exists).
    dynamic : bool
        Also run the tube controller on the 4-DOF dynamic plant (:mod:`tubekit.app.dynamic_study`).
    echo : callable
        Receives the result lines (comparison table, promises, acceptance, ``wrote ...``).

    Raises
    ------
    ConfigError
        Any input that cannot run (see :func:`tubekit.checks.check_run_inputs`) or an unusable
        ``out`` (field ``--out``); nothing is written.
    """
    started = time.perf_counter()
    if scenario.steps < 1:
        raise ConfigError("duration", f"at least one FHOCP period ({scenario.controller.dt:g} s)", scenario.duration)
    check_run_inputs(scenario)
    out = Path(out)
    check_output_dir(out)
    with StagedOutput(out) as staged:
        metrics = _write_study(scenario, out, staged.path, progress, with_acceptance, animate, started, dynamic)
    echo(comparison_table(metrics, metrics["baseline"]))
    log_promises(metrics, echo)
    if "dynamic" in metrics:
        dyn = metrics["dynamic"]
        echo(f"dynamic plant ({dyn['vehicle']}): {'certified' if dyn['certified'] else 'NOT certified'}"
             + (f" (failed: {', '.join(dyn['failures'])})" if dyn["failures"] else "")
             + f"; min clearance {_fmt(dyn['min_clearance'])} m, min e_d {_fmt(dyn['min_e_d'])} m, "
               f"sway max {_fmt(dyn.get('sway_max'))} vs {_fmt(dyn.get('sway_bound'))} m/s, velocity-loop error max "
               f"{dyn.get('velocity_error_max')}")
        log_promises(dyn, echo)
    if with_acceptance:
        log_acceptance(metrics, echo)
    echo(f"wrote {out} in {time.perf_counter() - started:.1f} s")
    return metrics
