"""Bare QP solvers on the real-time FHOCP's own subproblems: is a QP backend worth adding beside Clarabel?

Usage::

    python benchmarks/fhocp_qp.py [--duration S] [--json FILE]

The paper scenario's tube run (certified tightening, real-time SCP) is simulated once; every convex
subproblem it solves is recorded as Clarabel's canonical data (P, q, A, b, cones: Ax + s = b, s in K).
Each recorded problem is then solved, interleaved (order alternated per problem), by

* ``clarabel``: the controller's persistent Clarabel solver (``update`` then ``solve``), the whole problem;
* ``piqp``: PIQP's sparse solver (``update`` then ``solve``) on the **QP relaxation**: the zero and
  nonnegative rows only, every second-order cone row dropped (PIQP, like DAQP, takes no cones).

The relaxation is exact only where its optimum happens to satisfy the dropped cones; the script counts
those problems (``cones_hold``, every cone met to 1e-6) and, on them, the largest input difference to
Clarabel's plan. Bare solve times only (the data are built before the clock).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

__all__ = ["record_problems", "compare", "main"]


def record_problems(duration: float) -> tuple[list[tuple], object]:
    """The tube run's subproblems as (P, q, A, b) with the compiled program they came from
    (:func:`clarabel_settings.record` on the paper scenario)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import clarabel_settings  # noqa: E402 - the sibling benchmark's recorder
    from tubekit import paper_scenario

    problems, compiled, _ = clarabel_settings.record(paper_scenario(), duration)
    return problems, compiled


def _cone_dims(compiled) -> tuple[int, int, list[int]]:
    dims = compiled.dims  # tubekit.fhocp.qp.base.ConeDims
    return dims.zero, dims.nonneg, list(dims.soc)


def _cones_hold(s: np.ndarray, soc: list[int], tol: float = 1e-6) -> bool:
    i = 0
    for d in soc:
        if s[i] + tol < np.linalg.norm(s[i + 1:i + d]):
            return False
        i += d
    return True


def compare(problems: list[tuple], compiled) -> dict:
    """Interleaved bare solves (module doc); medians and p99 in ms, cone check and plan differences."""
    import clarabel
    import piqp
    from tubekit.fhocp.qp.clarabel import clarabel_cones, clarabel_settings

    zero, nonneg, soc = _cone_dims(compiled)
    m_lin = zero + nonneg
    P0, q0, A0, b0 = problems[0]
    cl = clarabel.DefaultSolver(P0, q0, A0, b0, clarabel_cones(compiled.dims),
                                clarabel_settings(compiled.backend.settings))
    full = lambda P: (P + sp.triu(P, 1).T).tocsc()  # PIQP takes the whole symmetric P
    qp = piqp.SparseSolver()
    qp.settings.eps_abs = qp.settings.eps_rel = 1e-7
    qp.setup(full(P0), q0, A0[:zero].tocsc(), b0[:zero], A0[zero:m_lin].tocsc(), None, b0[zero:m_lin])
    times: dict[str, list[float]] = {"clarabel": [], "piqp": []}
    hold, diffs, piqp_failed = 0, [], 0
    for i, (P, q, A, b) in enumerate(problems):
        order = ("clarabel", "piqp") if i % 2 == 0 else ("piqp", "clarabel")
        for name in order:
            if name == "clarabel":
                cl.update(P=P, q=q, A=A, b=b)
                t0 = time.perf_counter()
                sol = cl.solve()
                times[name].append(time.perf_counter() - t0)
                x_cl = np.asarray(sol.x)
            else:
                qp.update(full(P), q, A[:zero].tocsc(), b[:zero], A[zero:m_lin].tocsc(), None, b[zero:m_lin])
                t0 = time.perf_counter()
                status = qp.solve()
                times[name].append(time.perf_counter() - t0)
                x_qp = np.asarray(qp.result.x)
                ok = status == piqp.PIQP_SOLVED
        if not ok:
            piqp_failed += 1
            continue
        if _cones_hold(b[m_lin:] - A[m_lin:] @ x_qp, soc):
            hold += 1
            diffs.append(float(np.max(np.abs(x_qp - x_cl))))
    med = {k: float(np.median(v) * 1e3) for k, v in times.items()}
    return {"problems": len(problems), "rows": {"zero": zero, "nonneg": nonneg, "soc": soc},
            "median_ms": med, "p99_ms": {k: float(np.percentile(v, 99) * 1e3) for k, v in times.items()},
            "clarabel_over_piqp": med["clarabel"] / med["piqp"], "piqp_failed": piqp_failed,
            "cones_hold": hold, "max_x_diff_where_cones_hold": max(diffs, default=float("nan"))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=100.0, help="simulated seconds of the recorded run")
    ap.add_argument("--json", type=Path, help="write the results to this JSON file")
    args = ap.parse_args(argv)
    try:
        import piqp  # noqa: F401
    except ImportError:
        print("piqp is not installed (pip install piqp)", file=sys.stderr)
        return 1
    problems, compiled = record_problems(args.duration)
    res = compare(problems, compiled)
    text = json.dumps(res, indent=2)
    print(text)
    if args.json:
        from tubekit.jsonable import write_text

        write_text(args.json, text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
