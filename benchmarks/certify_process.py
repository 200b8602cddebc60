"""Whole-process time of ``tubekit certify`` on the shipped scenarios: interpreter start to exit.

Usage::

    python benchmarks/certify_process.py [--tree LABEL=DIR ...] [--repeat N] [--scenario FILE ...] [--json FILE]

Each run is a fresh ``python -m tubekit certify FILE -q`` (the console script's code path), timed from
``subprocess`` start to exit. With several ``--tree``s (checkouts of the project, e.g. ``before=/tmp/old``
made by ``git archive``; default: this checkout as ``current``) the runs are interleaved: every repetition
runs every scenario under every tree, the tree order rotating, so machine load falls on all alike; the
report is the median (and min, max) per scenario and tree, the ratio of each tree's median to the first
tree's, and the load average before and after. A tree is put first on ``PYTHONPATH``.

Bytecode: every child writes and reads its ``.pyc`` under one private ``PYTHONPYCACHEPREFIX`` (the
checkout is left alone, ``PYTHONDONTWRITEBYTECODE`` is dropped) and one untimed warm-up run per scenario
and tree fills it, so the numbers are those of an installed package (``--cold-bytecode`` keeps the
caller's environment instead). A probe run per tree reports which heavy modules the process loaded
(sympy, scipy, cvxpy, matplotlib, ...) and how many modules in all.
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

__all__ = ["main", "measure", "interleaved_order", "summarise", "scenario_files", "HEAVY"]

ROOT = Path(__file__).resolve().parents[1]
#: Modules whose presence in the finished process is reported.
HEAVY = ("sympy", "scipy", "cvxpy", "clarabel", "casadi", "matplotlib", "numba", "mpmath")
_PROBE = ("import sys, json\nsys.argv = ['tubekit', 'certify', {path!r}, '-q']\n"
          "from tubekit.app.cli import main\ncode = main()\n"
          "sys.stderr.write('\\nPROBE ' + json.dumps({{'loaded': [m for m in {heavy!r} if m in sys.modules], "
          "'modules': len(sys.modules), 'exit': code}}) + '\\n')\n")


def scenario_files(root: Path = ROOT) -> list[Path]:
    """The shipped scenario files ``tubekit certify`` accepts (verify/scenarios/, examples/; campaign specs skipped)."""
    from tubekit.exceptions import ConfigError
    from tubekit.scenario import load_scenario

    out = []
    for path in sorted((root / "verify" / "scenarios").glob("*.toml")) + sorted((root / "examples").glob("*.toml")):
        try:
            load_scenario(path)
        except ConfigError:
            continue
        out.append(path)
    return out


def interleaved_order(trees: list[str], scenarios: list[str], repeat: int) -> list[tuple[int, str, str]]:
    """(repetition, scenario, tree) in run order: each repetition runs every pair, the tree order rotated by one."""
    order = []
    for rep in range(repeat):
        k = rep % len(trees)
        rotated = trees[k:] + trees[:k]
        order += [(rep, s, t) for s in scenarios for t in rotated]
    return order


def _env(tree: Path, pycache: str | None) -> dict[str, str]:
    """The child's environment: ``tree`` first on PYTHONPATH; a private bytecode cache unless ``pycache`` is None."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(tree)] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    if pycache is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = pycache
    return env


def _run(path: Path, env: dict[str, str]) -> tuple[float, int]:
    """(wall seconds, exit code) of one ``python -m tubekit certify path -q`` process."""
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "tubekit", "certify", str(path), "-q"], env=env,
                         cwd=tempfile.gettempdir(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         timeout=600)
    wall = time.perf_counter() - t0
    if run.returncode not in (0, 3):
        raise RuntimeError(f"tubekit certify {path} exited {run.returncode}:\n{run.stderr[-2000:]}")
    return wall, run.returncode


def _probe(path: Path, env: dict[str, str]) -> dict:
    """Which of :data:`HEAVY` a certify process of ``path`` loaded, its module count and exit code."""
    code = _PROBE.format(path=str(path), heavy=HEAVY)
    run = subprocess.run([sys.executable, "-c", code], env=env, cwd=tempfile.gettempdir(), capture_output=True,
                         text=True, timeout=600)
    line = [ln for ln in run.stderr.splitlines() if ln.startswith("PROBE ")]
    if not line:
        raise RuntimeError(f"probe of {path} failed:\n{run.stderr[-2000:]}")
    return json.loads(line[-1][len("PROBE "):])


def summarise(walls: dict[str, dict[str, list[float]]], trees: list[str]) -> dict[str, dict[str, dict]]:
    """Per scenario and tree: median, min, max (s) and the median's ratio to the first tree's."""
    out: dict[str, dict[str, dict]] = {}
    for scen, per in walls.items():
        base = statistics.median(per[trees[0]])
        out[scen] = {t: {"median_s": statistics.median(per[t]), "min_s": min(per[t]), "max_s": max(per[t]),
                         "runs": len(per[t]), "ratio": statistics.median(per[t]) / base} for t in trees}
    return out


def measure(trees: dict[str, Path], scenarios: list[Path], repeat: int, cold_bytecode: bool = False) -> dict:
    """Interleaved whole-process timings of ``tubekit certify`` (see the module doc)."""
    labels = list(trees)
    with tempfile.TemporaryDirectory(prefix="certify_pyc_") as cache:
        envs = {t: _env(trees[t], None if cold_bytecode else os.path.join(cache, t)) for t in labels}
        load_before = os.getloadavg()
        probes = {t: _probe(scenarios[0], envs[t]) for t in labels}
        if not cold_bytecode:
            for path in scenarios:
                for t in labels:
                    _run(path, envs[t])
        walls: dict[str, dict[str, list[float]]] = {p.name: {t: [] for t in labels} for p in scenarios}
        codes: dict[str, dict[str, int]] = {p.name: {} for p in scenarios}
        by_name = {p.name: p for p in scenarios}
        for _, name, t in interleaved_order(labels, list(by_name), repeat):
            wall, code = _run(by_name[name], envs[t])
            walls[name][t].append(wall)
            codes[name][t] = code
        load_after = os.getloadavg()
    return {"trees": {t: str(p) for t, p in trees.items()}, "repeat": repeat, "cold_bytecode": cold_bytecode,
            "load_before": list(load_before), "load_after": list(load_after), "cpus": os.cpu_count(),
            "probe": probes, "exit_codes": codes, "walls_s": walls, "summary": summarise(walls, labels)}


def _table(res: dict) -> str:
    """The report as text."""
    labels = list(res["trees"])
    lines = [f"tubekit certify, whole process, median of {res['repeat']} interleaved runs "
             f"({'caller bytecode' if res['cold_bytecode'] else 'warm bytecode'}); load average "
             f"{res['load_before'][0]:.2f} before, {res['load_after'][0]:.2f} after, {res['cpus']} CPUs"]
    for t in labels:
        p = res["probe"][t]
        lines.append(f"  {t} = {res['trees'][t]}: {p['modules']} modules; heavy ones loaded: "
                     f"{', '.join(p['loaded']) or 'none'} (of {', '.join(HEAVY)})")
    head = f"{'scenario':<24}" + "".join(f"{t + ' median s':>18}{'(min-max)':>14}" for t in labels)
    lines += [head + "".join(f"{t + '/' + labels[0]:>16}" for t in labels[1:])]
    for scen, per in res["summary"].items():
        row = f"{scen:<24}" + "".join(f"{per[t]['median_s']:>18.3f}{per[t]['min_s']:>7.2f}-{per[t]['max_s']:<6.2f}"
                                      for t in labels)
        lines.append(row + "".join(f"{per[t]['ratio']:>16.3f}" for t in labels[1:]))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tree", action="append", default=None, metavar="LABEL=DIR",
                        help="a checkout to time (repeatable; the first is the ratios' base); default this one")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per scenario and tree (default 5)")
    parser.add_argument("--scenario", action="append", default=None, metavar="FILE",
                        help="a scenario file (repeatable); default every shipped one certify accepts")
    parser.add_argument("--cold-bytecode", action="store_true", help="keep the caller's bytecode settings")
    parser.add_argument("--json", default=None, metavar="FILE", help="also write the result as JSON")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat: expected an integer >= 1")
    trees = {"current": ROOT}
    if args.tree:
        pairs = [t.split("=", 1) for t in args.tree]
        if any(len(p) != 2 or not Path(p[1]).is_dir() for p in pairs):
            parser.error(f"--tree: expected LABEL=DIR with an existing DIR, received {args.tree}")
        trees = {label: Path(d).resolve() for label, d in pairs}
    scenarios = [Path(s).resolve() for s in args.scenario] if args.scenario else scenario_files()
    missing = [str(s) for s in scenarios if not s.is_file()]
    if missing:
        parser.error(f"--scenario: expected existing files, received {missing}")
    res = measure(trees, scenarios, args.repeat, args.cold_bytecode)
    print(_table(res))
    if args.json:
        from tubekit.jsonable import write_json

        write_json(args.json, res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
