"""Whole-process campaign benchmark (issue 23): ``tubekit campaign`` on 1 and on 2 local workers, alternated.

Usage::

    python benchmarks/campaign_whole.py [--spec benchmarks/campaign_16x15.toml] [--repeats 3] [--max-load L]
                                        [--reuse] [--json FILE]

Each repetition starts ``python -m tubekit.app.cli campaign SPEC --out TMP --workers N --no-progress`` as a
fresh process for N = 1 and N = 2 (the order alternates between repetitions: 1, 2, then 2, 1, ...) and
times the whole process: interpreter start, the spec, the LocalCluster on 127.0.0.1 (its fork server's
imports and warm-up, the forked workers), the certificates (on the workers), the runs, the tables and
figures, the shutdown (the process ends when its output pipes close: the fork server's exit included).
Reported: every wall time, the ratio wall(1 worker) / wall(2 workers) of each repetition (the two runs
of a pair are adjacent in time, so they share the machine's load), the median ratio, each process's own
throughput (``summary.json``) and the load average. The rows of every process must be identical
(``wall_s`` aside). The issue asks a median ratio >= 1.7.

``--reuse``: the same, but each process connects (``--scheduler``) to a scheduler and N single-threaded
workers started once for the pair's side on 127.0.0.1 (``dask scheduler`` / ``dask worker --no-nanny``,
stopped by their process ids) and warmed by one untimed campaign: the ratio without the cluster's
start-up and the workers' first-task imports, i.e. what reusing one local cluster gives.

``--max-load L``: before each pair, wait (up to 10 min) until the 1-min load average is at most ``L``
(on a shared machine, a pair measured while other jobs hold a core says little).

``--baseline DIR``: also time, in every repetition and right beside the current code's pair, a pair of
processes running the ``tubekit`` of the source tree ``DIR`` (put first on ``PYTHONPATH``; e.g. an export
of an earlier commit), so "before" and "after" share the machine's load; the rows must be identical too.

A benchmark, not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

__all__ = ["whole_process", "measure", "main"]

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "benchmarks" / "campaign_16x15.toml"


def whole_process(spec: Path, workers: int, out: Path, scheduler: str | None = None,
                  source: Path | None = None) -> dict:
    """Wall time (s) of one ``tubekit campaign`` process with ``workers`` local workers (or on ``scheduler``),
    running the ``tubekit`` of the source tree ``source`` if given (first on ``PYTHONPATH``)."""
    command = [sys.executable, "-m", "tubekit.app.cli", "campaign", str(spec), "--out", str(out), "--no-progress",
               *(["--scheduler", scheduler] if scheduler else ["--workers", str(workers)])]
    env = dict(os.environ)
    if source is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(source), *filter(None, [env.get("PYTHONPATH")])])
    load = os.getloadavg()[0]
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, timeout=900, check=False, env=env)
    wall = time.perf_counter() - started
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} exited {done.returncode}: {done.stderr.strip()[-2000:]}")
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    rows = sorted((json.loads(p.read_text(encoding="utf-8")) for p in (out / "runs").glob("run_*.json")),
                  key=lambda r: r["run"])
    return {"workers": workers, "wall_s": wall, "load_1min": load, "throughput": summary["throughput"],
            "campaign_wall_s": summary["campaign_wall_s"], "runs_wall_s": summary["runs_wall_s"],
            "rows": [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]}


def _stop(procs: list[subprocess.Popen]) -> None:
    """Stop the processes this benchmark started, by their ids: SIGTERM, then SIGKILL."""
    for proc in reversed(procs):
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=10)


def _cluster(folder: Path, workers: int, procs: list[subprocess.Popen]) -> str:
    """A scheduler and ``workers`` single-threaded workers on 127.0.0.1 (appended to ``procs``); its address."""
    info = folder / f"scheduler_{workers}.json"
    procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                                   "--port", "0", "--dashboard-address", "127.0.0.1:0", "--scheduler-file", str(info)],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    deadline = time.monotonic() + 120
    while not info.exists() and time.monotonic() < deadline:
        time.sleep(0.2)
    time.sleep(0.5)
    address = json.loads(info.read_text(encoding="utf-8"))["address"]
    procs += [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                                "--no-nanny", "--host", "127.0.0.1", "--no-dashboard"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for _ in range(workers)]
    return address


def measure(spec: Path = SPEC, repeats: int = 3, reuse: bool = False, max_load: float | None = None,
            baseline: Path | None = None) -> dict:
    """``repeats`` pairs of whole processes (1 and 2 workers, alternating order); the ratio of each pair
    (and, with ``baseline``, of a pair running that source tree beside each)."""
    pairs: list[dict] = []
    before: list[dict] = []
    procs: list[subprocess.Popen] = []
    with tempfile.TemporaryDirectory(prefix="tubekit-campaign-bench-") as tmp:
        try:
            clusters = {n: _cluster(Path(tmp), n, procs) for n in (1, 2)} if reuse else {1: None, 2: None}
            for n, address in clusters.items():
                if address:
                    whole_process(spec, n, Path(tmp) / f"warm_w{n}", address)  # imports and caches, untimed
            _pairs(spec, repeats, Path(tmp), clusters, pairs, max_load, baseline, before)
        finally:
            _stop(procs)
    result = {"spec": str(spec), "repeats": repeats, "reuse": reuse, "pairs": pairs, **_medians(pairs)}
    if baseline is not None:
        result["baseline"] = {"source": str(baseline), "pairs": before, **_medians(before)}
        result["identical_rows"] = result["identical_rows"] and result["baseline"]["identical_rows"]
    return result


def _medians(pairs: list[dict]) -> dict:
    """Median, min and max ratio, median wall times, whether every process wrote the reference rows."""
    ratios = [p["ratio"] for p in pairs]
    return {"median_ratio": statistics.median(ratios), "min_ratio": min(ratios), "max_ratio": max(ratios),
            "median_wall_s": {"one": statistics.median(p["one"]["wall_s"] for p in pairs),
                              "two": statistics.median(p["two"]["wall_s"] for p in pairs)},
            "median_load_1min": statistics.median(p[k]["load_1min"] for p in pairs for k in ("one", "two")),
            "identical_rows": all(p[k]["identical_rows"] for p in pairs for k in ("one", "two"))}


def _wait_for_load(max_load: float | None) -> float:
    """Wait (15 s steps, at most 10 min) until the 1-min load average is at most ``max_load``; that load."""
    deadline = time.monotonic() + 600
    while max_load is not None and os.getloadavg()[0] > max_load and time.monotonic() < deadline:
        time.sleep(15)
    return os.getloadavg()[0]


def _pairs(spec: Path, repeats: int, tmp: Path, clusters: dict, pairs: list, max_load: float | None = None,
           baseline: Path | None = None, before: list | None = None) -> None:
    """Append ``repeats`` timed pairs to ``pairs`` (and, with ``baseline``, as many to ``before``)."""
    reference: list = []
    for rep in range(repeats):
        _wait_for_load(max_load)
        order = (1, 2) if rep % 2 == 0 else (2, 1)
        sides = [(None, pairs)] + ([(baseline, before)] if baseline is not None else [])
        for source, into in (sides if rep % 2 == 0 else sides[::-1]):
            name = "base" if source else "cur"
            timed = {n: whole_process(spec, n, tmp / f"rep{rep}_{name}_w{n}", clusters[n], source) for n in order}
            for result in timed.values():
                rows = result.pop("rows")
                reference = reference or rows
                result["identical_rows"] = rows == reference
            into.append({"order": list(order), "one": timed[1], "two": timed[2],
                         "ratio": timed[1]["wall_s"] / timed[2]["wall_s"]})


def _line(result: dict) -> str:
    rate = result["throughput"]
    return (f"{result['workers']} worker(s): {result['wall_s']:6.2f} s whole process "
            f"({result['campaign_wall_s']:.2f} s in run_campaign; runs {result['runs_wall_s']:.2f} s); "
            f"{rate['simulated_s_per_wall_s']:.1f} simulated "
            f"s per wall s, {rate['runs_per_minute']:.0f} runs/min; load {result['load_1min']:.2f}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", type=Path, default=SPEC)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", default=None, metavar="FILE")
    parser.add_argument("--reuse", action="store_true", help="one warmed local cluster per worker count")
    parser.add_argument("--max-load", type=float, default=None, metavar="L",
                        help="before each pair, wait until the 1-min load average is at most L")
    parser.add_argument("--baseline", type=Path, default=None, metavar="DIR",
                        help="also time the tubekit of source tree DIR, a pair beside each pair")
    args = parser.parse_args(argv)
    baseline = args.baseline.resolve() if args.baseline else None
    result = measure(args.spec.resolve(), args.repeats, args.reuse, args.max_load, baseline)
    sides = [("", result)] + ([(f"baseline {baseline}: ", result["baseline"])] if baseline else [])
    for label, side in sides:
        for k, pair in enumerate(side["pairs"]):
            print(f"{label}repetition {k} (order {pair['order']}): ratio {pair['ratio']:.2f}")
            print("  " + _line(pair["one"]))
            print("  " + _line(pair["two"]))
    reused = " (reused clusters)" if args.reuse else ""
    for label, side in sides[::-1]:
        print(f"{label}whole-process speedup 2 vs 1 workers{reused}: median {side['median_ratio']:.2f}x "
              f"(min {side['min_ratio']:.2f}, max {side['max_ratio']:.2f}) over {args.repeats} interleaved pairs; "
              f"median wall {side['median_wall_s']['one']:.2f} s vs {side['median_wall_s']['two']:.2f} s; "
              f"median load {side['median_load_1min']:.2f}; rows identical: {side['identical_rows']}")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
