"""Where the wall time of one ``tubekit campaign`` process goes: a timeline of its phases (issue 23).

Usage::

    python benchmarks/campaign_phases.py [--spec benchmarks/campaign_16x15.toml] [--workers 2]

Runs the CLI in this process with the client-side steps of :mod:`tubekit.app.campaign` wrapped to
print, on stderr, the time since this interpreter started its imports (s) at each step: the imports,
the cluster up, each certificate and run stored, the end of the runs, the tables, the summary, the
figures, the cluster closed (the close runs beside the tables and figures). The output directory is a
temporary one. A benchmark, not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import time

STARTED = time.perf_counter()
EPOCH = time.time()  # the same instant on the wall clock (the workers' task stream uses it)

import argparse  # noqa: E402
import contextlib  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

__all__ = ["main"]

SPEC = Path(__file__).resolve().parents[1] / "benchmarks" / "campaign_16x15.toml"


def _mark(what: str) -> None:
    print(f"{time.perf_counter() - STARTED:7.2f} s  {what}  (load {os.getloadavg()[0]:.2f})", file=sys.stderr,
          flush=True)


def _timeline(tasks: list[dict]) -> None:
    """Per worker: its first task's start, its busy time, its idle time between tasks, its last task's end
    (s since this interpreter started), and each task's compute time."""
    by_worker: dict[str, list[tuple[float, float, str]]] = {}
    for task in tasks:
        for part in task["startstops"]:
            if part["action"] == "compute":
                by_worker.setdefault(task["worker"], []).append((part["start"] - EPOCH, part["stop"] - EPOCH,
                                                                 task["key"].split("-")[-2]))
    for worker, spans in sorted(by_worker.items()):
        spans.sort()
        busy = sum(stop - start for start, stop, _ in spans)
        idle = sum(b[0] - a[1] for a, b in zip(spans, spans[1:]))
        kinds = {k: sum(stop - start for start, stop, kind in spans if kind == k) for k in {s[2] for s in spans}}
        print(f"  worker {worker}: {len(spans)} tasks, first starts {spans[0][0]:.2f} s, last ends "
              f"{spans[-1][1]:.2f} s; busy {busy:.2f} s ({', '.join(f'{k} {v:.2f} s' for k, v in kinds.items())}), "
              f"idle between tasks {idle:.2f} s; first task {spans[0][2]} {spans[0][1] - spans[0][0]:.2f} s",
              file=sys.stderr, flush=True)


def _wrap(module: object, name: str) -> None:
    inner = getattr(module, name, None)
    if inner is None:  # an older campaign module (run with another tree on PYTHONPATH)
        return

    def wrapped(*args, **kwargs):
        _mark(f"{name} begins")
        result = inner(*args, **kwargs)
        _mark(f"{name} ends")
        return result

    setattr(module, name, wrapped)


def _instrument() -> None:
    import tubekit.app.campaign as campaign
    import tubekit.app.certified as certified

    for name in ("start_fork_server", "import_plotting", "_execute", "_write_parquet", "summarise",
                 "write_figures"):
        _wrap(campaign, name)
    opener, writer, store = campaign.open_client, campaign.write_json, certified.write_cached

    @contextlib.contextmanager
    def open_client(*args, **kwargs):
        from distributed import get_task_stream

        _mark("cluster starts")
        with opener(*args, **kwargs) as client:
            _mark("cluster up")
            with get_task_stream(client) as stream:
                yield client
            _mark("cluster closes")
            _timeline(stream.data)
        _mark("cluster closed")

    def write_json(path, obj):
        if Path(path).parent.name == "runs":
            _mark(f"run stored ({Path(path).stem})")
        return writer(path, obj)

    def write_cached(folder, issued):
        _mark(f"certificate stored ({issued.key[:12]})")
        return store(folder, issued)

    campaign.open_client, campaign.write_json, certified.write_cached = open_client, write_json, write_cached


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spec", type=Path, default=SPEC)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    from tubekit.app.cli import main as cli

    _mark("client imports done")
    _instrument()
    with tempfile.TemporaryDirectory(prefix="tubekit-campaign-phases-") as tmp:
        code = cli(["campaign", str(args.spec), "--out", str(Path(tmp) / "out"), "--workers", str(args.workers),
                    "--no-progress"])
    _mark(f"end (exit {code})")
    return code


if __name__ == "__main__":
    sys.exit(main())
