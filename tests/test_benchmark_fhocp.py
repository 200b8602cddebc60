"""The FHOCP benchmark runs in quick mode and writes every required key (timings not asserted)."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest

from .scripts import ROOT, load_script
KEYS = ("rt_step_ms_median", "rt_step_ms_p99", "converged_ms_median", "ipopt_ms_median", "clarabel_ms_median",
        "ratio_rt_vs_ipopt", "ratio_converged_vs_ipopt", "cost_gap_max", "n_states")
PEERS = ("scp_realtime", "scp_converged", "ipopt", "sqpmethod_qrqp")
PEER_KEYS = ("median_ms", "p90_ms", "p99_ms", "failures", "cost_gap_max", "converged")


@pytest.mark.slow
def test_quick_benchmark_writes_all_keys(tmp_path):
    pytest.importorskip("casadi")
    out = tmp_path / "fhocp.json"
    # 11 s of closed loop (the quick run's 20 s shortened): over 100 sampled states, every key and every peer
    proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "fhocp.py"), "--quick", "--duration", "11",
                           "--rate-penalty", "0", "--json", str(out)],
                          capture_output=True, text=True, timeout=600, cwd=tmp_path)  # a hang guard
    assert proc.returncode == 0, proc.stderr
    assert "real-time SCP step" in proc.stdout and "sqpmethod" in proc.stdout
    res = json.loads(out.read_text())
    for key in KEYS:
        assert key in res, key
        assert isinstance(res[key], (int, float)) and math.isfinite(res[key]), (key, res[key])
    assert res["n_states"] >= 100
    assert res["details"]["rt_fallbacks"] == 0
    assert res["details"]["rate_penalty"] == 0.0
    assert set(PEERS) <= set(res["peers"])
    for name in PEERS:
        for key in PEER_KEYS:
            assert key in res["peers"][name], (name, key)
    assert res["peers"]["ipopt"]["converged"] and not res["peers"]["scp_realtime"]["converged"]
    for key in ("rt_suboptimality_median", "rt_suboptimality_max", "rt_over_clarabel", "rt_p99_over_median"):
        assert key in res["targets"], key


def _bench_module():
    return load_script("benchmarks/fhocp.py", "bench_fhocp")


@pytest.mark.parametrize("lam, with_sqp", [(0.0, True), (10.0, False), (2.5, False)])
def test_every_method_solves_one_problem(lam, with_sqp):
    """Every method gets the same rate penalty; sqpmethod (it fails on the rate rows) joins only at 0."""
    pytest.importorskip("casadi")
    bench = _bench_module()
    from tubekit import paper_scenario
    sc = paper_scenario()
    methods = bench.make_methods(sc, bench.benchmark_tightening(sc), rate_penalty=lam)
    assert ("sqpmethod_qrqp" in methods) is with_sqp
    assert {m.nlp.rate_penalty for m, _ in methods.values()} == {lam}
    assert len({m.max_obstacles for m, _ in methods.values()}) == 1


def test_the_opt_in_methods_solve_the_same_problem_with_their_own_backend_or_setting():
    """``--qoco`` adds the real-time SCP on the QOCO backend, ``--clarabel-1e7`` the one with Clarabel at 1e-7 with
    refinement (the real-time setting before): same rate penalty and slots as ours, and the first state's plans
    agree to 1e-4."""
    pytest.importorskip("casadi")
    pytest.importorskip("qoco")
    import numpy as np
    bench = _bench_module()
    from tubekit import paper_scenario
    sc = paper_scenario()
    methods = bench.make_methods(sc, bench.benchmark_tightening(sc), with_casadi=False,
                                 opt_in=("qoco", "clarabel_1e7"))
    assert set(methods) == {"scp_realtime", "scp_converged", "scp_realtime_qoco", "scp_realtime_1e7"}
    assert methods["scp_realtime_qoco"][0].options.qp_solver == "qoco"
    assert dict(methods["scp_realtime_1e7"][0].options.clarabel_settings) == bench.CLARABEL_1E7
    x0 = np.asarray(sc.initial_state, dtype=float)
    plans = {n: methods[n][0].solve(0.0, x0.copy(), list(sc.obstacles)).inputs
             for n in ("scp_realtime", "scp_realtime_qoco", "scp_realtime_1e7")}
    for name in ("scp_realtime_qoco", "scp_realtime_1e7"):
        assert np.max(np.abs(plans[name] - plans["scp_realtime"])) < 1e-4, name
