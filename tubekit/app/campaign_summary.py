"""The summary of a campaign (``summary.json``, the result line, throughput) and its figures.

:func:`summarise` reads the run rows (``DIR/runs/*.json``): the runs per tier their certificate gives
(``runs_by_tier``: both, safe only, none; issue 35: no run is called certified on the safe tier alone),
the largest ``max_rho_ratio`` beside the certified radius 1 (the tube's box norm), violations, the tiers'
figures (issue 21), quantiles of each metric, the 10 worst runs and the throughput of this invocation
(issue 23): simulated seconds per wall second and runs per minute. :func:`write_figures` draws
``figures/ecdf.png`` and ``figures/worst_runs.png`` (matplotlib, imported only to draw them), whatever the rows
hold (no tube, no certified run), each written atomically.
"""

from __future__ import annotations

import io
import os
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from tubekit.app.campaign_spec import CampaignSpec
from tubekit.app.plots_campaign import TIERS, ecdf_figure, empty_reason, tier_counts, tier_of, worst_runs_figure
from tubekit.tightening import Tightening

__all__ = ["summarise", "summary_line", "throughput", "write_figures", "import_plotting", "METRIC_COLUMNS", "FIGURES"]

#: Per-run metric columns of ``runs.parquet`` (after run, seed and the sampled values).
METRIC_COLUMNS = ("certified", "safe_tier", "tracking_tier", "max_rho_ratio", "min_clearance", "min_e_d",
                  "tracking_rmse", "saturated_steps", "replaced_steps", "backup_s", "backup_engagements",
                  "violated", "safety_broken", "premises_held", "broken", "worst_sequence", "error", "wall_s")
#: Figures written under ``DIR/figures/``.
FIGURES = ("ecdf.png", "worst_runs.png")


def _quantiles(rows: list[dict], key: str) -> dict[str, float | None]:
    x = np.array([r[key] for r in rows if r.get(key) is not None], dtype=float)
    x = x[np.isfinite(x)]
    if not x.size:
        return {"min": None, "p05": None, "median": None, "p95": None, "max": None}
    q = np.quantile(x, [0.0, 0.05, 0.5, 0.95, 1.0])
    return dict(zip(("min", "p05", "median", "p95", "max"), (float(v) for v in q)))


def _worst(rows: list[dict], count: int = 10) -> list[dict]:
    ranked = sorted((r for r in rows if r.get("max_rho_ratio") is not None), key=lambda r: -r["max_rho_ratio"])
    keep = ("run", "seed", "certified", "safe_tier", "tracking_tier", "max_rho_ratio", "min_clearance", "violated",
            "broken", "worst_sequence")
    values = [k for k in (ranked[0] if ranked else {}) if k not in keep and k not in METRIC_COLUMNS]
    return [{**{k: r.get(k) for k in keep}, "values": {k: r[k] for k in values}} for r in ranked[:count]]


def _tier_summary(rows: list[dict], seconds_per_run: float) -> dict[str, Any]:
    """Safety (must be 0), the backup's activity and the tracking tier over the runs (issue 21); a row's
    ``backup_s`` is its worst simulation's, so ``share_of_simulated_time`` is per run's duration."""
    safe = [r for r in rows if r.get("safe_tier")]
    tracking = [r for r in rows if r.get("tracking_tier")]
    engaged = [r for r in rows if (r.get("backup_s") or 0) > 0]
    simulated = seconds_per_run * len(rows)
    return {
        "safe_tier_runs": len(safe), "tracking_tier_runs": len(tracking),
        "safety_broken": sum(bool(r.get("safety_broken")) for r in rows),
        "safety_broken_safe_tier": sum(bool(r.get("safety_broken")) for r in safe),
        "tracking_broken_tracking_tier": sum(bool(r["broken"]) and r["broken"] != r.get("safety_broken")
                                             for r in tracking),
        "backup": {"runs_engaged": len(engaged), "fraction_engaged": len(engaged) / len(rows) if rows else None,
                   "seconds_total": float(sum(r["backup_s"] for r in engaged)),
                   "share_of_simulated_time": (float(sum(r["backup_s"] for r in engaged)) / simulated
                                               if simulated else None),
                   "seconds_per_engaged_run": _quantiles(engaged, "backup_s"),
                   "engagements_per_engaged_run": _quantiles(engaged, "backup_engagements")},
        "runs_with_replaced_steps": sum((r.get("replaced_steps") or 0) > 0 for r in rows),
    }


def throughput(computed_runs: int, simulated_s_per_run: float, wall_s: float, runs_wall_s: float) -> dict[str, Any]:
    """The throughput of one invocation (None where undefined: no run computed).

    Parameters
    ----------
    computed_runs : int
        Runs computed by this invocation (skipped ones excluded).
    simulated_s_per_run : float
        Simulated seconds per run (s): the duration times 1 + the falsification sequences.
    wall_s : float
        Wall time of the invocation (s), from the spec's validation to the figures.
    runs_wall_s : float
        Sum of the computed runs' own wall times (s, on the workers).

    Returns
    -------
    dict
        ``simulated_s``, ``simulated_s_per_wall_s``, ``runs_per_minute`` (per wall minute) and
        ``simulated_s_per_run_s`` (the simulations' own speed: simulated s per second of a worker's run).
    """
    simulated = float(computed_runs * simulated_s_per_run)
    some = computed_runs > 0
    return {"simulated_s": simulated, "wall_s": float(wall_s),
            "simulated_s_per_wall_s": simulated / wall_s if some and wall_s > 0 else None,
            "runs_per_minute": 60.0 * computed_runs / wall_s if some and wall_s > 0 else None,
            "simulated_s_per_run_s": simulated / runs_wall_s if some and runs_wall_s > 0 else None}


def _certificates_by_tier(certs: dict[str, Tightening]) -> tuple[dict[str, int], np.ndarray]:
    """The distinct certificates per tier they give (:data:`TIERS`, read as a run's row reads them) and the
    tubes of those giving the tracking tier (the tube is its promise; a safe-only design has none), shape (n, 3)."""
    from tubekit.app.campaign_task import _tiers_of  # the row's safe_tier and tracking_tier

    counts = dict.fromkeys(TIERS, 0)
    tubes = []
    for tightening in certs.values():
        tier = tier_of(_tiers_of(tightening))
        counts[tier] += 1
        if tier == "both":
            tubes.append(tightening.tube)
    return counts, np.array(tubes, dtype=float).reshape(-1, 3)


def summarise(rows: list[dict], spec: CampaignSpec, certs: dict[str, Tightening], facts: dict) -> dict[str, Any]:
    """``summary.json``: runs per tier, the largest max_rho_ratio beside the certified radius (1 in the tube's
    box norm), violations, the tiers' figures, quantiles, the worst runs and the throughput.

    Parameters
    ----------
    rows : list of dict
        The campaign's rows (``runs/*.json``).
    spec : CampaignSpec
        The campaign's spec.
    certs : dict
        Its distinct certificates' tightenings, by input key.
    facts : dict
        ``computed_runs``, ``campaign_wall_s``, ``computed_runs_wall_s`` and whatever else the summary carries.

    Returns
    -------
    dict
        ``runs_by_tier`` counts each run once by the tiers its certificate gives (``both``, ``safe_only``,
        ``none``); ``certificates_by_tier`` the distinct certificates alike. ``violations_certified`` counts
        runs with a tier that broke one of its promises; ``largest_max_rho_ratio_certified`` and
        ``certificate_tube_box`` are of the runs and certificates with the tracking tier (null: none).
    """
    given = [r for r in rows if tier_of(r) != "none"]  # a tier given: the safe tier at least
    tracking = [r for r in rows if tier_of(r) == "both"]
    by_certificate, tubes = _certificates_by_tier(certs)
    worst = _worst(rows)
    largest_cert = _worst(tracking, 1)
    return {
        "runs": len(rows), "planned_runs": spec.runs, "seed": spec.seed, "duration_s": spec.duration,
        "scenario": spec.scenario_source, "falsify_sequences": spec.falsify_sequences,
        "runs_by_tier": tier_counts(rows), "distinct_certificates": len(certs),
        "certificates_by_tier": by_certificate,
        "certificate_radius": 1.0,
        "certificate_tube_box": {"min": tubes.min(axis=0).tolist() if tubes.size else None,
                                 "max": tubes.max(axis=0).tolist() if tubes.size else None},
        "largest_max_rho_ratio": worst[0] if worst else None,
        "largest_max_rho_ratio_certified": largest_cert[0] if largest_cert else None,
        "violations": sum(bool(r["violated"]) for r in rows),
        "violations_certified": sum(bool(r["violated"]) for r in given),  # of a given tier, its premises held
        "premise_failures": sum(not r["premises_held"] for r in rows),
        "errors": sum(bool(r["error"]) for r in rows),
        **_tier_summary(rows, spec.duration),
        "metrics": {k: _quantiles(rows, k) for k in ("max_rho_ratio", "min_clearance", "min_e_d", "tracking_rmse",
                                                     "saturated_steps", "replaced_steps", "backup_s", "wall_s")},
        "worst_runs": worst,
        **facts,
        "throughput": throughput(facts["computed_runs"], spec.duration * (1 + spec.falsify_sequences),
                                 facts["campaign_wall_s"], facts.get("computed_runs_wall_s", 0.0)),
    }


def summary_line(summary: dict, out: str | Path) -> str:
    """The result line of ``tubekit campaign``: runs per tier, the largest max_rho_ratio beside the radius
    (or that no run has one), violations, safety, the backup and the throughput."""
    tiers = summary["runs_by_tier"]
    top = summary["largest_max_rho_ratio"]
    radius = "vs certified radius 1" if tiers["both"] else "(no run has the tracking tier: no tube is promised)"
    ratio = (f"largest max_rho_ratio {top.get('max_rho_ratio')} (run {top.get('run')}, seed {top.get('seed')}) "
             f"{radius}" if top else "no tube ratio (no run has a tube)")
    return (f"{summary['runs']} runs ({summary['computed_runs']} computed): {tiers['both']} with both tiers, "
            f"{tiers['safe_only']} with the safe tier only, {tiers['none']} uncertified; {ratio}; "
            f"violations {summary['violations']} ({summary['violations_certified']} of a tier a run's certificate "
            f"gives, its premises held); safety promises broken {summary['safety_broken_safe_tier']} "
            f"(of {summary['safe_tier_runs']} runs with the safe tier); backup engaged in "
            f"{summary['backup']['runs_engaged']} runs, {summary['backup']['seconds_total']:.4g} s in all; "
            f"{_speed(summary['throughput'])}wrote {out}")


def _speed(rate: dict) -> str:
    """``"9.2 s wall: 26.1 simulated s per wall s, 104 runs/min; "`` (empty when no run was computed)."""
    if rate["runs_per_minute"] is None:
        return ""
    return (f"{rate['wall_s']:.3g} s wall: {rate['simulated_s_per_wall_s']:.3g} simulated s per wall s, "
            f"{rate['runs_per_minute']:.3g} runs/min; ")


def import_plotting() -> None:
    """Import what the tables and :func:`write_figures` need (pyarrow's parquet writer, matplotlib's Figure,
    ticker and Agg, ~0.6 s): called while the client waits for its workers, so the end does not pay it."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401
    import matplotlib.ticker  # noqa: F401
    import pyarrow.parquet  # noqa: F401


def _save(figure: Any, path: Path) -> Path:
    """``figure`` as a PNG at ``path``, atomically (drawn in memory, then a temporary file renamed into place)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100)
    temporary = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        temporary.write_bytes(buffer.getvalue())
        os.replace(temporary, path)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
    return path


def write_figures(out: Path, rows: list[dict], epsilon: float) -> list[Path]:
    """``figures/ecdf.png`` and ``figures/worst_runs.png`` (:mod:`tubekit.app.plots_campaign`: units on every
    axis; the worst runs as the margin 1 - ratio on a log axis; a panel saying why where there is nothing to
    draw, e.g. no tube at σ = 0), each written atomically."""
    folder = out / "figures"
    folder.mkdir(exist_ok=True)
    worst = _worst(rows, 15)
    return [_save(ecdf_figure(rows, epsilon), folder / FIGURES[0]),
            _save(worst_runs_figure(worst, "" if worst else empty_reason(rows, "max_rho_ratio")), folder / FIGURES[1])]
