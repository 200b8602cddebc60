"""``tubekit campaign``: many closed-loop runs on a dask.distributed cluster — reproducible, resumable.

Pipeline (client side): validate the spec (:mod:`tubekit.app.campaign_spec`) and plan every run →
certify once per distinct certificate input (:func:`verify.certify`, on the client) → open a
:class:`distributed.Client` (a LocalCluster of N worker processes on 127.0.0.1, or ``--scheduler``)
→ submit the unfinished runs (``retries``) → store each finished run as ``DIR/runs/run_KKKKKK.json``
the moment it completes → assemble ``DIR/runs.parquet`` atomically → ``summary.json`` → figures.

Worker side (:func:`simulate_task`): the run's scenario under the shipped tightening (each simulation is
:func:`tubekit.loop.pipeline.certified_run`; the verdict travels in ``Tightening.certified``), plus
``falsify.sequences`` runs where the current is replaced by a random piecewise-constant disturbance
within the certificate's bounds (:func:`verify.falsify.closed_loop.piecewise_disturbance`, one ω per FHOCP
period, drawn from the run's seed); the row keeps the worst figure of each metric over those runs.
Nothing in a row depends on the worker, the order or the scheduler except ``wall_s``.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from tubekit.exceptions import ConfigError, TubekitError
from tubekit.jsonable import write_json
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.app.campaign_spec import CampaignSpec, RunPlan, certificate_key, spec_from_stored
from tubekit.app.output import check_output_dir

__all__ = ["RunTask", "simulate_task", "certify_plans", "open_client", "run_campaign", "read_rows", "replay_run",
           "replay_into", "ReplayResult", "summarise", "summary_line", "write_figures", "METRIC_COLUMNS", "FIGURES"]

LOGGER = logging.getLogger("tubekit.campaign")
#: Per-run metric columns of ``runs.parquet`` (after run, seed and the sampled values).
METRIC_COLUMNS = ("certified", "safe_tier", "tracking_tier", "max_rho_ratio", "min_clearance", "min_e_d",
                  "tracking_rmse", "saturated_steps", "replaced_steps", "backup_s", "backup_engagements",
                  "violated", "safety_broken", "premises_held", "broken", "worst_sequence", "error", "wall_s")
#: Figures written under ``DIR/figures/``.
FIGURES = ("ecdf.png", "worst_runs.png")
#: Retries of a run whose worker raised or died (dask ``retries``).
RETRIES = 3


@dataclass(frozen=True)
class RunTask:
    """Everything a worker needs for one run (pickled to the worker); ``tightening.certified`` is the verdict."""

    run: int
    seed: int
    scenario: Scenario
    tightening: Tightening
    sequences: int


# ---- one run (worker side) ------------------------------------------------------------------------------

def _disturbances(task: RunTask) -> list[Callable | None]:
    """None (the scenario's current), then ``sequences`` piecewise-constant ω within the certificate's bounds."""
    if task.sequences == 0:
        return [None]
    from verify.falsify.closed_loop import piecewise_disturbance

    bound = task.tightening.disturbance
    omega_xy, omega_z = bound.omega_xy, bound.omega_z
    rng = np.random.default_rng([task.seed, 1])
    dt = task.scenario.controller.dt
    return [None] + [piecewise_disturbance(omega_xy, omega_z, dt, rng.random((task.scenario.steps, 3)))
                     for _ in range(task.sequences)]


def _simulate_all(task: RunTask) -> list[Any]:
    """Each simulation of the run: a :class:`tubekit.loop.pipeline.CertifiedRun` per disturbance."""
    from tubekit.loop.pipeline import certified_run

    return [certified_run(task.scenario, task.tightening, label="tube", disturbance=disturbance)
            for disturbance in _disturbances(task)]


def _figures_of(sim: Any) -> dict[str, Any]:
    metrics = sim.metrics
    return {"max_rho_ratio": sim.ratio, "min_clearance": float(metrics["min_clearance"]),
            "min_e_d": float(metrics["min_e_d"]), "tracking_rmse": float(metrics["tracking_rmse"]),
            "saturated_steps": int(metrics["saturated_steps"]), "broken": list(sim.broken),
            "replaced_steps": int(metrics["replaced_steps"]), "backup_s": float(metrics["backup_s"]),
            "backup_engagements": int(metrics["backup_engagements"]),
            "safety_broken": [p.name for p in sim.promises if p.tier == "safe" and p.name in sim.broken],
            "premises_held": sim.premises_held}


def _tiers_of(tightening: Tightening) -> dict[str, bool]:
    """``safe_tier`` and ``tracking_tier``: the tiers the run's certificate gives."""
    from tubekit.loop.promises import tiers_given

    given = tiers_given(tightening)
    return {"safe_tier": bool(given.get("safe")), "tracking_tier": bool(given.get("tracking"))}


def simulate_task(task: RunTask) -> dict[str, Any]:
    """Run ``task`` and return its row (without the sampled values); ``wall_s`` is the only timing."""
    started = time.perf_counter()
    try:
        sims = _simulate_all(task)
    except TubekitError as exc:  # a run that cannot be simulated is recorded, not retried
        return {"run": task.run, "seed": task.seed, "certified": bool(task.tightening.certified),
                **_tiers_of(task.tightening), "max_rho_ratio": None, "min_clearance": None, "min_e_d": None,
                "tracking_rmse": None, "saturated_steps": None, "replaced_steps": None, "backup_s": None,
                "backup_engagements": None, "violated": False, "safety_broken": "", "premises_held": False,
                "broken": "", "worst_sequence": -1, "error": str(exc).splitlines()[0],
                "wall_s": time.perf_counter() - started}
    return _row_of(task, sims, started)


def _row_of(task: RunTask, sims: list[Any], started: float) -> dict[str, Any]:
    """The row of a run: the worst figure of each metric over its simulations."""
    figures = [_figures_of(sim) for sim in sims]
    worst = int(np.argmax([f["max_rho_ratio"] for f in figures]))
    return {"run": task.run, "seed": task.seed, "certified": bool(task.tightening.certified),
            **_tiers_of(task.tightening), "max_rho_ratio": figures[worst]["max_rho_ratio"],
            "min_clearance": min(f["min_clearance"] for f in figures),
            "min_e_d": min(f["min_e_d"] for f in figures),
            "tracking_rmse": max(f["tracking_rmse"] for f in figures),
            "saturated_steps": max(f["saturated_steps"] for f in figures),
            **{k: max(f[k] for f in figures) for k in ("replaced_steps", "backup_s", "backup_engagements")},
            "violated": any(f["broken"] for f in figures),
            "safety_broken": ",".join(sorted({n for f in figures for n in f["safety_broken"]})),
            "premises_held": all(f["premises_held"] for f in figures),
            "broken": ",".join(sorted({n for f in figures for n in f["broken"]})),
            "worst_sequence": worst, "error": "", "wall_s": time.perf_counter() - started}


# ---- certificates and the cluster (client side) ---------------------------------------------------------

def certify_plans(plans: list[RunPlan]) -> dict[str, Tightening]:
    """One certification per distinct certificate input of ``plans`` (keyed by :func:`certificate_key`):
    its best-effort tightening, ``certified`` set when the certificate certified it."""
    from tubekit.app.certified import certify_design

    certs: dict[str, Tightening] = {}
    for plan in plans:
        key = certificate_key(plan.scenario)
        if key not in certs:
            certs[key] = certify_design(plan.scenario).tightening
    return certs


@contextlib.contextmanager
def open_client(workers: int, scheduler: str | None) -> Iterator[Any]:
    """A :class:`distributed.Client`: on ``scheduler`` (tcp://HOST:PORT), else on a LocalCluster of
    ``workers`` single-threaded worker processes bound to 127.0.0.1 (dashboard on 127.0.0.1, a free port)."""
    from distributed import Client, LocalCluster

    if scheduler is not None:
        if not scheduler.startswith(("tcp://", "tls://")):
            raise ConfigError("--scheduler", "an address tcp://HOST:PORT", scheduler)
        try:
            client = Client(scheduler, timeout="15s")
        except (OSError, TimeoutError) as exc:
            raise ConfigError("--scheduler", "a reachable dask scheduler", scheduler, str(exc)) from None
        with client:
            yield client
        return
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      scheduler_port=0, dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client:
        yield client


# ---- the campaign directory -----------------------------------------------------------------------------

def _run_file(out: Path, run: int) -> Path:
    return out / "runs" / f"run_{run:06d}.json"


def _check_campaign_dir(out: Path, spec: CampaignSpec) -> None:
    """Read only: ``out`` is new, empty, or holds this campaign (same fingerprint); else ``--out`` is refused."""
    stored = out / "campaign.json"
    if stored.exists():
        try:
            old = json.loads(stored.read_text(encoding="utf-8"))["fingerprint"]
        except (OSError, ValueError, KeyError):
            old = None
        if old != spec.fingerprint:
            raise ConfigError("--out", "a new directory or one holding this same campaign (same spec)", str(out),
                              "It holds another campaign's runs.")
    elif out.exists() and any(out.iterdir()):
        raise ConfigError("--out", "a new or empty directory (or this campaign's)", str(out), "It is not empty.")


def _prepare_dir(out: Path, spec: CampaignSpec) -> None:
    """Create ``out/runs`` and record the spec in ``out/campaign.json``."""
    (out / "runs").mkdir(parents=True, exist_ok=True)
    write_json(out / "campaign.json", {"fingerprint": spec.fingerprint, "spec": spec.to_dict()})


def _finished(out: Path) -> set[int]:
    runs = out / "runs"
    return {int(p.stem[4:]) for p in runs.glob("run_*.json")} if runs.is_dir() else set()


def _flat_values(values: dict[str, Any]) -> dict[str, Any]:
    """Sampled values as columns; a vector ``key`` becomes ``key[0]``, ``key[1]``, ..."""
    flat: dict[str, Any] = {}
    for key, value in values.items():
        if isinstance(value, list) and value and isinstance(value[0], dict):  # a sampled obstacle set
            flat.update({f"{key}.count": len(value), key: json.dumps(value)})
        elif isinstance(value, list):
            flat.update({f"{key}[{i}]": v for i, v in enumerate(value)})
        else:
            flat[key] = value
    return flat


def read_rows(out: str | Path) -> list[dict[str, Any]]:
    """Every stored run of campaign ``out`` (``runs/*.json``), by run number."""
    rows = []
    for path in sorted((Path(out) / "runs").glob("run_*.json")):
        rows.append(json.loads(path.read_text(encoding="utf-8")))
    return rows


def _write_parquet(out: Path, rows: list[dict[str, Any]]) -> Path:
    """``runs.parquet`` written to a temporary name, then renamed (atomic)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = list(rows[0]) if rows else ["run", "seed", *METRIC_COLUMNS]
    table = pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in rows])
    target = out / "runs.parquet"
    temporary = out / f".runs.parquet.{os.getpid()}.tmp"
    pq.write_table(table, temporary)
    os.replace(temporary, target)
    return target


# ---- summary and figures --------------------------------------------------------------------------------

def _quantiles(rows: list[dict], key: str) -> dict[str, float | None]:
    x = np.array([r[key] for r in rows if r.get(key) is not None], dtype=float)
    x = x[np.isfinite(x)]
    if not x.size:
        return {"min": None, "p05": None, "median": None, "p95": None, "max": None}
    q = np.quantile(x, [0.0, 0.05, 0.5, 0.95, 1.0])
    return dict(zip(("min", "p05", "median", "p95", "max"), (float(v) for v in q)))


def _worst(rows: list[dict], count: int = 10) -> list[dict]:
    ranked = sorted((r for r in rows if r.get("max_rho_ratio") is not None), key=lambda r: -r["max_rho_ratio"])
    keep = ("run", "seed", "certified", "max_rho_ratio", "min_clearance", "violated", "broken", "worst_sequence")
    values = [k for k in (ranked[0] if ranked else {}) if k not in keep and k not in METRIC_COLUMNS]
    return [{**{k: r[k] for k in keep}, "values": {k: r[k] for k in values}} for r in ranked[:count]]


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


def summarise(rows: list[dict], spec: CampaignSpec, certs: dict[str, Tightening], facts: dict) -> dict[str, Any]:
    """``summary.json``: the largest max_rho_ratio beside the certified radius (1 in the tube's box norm), counts."""
    certified = [r for r in rows if r["certified"]]
    tubes = np.array([t.tube for t in certs.values() if t.certified], dtype=float).reshape(-1, 3)
    largest = _worst(rows, 1)
    largest_cert = _worst(certified, 1)
    return {
        "runs": len(rows), "planned_runs": spec.runs, "seed": spec.seed, "duration_s": spec.duration,
        "scenario": spec.scenario_source, "falsify_sequences": spec.falsify_sequences,
        "certified_runs": len(certified), "distinct_certificates": len(certs),
        "certified_certificates": int(sum(bool(t.certified) for t in certs.values())),
        "certificate_radius": 1.0,
        "certificate_tube_box": {"min": tubes.min(axis=0).tolist() if tubes.size else None,
                                 "max": tubes.max(axis=0).tolist() if tubes.size else None},
        "largest_max_rho_ratio": largest[0] if largest else None,
        "largest_max_rho_ratio_certified": largest_cert[0] if largest_cert else None,
        "violations": sum(bool(r["violated"]) for r in rows),
        "violations_certified": sum(bool(r["violated"]) for r in certified),  # of a given tier, its premises held
        "premise_failures": sum(not r["premises_held"] for r in rows),
        "errors": sum(bool(r["error"]) for r in rows),
        **_tier_summary(rows, spec.duration),
        "metrics": {k: _quantiles(rows, k) for k in ("max_rho_ratio", "min_clearance", "min_e_d", "tracking_rmse",
                                                     "saturated_steps", "replaced_steps", "backup_s", "wall_s")},
        "worst_runs": _worst(rows),
        **facts,
    }


def summary_line(summary: dict, out: str | Path) -> str:
    """The result line of ``tubekit campaign``: runs, the largest max_rho_ratio beside the radius, violations."""
    top = summary["largest_max_rho_ratio"] or {}
    return (f"{summary['runs']} runs ({summary['computed_runs']} computed), {summary['certified_runs']} certified; "
            f"largest max_rho_ratio {top.get('max_rho_ratio')} (run {top.get('run')}, seed {top.get('seed')}) vs "
            f"certified radius 1; violations {summary['violations']} ({summary['violations_certified']} of a "
            f"certified run with its premises held); safety promises broken {summary['safety_broken_safe_tier']} "
            f"(of {summary['safe_tier_runs']} runs with the safe tier); backup engaged in "
            f"{summary['backup']['runs_engaged']} runs, {summary['backup']['seconds_total']:.4g} s in all; wrote {out}")


def write_figures(out: Path, rows: list[dict], epsilon: float) -> list[Path]:
    """``figures/ecdf.png`` (one ECDF per metric, its bound dashed) and ``figures/worst_runs.png``."""
    from matplotlib.figure import Figure

    folder = out / "figures"
    folder.mkdir(exist_ok=True)
    panels = (("max_rho_ratio", 1.0, "certified radius"), ("min_clearance", 0.0, "contact"),
              ("min_e_d", epsilon, "epsilon"), ("tracking_rmse", None, ""), ("saturated_steps", None, ""),
              ("replaced_steps", None, ""), ("backup_s", None, ""), ("wall_s", None, ""))
    fig = Figure(figsize=(14, 6.5), layout="constrained")
    for ax, (key, bound, label) in zip(fig.subplots(2, 4).ravel(), panels):
        x = np.sort([float(r[key]) for r in rows if r.get(key) is not None and np.isfinite(float(r[key]))])
        ax.step(np.r_[x[:1], x], np.arange(x.size + 1) / max(x.size, 1), where="post", color="C0")
        if bound is not None:
            ax.axvline(bound, color="C3", ls="--", label=label)
            ax.legend(loc="lower right", fontsize=8)
        ax.set(xlabel=key, ylabel="fraction of runs <= x", title=f"{key} ({x.size} runs)")
        ax.grid(alpha=0.3)
    paths = [folder / FIGURES[0]]
    fig.savefig(paths[0], dpi=100)
    worst = _worst(rows, 15)[::-1]
    fig = Figure(figsize=(8, 0.35 * len(worst) + 1.5), layout="constrained")
    ax = fig.subplots()
    ax.barh(range(len(worst)), [w["max_rho_ratio"] for w in worst],
            color=["C3" if w["violated"] else "C0" for w in worst])
    ax.set_yticks(range(len(worst)), [f"run {w['run']}  seed {w['seed']}" for w in worst], fontsize=7)
    ax.axvline(1.0, color="C3", ls="--", label="certified radius")
    ax.set(xlabel="max_rho_ratio (tube deviation / certified radius)", title="worst runs (replay: tubekit "
           "simulate --from-campaign DIR --run K)")
    ax.legend(loc="lower right", fontsize=8)
    paths.append(folder / FIGURES[1])
    fig.savefig(paths[1], dpi=100)
    return paths


# ---- the pipeline ---------------------------------------------------------------------------------------

def _execute(client: Any, tasks: list[RunTask], plans: dict[int, RunPlan], out: Path, key: str,
             progress: bool) -> None:
    """Submit ``tasks``; store each row the moment its run completes."""
    from distributed import as_completed
    from tqdm.auto import tqdm

    futures = [client.submit(simulate_task, task, key=f"tubekit-{key}-run-{task.run}", retries=RETRIES,
                             pure=False) for task in tasks]
    with tqdm(total=len(futures), unit="run", disable=not (progress and sys.stderr.isatty())) as bar:
        for future in as_completed(futures):
            row = future.result()
            row = {"run": row["run"], "seed": row["seed"], **_flat_values(plans[row["run"]].values),
                   **{k: row[k] for k in METRIC_COLUMNS}}
            write_json(_run_file(out, row["run"]), row)
            bar.update(1)
            future.release()


def run_campaign(spec: CampaignSpec, out: str | Path, *, workers: int = 2, scheduler: str | None = None,
                 progress: bool = True) -> dict[str, Any]:
    """Run every unfinished run of ``spec`` into ``out``; write runs.parquet, summary.json, figures.

    Parameters
    ----------
    workers : int
        Worker processes of the LocalCluster (ignored with ``scheduler``).
    scheduler : str, optional
        ``tcp://HOST:PORT`` of an existing dask scheduler.

    Returns
    -------
    dict
        The summary (also in ``out/summary.json``).
    """
    started = time.perf_counter()
    out = Path(out)
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ConfigError("--workers", "an integer >= 1", workers)
    check_output_dir(out)
    _check_campaign_dir(out, spec)
    plans = {k: spec.plan(k) for k in range(spec.runs)}  # every sample is validated before anything is written
    certs = certify_plans(list(plans.values()))
    done = _finished(out) if (out / "campaign.json").exists() else set()
    todo = [RunTask(k, p.seed, p.scenario, certs[certificate_key(p.scenario)], spec.falsify_sequences)
            for k, p in plans.items() if k not in done]
    LOGGER.info("campaign: %d runs (%d already finished), %d distinct certificates, %s", spec.runs,
                spec.runs - len(todo), len(certs), scheduler or f"LocalCluster of {workers} workers")
    nworkers = 0
    with open_client(workers, scheduler) if todo else contextlib.nullcontext() as client:
        _prepare_dir(out, spec)  # after the scheduler answered: a bad --scheduler writes nothing
        if todo:
            _execute(client, todo, plans, out, spec.fingerprint[:12], progress)
            nworkers = len(client.scheduler_info().get("workers", {}))
    rows = [r for r in read_rows(out) if r["run"] < spec.runs]
    _write_parquet(out, rows)
    facts = {"computed_runs": len(todo), "skipped_runs": spec.runs - len(todo), "workers": nworkers,
             "scheduler": scheduler or "LocalCluster", "campaign_wall_s": time.perf_counter() - started,
             "runs_wall_s": float(sum(r["wall_s"] for r in rows))}
    summary = summarise(rows, spec, certs, facts)
    write_json(out / "summary.json", summary)
    write_figures(out, rows, float(spec.base["epsilon"]))
    return summary


def replay_run(campaign_dir: str | Path, run: int) -> tuple[dict, dict | None, Any]:
    """Run ``run`` of a campaign again, in this process: (replayed row, stored row or None, worst SimulationResult)."""
    folder = Path(campaign_dir)
    try:
        stored = json.loads((folder / "campaign.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        raise ConfigError("--from-campaign", "a campaign directory (with campaign.json)", str(folder)) from None
    spec = spec_from_stored(stored["spec"])
    if isinstance(run, bool) or not isinstance(run, int) or not 0 <= run < spec.runs:
        raise ConfigError("--run", f"a run number in [0, {spec.runs - 1}]", run)
    plan = spec.plan(run)
    cert = certify_plans([plan])[certificate_key(plan.scenario)]
    task = RunTask(run, plan.seed, plan.scenario, cert, spec.falsify_sequences)
    started = time.perf_counter()
    sims = _simulate_all(task)
    row = _row_of(task, sims, started)
    row = {"run": run, "seed": plan.seed, **_flat_values(plan.values), **{k: row[k] for k in METRIC_COLUMNS}}
    worst = sims[row["worst_sequence"]].run
    path = _run_file(folder, run)
    previous = json.loads(path.read_text(encoding="utf-8")) if path.exists() else None
    return row, previous, worst


@dataclass(frozen=True)
class ReplayResult:
    """A campaign run replayed: the replayed row, the stored one (None if never stored), where it was written."""

    row: dict[str, Any]
    stored: dict[str, Any] | None
    out: Path

    @property
    def identical(self) -> bool:
        """The replayed row equals the stored one (``wall_s`` aside)."""
        from tubekit.jsonable import dumps

        return self.stored is not None and dumps({**self.stored, "wall_s": 0}) == dumps({**self.row, "wall_s": 0})

    @property
    def broken(self) -> bool:
        """The run is certified and broke a promise (its premises aside)."""
        return bool(self.row["certified"] and self.row["violated"])

    def check(self) -> bool:
        """True when the replay is identical to the campaign's row and no certified promise broke."""
        return self.identical and not self.broken

    def summary(self) -> str:
        """Each figure replayed beside the campaign's, then the verdict line."""
        stored = self.stored or {}
        lines = [f"{key:16s} replayed {self.row[key]!s:24s} campaign {stored.get(key)!s}"
                 for key in ("max_rho_ratio", "min_clearance", "min_e_d", "tracking_rmse", "saturated_steps",
                             "violated")]
        lines.append(f"run {self.row['run']} (seed {self.row['seed']}): "
                     f"{'identical to' if self.identical else 'DIFFERS from'} the campaign's row; wrote {self.out}")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """``replay.json``."""
        return {"replayed": self.row, "stored": self.stored, "identical": self.identical}


def replay_into(campaign_dir: str | Path, run: int, out: str | Path | None,
                echo: Callable = print) -> ReplayResult:
    """``tubekit simulate --from-campaign DIR --run K``: replay, write ``trajectory.csv`` and ``replay.json``."""
    target = Path(out) if out else Path(campaign_dir) / f"replay_{run:06d}"
    check_output_dir(target)
    row, stored, worst = replay_run(campaign_dir, run)
    target.mkdir(parents=True, exist_ok=True)
    worst.write_csv(target / "trajectory.csv")
    result = ReplayResult(row, stored, target)
    write_json(target / "replay.json", result.to_dict())
    echo(result.summary())
    return result
