"""``tubekit campaign``: many closed-loop runs on a dask.distributed cluster — reproducible, resumable.

Pipeline (client side): validate the spec (:mod:`tubekit.app.campaign_spec`) and plan every run →
load the certificates stored in ``DIR/certificates/`` (:func:`tubekit.app.certified.read_cached`: checksum,
design key, scenario) → start the workers' fork server, warming up on the first scenario, while this
process imports what its tables and figures need (:mod:`tubekit.app.campaign_cluster`) → open a
:class:`distributed.Client` (a LocalCluster of N worker processes on 127.0.0.1 forked from that server,
or ``--scheduler``) → submit one certification task per missing certificate input
(:func:`tubekit.app.certified.issue_certificate`, keyed by :func:`tubekit.app.certified.input_key`) and
the unfinished runs, each depending on its certificate's task (``retries``) → store each certificate as
``DIR/certificates/<key>.json`` and each finished run as ``DIR/runs/run_KKKKKK.json`` the moment it
completes → assemble ``DIR/runs.parquet`` atomically → ``summary.json`` (with the throughput) → figures,
while the cluster closes.

Worker side: :func:`tubekit.app.campaign_task.simulate_task` (one run, its row).
"""

from __future__ import annotations

import atexit
import contextlib
import gc
import json
import logging
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from tubekit.exceptions import ConfigError
from tubekit.jsonable import write_json
from tubekit.scenario import Scenario
from tubekit.tightening import Tightening
from tubekit.app.campaign_spec import CampaignSpec, RunPlan, spec_from_stored
from tubekit.app.campaign_cluster import open_client, start_fork_server
from tubekit.app.campaign_task import RunTask, row_of, simulate_all, simulate_task
from tubekit.app.exit_codes import interrupts_remembered
from tubekit.app.output import check_output_dir
from tubekit.app.campaign_summary import (FIGURES, METRIC_COLUMNS, import_plotting, summarise, summary_line,
                                          write_figures)

__all__ = ["RunTask", "simulate_task", "certify_plans", "cached_certificates", "CERTIFICATES", "open_client",
           "run_campaign", "read_rows", "replay_run",
           "replay_into", "ReplayResult", "summarise", "summary_line", "write_figures", "METRIC_COLUMNS", "FIGURES"]

LOGGER = logging.getLogger("tubekit.campaign")
#: Retries of a run whose worker raised or died (dask ``retries``).
RETRIES = 3
#: Folder of a campaign directory holding its certificates, one ``<input key>.json`` each.
CERTIFICATES = "certificates"


# ---- certificates and the cluster (client side) ---------------------------------------------------------

def certify_plans(plans: list[RunPlan]) -> dict[str, Tightening]:
    """One certification per distinct certificate input of ``plans``, in this process (keyed by
    :func:`tubekit.app.certified.input_key`): its best-effort tightening, ``certified`` set when certified."""
    from tubekit.app.certified import certify_design, input_key

    certs: dict[str, Tightening] = {}
    for plan in plans:
        key = input_key(plan.scenario)
        if key not in certs:
            certs[key] = certify_design(plan.scenario).tightening
    return certs


def cached_certificates(out: Path, scenarios: dict[str, Scenario]) -> dict[str, Tightening]:
    """The certificates of ``scenarios`` (by input key) stored in ``out/certificates``, each loaded through
    :func:`tubekit.app.certified.read_cached` (a file that fails a check is refused: ConfigError)."""
    from tubekit.app.certified import read_cached

    folder = out / CERTIFICATES
    if not folder.is_dir():
        return {}
    found = {key: read_cached(folder, scenario) for key, scenario in scenarios.items()}
    return {key: design.tightening for key, design in found.items() if design is not None}


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


def _stored_row(plan: RunPlan, row: dict[str, Any]) -> dict[str, Any]:
    """A worker's ``row`` as stored: run, seed, ``plan``'s sampled values (:func:`_flat_values`), the metrics."""
    return {"run": row["run"], "seed": row["seed"], **_flat_values(plan.values), **{k: row[k] for k in METRIC_COLUMNS}}


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


# ---- the pipeline ---------------------------------------------------------------------------------------

def _submit(client: Any, tasks: list[RunTask], keys: dict[int, str], missing: dict[str, Scenario],
            name: str) -> tuple[list[Any], list[Any]]:
    """One certificate task per ``missing`` input key (first), then the runs, each depending on its own."""
    from tubekit.app.certified import issue_certificate

    certs = {key: client.submit(issue_certificate, scenario, key=f"tubekit-{name}-cert-{key[:16]}",
                                retries=RETRIES, pure=False, priority=1) for key, scenario in missing.items()}
    runs = [client.submit(simulate_task, task, certs.get(keys[task.run]), key=f"tubekit-{name}-run-{task.run}",
                          retries=RETRIES, pure=False) for task in tasks]
    return list(certs.values()), runs


def _execute(client: Any, tasks: list[RunTask], plans: dict[int, RunPlan], keys: dict[int, str], out: Path,
             key: str, progress: bool, missing: dict[str, Scenario], certs: dict[str, Tightening]) -> None:
    """Certify ``missing`` and run ``tasks`` on the workers (``keys``: each run's input key); store each
    certificate (into ``certs`` and ``out/certificates``) and each row the moment it completes."""
    from distributed import as_completed
    from tqdm.auto import tqdm

    from tubekit.app.certified import IssuedCertificate, write_cached

    cert_futures, futures = _submit(client, tasks, keys, missing, key)
    with tqdm(total=len(futures), unit="run", disable=not (progress and sys.stderr.isatty())) as bar:
        for future in as_completed(cert_futures + futures):
            row = future.result()
            if isinstance(row, IssuedCertificate):
                write_cached(out / CERTIFICATES, row)
                certs[row.key] = row.tightening
                continue
            row = _stored_row(plans[row["run"]], row)
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
    atexit.unregister(gc.freeze)  # once: at this process's exit its final collections skip what is alive
    atexit.register(gc.freeze)  # (~0.3 s of a campaign client's exit: dask, pyarrow, matplotlib)
    out = Path(out)
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ConfigError("--workers", "an integer >= 1", workers)
    check_output_dir(out)
    _check_campaign_dir(out, spec)
    plans = {k: spec.plan(k) for k in range(spec.runs)}  # every sample is validated before anything is written
    from tubekit.app.certified import input_key

    keys = {k: input_key(p.scenario) for k, p in plans.items()}
    scenarios = {keys[k]: p.scenario for k, p in reversed(plans.items())}  # the first run's scenario
    resumed = (out / "campaign.json").exists()
    certs = cached_certificates(out, scenarios) if resumed else {}
    missing = {key: scenario for key, scenario in scenarios.items() if key not in certs}
    done = _finished(out) if resumed else set()
    todo = [RunTask(k, p.seed, p.scenario, certs.get(keys[k]), spec.falsify_sequences)
            for k, p in plans.items() if k not in done]
    LOGGER.info("campaign: %d runs (%d already finished), %d distinct certificates (%d stored), %s", spec.runs,
                spec.runs - len(todo), len(scenarios), len(certs), scheduler or f"LocalCluster of {workers} workers")
    with interrupts_remembered():  # a Ctrl-C that dask swallows while the cluster closes still ends in exit 130
        return _run(out, spec, plans, keys, todo, missing, certs, workers, scheduler, progress, started)


def _run(out: Path, spec: CampaignSpec, plans: dict[int, RunPlan], keys: dict[int, str], todo: list[RunTask],
         missing: dict[str, Scenario], certs: dict[str, Tightening], workers: int, scheduler: str | None,
         progress: bool, started: float) -> dict[str, Any]:
    """The cluster, the runs and the outputs of :func:`run_campaign` (its inputs validated)."""
    nworkers = 0
    if scheduler is None and (todo or missing):  # the workers' fork server warms up while the client ...
        start_fork_server(next(iter(missing.values()), todo[0].scenario if todo else None))
    import_plotting()  # ... imports what the end needs (in this thread: a second one would slow both)
    with ThreadPoolExecutor(1, thread_name_prefix="tubekit-campaign-finish") as pool:
        with open_client(workers, scheduler) if todo or missing else contextlib.nullcontext() as client:
            _prepare_dir(out, spec)  # after the scheduler answered: a bad --scheduler writes nothing
            if client is not None:
                _execute(client, todo, plans, keys, out, spec.fingerprint[:12], progress, missing, certs)
                nworkers = len(client.scheduler_info().get("workers", {}))
            facts = {"workers": nworkers, "scheduler": scheduler or "LocalCluster"}
            finishing = pool.submit(_finish, out, spec, certs, todo, started, facts)  # while the cluster stops
        return finishing.result()


def _finish(out: Path, spec: CampaignSpec, certs: dict[str, Tightening], todo: list[RunTask], started: float,
            facts: dict[str, Any]) -> dict[str, Any]:
    """``runs.parquet``, ``summary.json`` (with this invocation's throughput) and the figures; the summary."""
    rows = [r for r in read_rows(out) if r["run"] < spec.runs]
    computed = {task.run for task in todo}
    _write_parquet(out, rows)
    facts = {"computed_runs": len(todo), "skipped_runs": spec.runs - len(todo), **facts,
             "campaign_wall_s": time.perf_counter() - started,
             "runs_wall_s": float(sum(r["wall_s"] for r in rows)),
             "computed_runs_wall_s": float(sum(r["wall_s"] for r in rows if r["run"] in computed))}
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
    from tubekit.app.certified import input_key

    key = input_key(plan.scenario)
    cert = cached_certificates(folder, {key: plan.scenario}).get(key)  # the campaign's own, through the checks
    if cert is None:
        cert = certify_plans([plan])[key]
    task = RunTask(run, plan.seed, plan.scenario, cert, spec.falsify_sequences)
    started = time.perf_counter()
    sims = simulate_all(task)
    row = row_of(task, sims, started)
    row = _stored_row(plan, row)
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
