"""Campaign throughput on this machine: speedup with 2 workers against 1, and scheduling overhead per run.

Usage::

    python benchmarks/campaign.py [--runs N] [--duration S] [--json FILE]

The runs are those of a campaign on ``verify/scenarios/paper_currents.toml`` (current amplitude and
period sampled, no falsification), certified on the client before any clock starts. For each worker
count a LocalCluster (127.0.0.1) is started and every worker is warmed up with one short run (imports,
solver compilation), then the clock times ``simulate_task`` for all runs through ``Client.submit`` /
``as_completed`` — the code path of ``tubekit campaign``. Reported:

* ``speedup`` = elapsed(1 worker) / elapsed(2 workers) (the issue asks >= 1.7 on 2 cores);
* ``overhead_per_run_s`` = (elapsed x workers - sum of the runs' own wall_s) / runs: scheduler, transfer and
  idle time per run, and ``overhead_fraction`` = that over the mean run time (the issue asks < 5 %).

A benchmark, not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from tubekit.app.campaign import RunTask, certify_plans, open_client, simulate_task
from tubekit.app.campaign_spec import spec_from_dict
from tubekit.app.certified import input_key

__all__ = ["measure", "main"]

ROOT = Path(__file__).resolve().parents[1]


def _tasks(runs: int, duration: float) -> list[RunTask]:
    spec = spec_from_dict({"scenario": str(ROOT / "verify/scenarios/paper_currents.toml"), "runs": runs,
                           "seed": 1, "duration": duration,
                           "sample": {"disturbance.amplitude": {"uniform": [[0.05] * 3, [0.1] * 3]},
                                      "disturbance.period": {"uniform": [8.0, 20.0]}}})
    plans = [spec.plan(k) for k in range(runs)]
    certs = certify_plans(plans)
    return [RunTask(p.run, p.seed, p.scenario, certs[input_key(p.scenario)], 0) for p in plans]


def _timed(workers: int, tasks: list[RunTask]) -> dict:
    """Elapsed time (s) of every task on a warmed LocalCluster of ``workers`` processes."""
    from dataclasses import replace

    from distributed import as_completed

    warm = replace(tasks[0], scenario=tasks[0].scenario.with_changes(duration=1.0))
    with open_client(workers, None) as client:
        client.run(simulate_task, warm)  # every worker: imports and solver compilation, off the clock
        started = time.perf_counter()
        futures = [client.submit(simulate_task, t, pure=False) for t in tasks]
        rows = [f.result() for f in as_completed(futures)]
        elapsed = time.perf_counter() - started
    run_s = sum(r["wall_s"] for r in rows)
    overhead = (elapsed * workers - run_s) / len(rows)
    return {"workers": workers, "elapsed_s": elapsed, "sum_run_wall_s": run_s, "mean_run_s": run_s / len(rows),
            "overhead_per_run_s": overhead, "overhead_fraction": overhead / (run_s / len(rows)),
            "rows": sorted(({k: v for k, v in r.items() if k != "wall_s"} for r in rows), key=lambda r: r["run"])}


def measure(runs: int = 16, duration: float = 20.0) -> dict:
    """Time the same runs on 1 and on 2 workers; the per-run results must agree."""
    tasks = _tasks(runs, duration)
    one, two = _timed(1, tasks), _timed(2, tasks)
    same = one.pop("rows") == two.pop("rows")
    return {"runs": runs, "duration_s": duration, "one_worker": one, "two_workers": two,
            "speedup": one["elapsed_s"] / two["elapsed_s"], "identical_rows": same}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=16)
    parser.add_argument("--duration", type=float, default=20.0, help="simulated seconds per run")
    parser.add_argument("--json", default=None, metavar="FILE")
    args = parser.parse_args(argv)
    result = measure(args.runs, args.duration)
    for key in ("one_worker", "two_workers"):
        r = result[key]
        print(f"{r['workers']} worker(s): {r['elapsed_s']:.2f} s for {args.runs} runs of {args.duration:g} s "
              f"(mean run {r['mean_run_s']:.3f} s); overhead {r['overhead_per_run_s'] * 1e3:.1f} ms/run "
              f"= {100 * r['overhead_fraction']:.1f} % of a run")
    print(f"speedup 2 vs 1 workers: {result['speedup']:.2f}x; per-run results identical: {result['identical_rows']}")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
