"""The closed-loop study behind ``tubekit reproduce`` and ``tubekit simulate`` (issue 5).

Both run the same study on a scenario: certify it with :func:`verify.certify`
(written even when it does not certify), run the tube controller with the
certificate's (best-effort) tightened sets and gain, run the baseline (nominal
MPC alone: no κ, no tightening) under the same disturbance, then write into
the output directory:

* ``trajectory.csv`` / ``baseline_trajectory.csv`` (columns: see
  :data:`tubekit.loop.result.CSV_COLUMNS`),
* ``metrics.json`` (tube metrics at the top level, ``baseline`` nested,
  ``acceptance`` for ``reproduce``, ``tiers_report``: which tier the certificate gives and which
  promise depends on what, :func:`tubekit.app.tiers.tier_report`),
* ``certificate.json`` and ``certificate.txt``, ``scenario.json``,
* the figures of :data:`tubekit.app.plots.FIGURE_FILES` (and, with
  ``animate=True``, the animation of :func:`tubekit.app.animate.animate_top_view`).

:func:`run_study` is the pipeline: certify (:func:`tubekit.app.certified.certify_design`), then
each run is :func:`tubekit.loop.pipeline.certified_run` (simulate → metrics → promises), so the
top level of ``metrics.json`` is the tube run's ``SimulationResult.metrics`` key for key, plus the
study's own keys (:data:`STUDY_KEYS`). It returns a typed :class:`StudyResult`. Every input is
checked first (:func:`tubekit.checks.check_run_inputs` and the output path), then everything is
written into a temporary directory next to ``out`` that replaces ``out`` in one rename at the end
(:class:`tubekit.app.output.StagedOutput`): a failed or interrupted run leaves the previous results
untouched. Diagnostics go to the ``logging`` logger of this module; the results (comparison table,
replaced steps and backup time, tiers, promises, acceptance, ``wrote ...``) are printed on stdout. The
figures carry the tiers as a title line and shade the stretches in which the backup law ran.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from tubekit.checks import check_run_inputs, require_one_period
from tubekit.jsonable import write_json, write_text
from tubekit.loop.pipeline import CertifiedRun, certified_run
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.validation import duration_seconds
from tubekit.app import QUICK_S
from tubekit.app.certified import CertifiedDesign, certify_design
from tubekit.app.output import StagedOutput, check_output_dir
from tubekit.app.plots import plot_all
from tubekit.app.sigma_story import sigma_story
from tubekit.app.tiers import activity_line, report_title, tier_lines, tier_report

__all__ = [
    "run_study",
    "StudyResult",
    "apply_overrides",
    "acceptance",
    "output_dir_name",
    "QUICK_DURATION_S",
    "OUTPUT_FILES",
    "STUDY_KEYS",
]

LOGGER = logging.getLogger(__name__)

#: Simulated seconds of ``--quick``.
QUICK_DURATION_S = QUICK_S  # re-exported; the parser reads it from tubekit.app without importing the study
#: Files (besides figures) every study writes.
OUTPUT_FILES: tuple[str, ...] = ("trajectory.csv", "baseline_trajectory.csv", "metrics.json", "certificate.json",
                                 "certificate.txt", "scenario.json")
#: Keys of ``metrics.json`` that are the study's, not the tube run's (every other key is ``run.metrics``'s).
STUDY_KEYS: tuple[str, ...] = ("baseline", "e_d_peaks", "certify_s", "closed_loop", "dynamic", "total_wall_s",
                               "acceptance", "tiers_report")

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
        duration = duration_seconds("--duration", duration)
        require_one_period("--duration", duration, scenario.controller.dt)
        scenario = scenario.with_changes(duration=duration)
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


def certify_and_write(scenario: Scenario, out: Path) -> CertifiedDesign:
    """Certify (:func:`tubekit.app.certified.certify_design`); write ``certificate.json`` and ``certificate.txt``."""
    design = certify_design(scenario)
    for line in sigma_story(scenario, design.certificate):
        LOGGER.info("%s", line)
    write_json(out / "certificate.json", design.certificate.to_dict())
    write_text(out / "certificate.txt", str(design.certificate.summary(verbose=True)) + "\n")
    return design


def run_tube_and_baseline(scenario: Scenario, tightening: Tightening,
                          progress: bool) -> tuple[CertifiedRun, CertifiedRun]:
    """The tube controller with ``tightening``, then the baseline (untightened, no κ) under the same disturbance."""
    LOGGER.info("tube run (%g s simulated) ...", scenario.duration)
    tube = certified_run(scenario, tightening, tube=True, progress=progress, label="tube")
    LOGGER.info("  %s", tube.run.summary())
    LOGGER.info("baseline run (nominal MPC alone) ...")
    base = certified_run(scenario, Tightening.untightened(scenario), tube=False, progress=progress,
                         label="baseline")
    LOGGER.info("  %s", base.run.summary())
    return tube, base


def closed_loop_notes(scenario: Scenario, tube: CertifiedRun) -> dict[str, str]:
    """How the closed loop was simulated, in words (``metrics.json["closed_loop"]``)."""
    return {
        "plant": f"eq. (11), classical RK4, fixed step {tube.run.plant_step_s * 1e3:g} ms, input held over each tick",
        "ancillary": f"kappa at {scenario.controller.ancillary_rate_hz:g} Hz, zero-order hold",
        "fhocp": f"every {scenario.controller.dt:g} s, nominal reset to the measured state, first input held",
        "sensing": "obstacle known once its surface is within sensing_range of the vehicle centre; remembered",
        "saturation": "v = v_hat + kappa clipped to V only when outside V; counted per tick and per period",
    }


def write_runs(out: Path, scenario: Scenario, design: CertifiedDesign, tube: CertifiedRun,
               base: CertifiedRun) -> dict[str, Any]:
    """Write both CSVs and the figures; return ``metrics.json`` so far: the tube run's metrics, baseline nested."""
    tube.run.write_csv(out / "trajectory.csv")
    base.run.write_csv(out / "baseline_trajectory.csv")
    tube_cols, base_cols = tube.run.columns(), base.run.columns()
    tight = design.tightening
    metrics = tube.to_dict()
    metrics["tiers_report"] = tier_report(design.certificate, metrics)
    plot_all(out, scenario, [("tube", tube_cols), ("baseline", base_cols)], tightening=tight,
             tiers=report_title(metrics["tiers_report"]))
    metrics["baseline"] = base.to_dict()
    metrics["e_d_peaks"] = e_d_peaks(tube_cols["e_d"], tube_cols["t"])
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


def _mark(p: dict[str, Any], broken: set[str]) -> str:
    """``ok``, ``BROKEN`` (a given tier, its premises held: exit 4) or why a failed figure claims nothing."""
    if p["ok"]:
        return "ok"
    if p["name"] in broken:
        return "BROKEN"
    if p.get("tier") == "premise":
        return "premise failed"
    return "no: tier not given" if not p.get("given", True) else "no: a premise failed"


def promise_lines(metrics: dict[str, Any]) -> list[str]:
    """Each promise with its tier, numbers and premises; says plainly when a promise of a given tier broke."""
    certified = metrics["certified"]
    broken = set(metrics.get("promises_broken") or ())
    lines = ["promises of the certificate, by tier:" if certified
             else "figures a certificate would promise (NOT certified: nothing is claimed):"]
    for p in metrics["promises"]:
        tier = p.get("tier", "")
        needs = f"; depends on {', '.join(p['depends_on'])}" if p.get("depends_on") else ""
        lines.append(f"  [{_mark(p, broken) if certified else ('ok' if p['ok'] else 'no')}] {tier} {p['name']}: "
                     f"{_fmt(p['observed'])} vs {_fmt(p['bound'])}  ({p['detail']}{needs})")
    if certified and broken:
        lines.append(f"CERTIFIED PROMISE BROKEN ({', '.join(sorted(broken))}): the run violates what the "
                     "certificate guarantees (exit 4)")
    return lines


def acceptance_lines(metrics: dict[str, Any]) -> list[str]:
    """The acceptance verdicts, then every e_d < ε interval and every collision."""
    lines = ["acceptance: " + ", ".join(f"{k}={v}" for k, v in metrics["acceptance"].items() if k != "notes")]
    for iv in metrics["e_d_below_epsilon"]:
        lines.append(f"  e_d < epsilon from t={iv['t_start']:.2f} s to {iv['t_end']:.2f} s, "
                     f"min {iv['min']:.4f} m at t={iv['t_min']:.2f} s (by {iv['depth']:.4f} m)")
    for iv in metrics["collisions"]:
        lines.append(f"  collision from t={iv['t_start']:.2f} s to {iv['t_end']:.2f} s, "
                     f"penetration {iv['depth']:.4f} m at t={iv['t_min']:.2f} s")
    return lines


def _dynamic_lines(dyn: dict[str, Any]) -> list[str]:
    head = (f"dynamic plant ({dyn['vehicle']}): {'certified' if dyn['certified'] else 'NOT certified'}"
            + (f" (failed: {', '.join(dyn['failures'])})" if dyn["failures"] else "")
            + f"; min clearance {_fmt(dyn['min_clearance'])} m, min e_d {_fmt(dyn['min_e_d'])} m, "
              f"sway max {_fmt(dyn.get('sway_max'))} vs {_fmt(dyn.get('sway_bound'))} m/s, velocity-loop error max "
              f"{dyn.get('velocity_error_max')}")
    extra = ["  " + line for line in tier_lines(dyn["tiers_report"])] if "tiers_report" in dyn else []
    return [head, "  " + activity_line(dyn), *extra, *promise_lines(dyn)]


@dataclass(frozen=True)
class StudyResult:
    """What :func:`run_study` did: the runs (typed), ``metrics.json`` and where it was written.

    Attributes
    ----------
    out : Path
        The results directory.
    tube, baseline : CertifiedRun
        The tube controller's run and the baseline's.
    metrics : dict
        What ``metrics.json`` holds (the tube run's metrics plus :data:`STUDY_KEYS`).
    dynamic : CertifiedRun, optional
        The tube run on the dynamic plant (``reproduce``).
    """

    out: Path
    tube: CertifiedRun
    baseline: CertifiedRun
    metrics: dict[str, Any]
    dynamic: CertifiedRun | None = None

    @property
    def certified(self) -> bool:
        """The scenario's certificate certified it."""
        return self.tube.certified

    def check(self) -> bool:
        """False when a certified run (tube, or dynamic) broke a promise of its certificate (exit 4)."""
        return self.tube.check() and (self.dynamic is None or self.dynamic.check())

    def summary(self) -> str:
        """The comparison table, the promises, the dynamic-plant line and the acceptance, one item a line."""
        lines = [comparison_table(self.metrics, self.metrics["baseline"]), activity_line(self.metrics)]
        if "tiers_report" in self.metrics:
            lines += tier_lines(self.metrics["tiers_report"])
        lines += promise_lines(self.metrics)
        if "dynamic" in self.metrics:
            lines += _dynamic_lines(self.metrics["dynamic"])
        if "acceptance" in self.metrics:
            lines += acceptance_lines(self.metrics)
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """``metrics.json``."""
        return dict(self.metrics)


def _write_study(scenario: Scenario, out: Path, staging: Path, progress: bool, with_acceptance: bool,
                 animate: bool, started: float, dynamic: bool = False) -> StudyResult:
    """Certify, run, and write every file of the study into ``staging``."""
    write_json(staging / "scenario.json", scenario.to_dict())
    design = certify_and_write(scenario, staging)
    tube, base = run_tube_and_baseline(scenario, design.tightening, progress)
    metrics = write_runs(staging, scenario, design, tube, base)
    dyn_run = None
    if dynamic:
        from tubekit.app.dynamic_study import run_dynamic

        LOGGER.info("tube run on the dynamic plant ...")
        dyn_run, metrics["dynamic"] = run_dynamic(scenario, staging, tube.run, progress)
        LOGGER.info("  vehicle %s", metrics["dynamic"]["vehicle"])
    if animate:
        from tubekit.app.animate import animate_top_view

        runs = [("tube", tube.run.columns()), ("baseline", base.run.columns())]
        for path in animate_top_view(staging, scenario, runs):
            LOGGER.info("animation written: %s", out / path.name)
    total = time.perf_counter() - started
    metrics["total_wall_s"] = total
    if with_acceptance:
        metrics["acceptance"] = acceptance(metrics, total)
    write_json(staging / "metrics.json", metrics)
    return StudyResult(out=out, tube=tube, baseline=base, metrics=metrics, dynamic=dyn_run)


def run_study(scenario: Scenario, out: Path, *, progress: bool = True, with_acceptance: bool = False,
              animate: bool = False, dynamic: bool = False, echo: Echo = print) -> StudyResult:
    """Check every input, certify, run tube + baseline, write every output into ``out``.

    Parameters
    ----------
    out : Path
        Results directory; replaced atomically at the end (see :class:`tubekit.app.output.StagedOutput`).
    animate : bool
        Also write the top-view animation (GIF; MP4 where ffmpeg exists).
    dynamic : bool
        Also run the tube controller on the 4-DOF dynamic plant (:mod:`tubekit.app.dynamic_study`).
    echo : callable
        Receives the result lines (:meth:`StudyResult.summary`, then ``wrote ...``).

    Returns
    -------
    StudyResult
        The runs and ``metrics.json``; ``check()`` is False when a certified promise broke.

    Raises
    ------
    ConfigError
        Any input that cannot run (see :func:`tubekit.checks.check_run_inputs`) or an unusable
        ``out`` (field ``--out``); nothing is written.
    """
    started = time.perf_counter()
    require_one_period("duration", scenario.duration, scenario.controller.dt)
    check_run_inputs(scenario)
    out = Path(out)
    check_output_dir(out)
    with StagedOutput(out) as staged:
        result = _write_study(scenario, out, staged.path, progress, with_acceptance, animate, started, dynamic)
    echo(result.summary())
    echo(f"wrote {out} in {time.perf_counter() - started:.1f} s")
    return result
