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


def _wrap(module: object, name: str) -> None:
    inner = getattr(module, name)

    def wrapped(*args, **kwargs):
        _mark(f"{name} begins")
        result = inner(*args, **kwargs)
        _mark(f"{name} ends")
        return result

    setattr(module, name, wrapped)


def _instrument() -> None:
    import tubekit.app.campaign as campaign
    import tubekit.app.certified as certified

    for name in ("_execute", "_write_parquet", "summarise", "write_figures"):
        _wrap(campaign, name)
    opener, writer, store = campaign.open_client, campaign.write_json, certified.write_cached

    @contextlib.contextmanager
    def open_client(*args, **kwargs):
        _mark("cluster starts")
        with opener(*args, **kwargs) as client:
            _mark("cluster up")
            yield client
            _mark("cluster closes")
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
