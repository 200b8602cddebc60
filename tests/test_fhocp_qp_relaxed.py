"""The opt-in PIQP path (tubekit.fhocp.qp_relaxed): Clarabel's answers, through the QP relaxation where it is exact."""

from __future__ import annotations

import numpy as np
import pytest

from tubekit.exceptions import ConfigError
from tubekit.fhocp import FHOCP, ScpOptions
from tubekit.fhocp.registry import backends, make_solver

from .fhocp_cases import RUN_STATES, SC, tightening


def test_qp_solver_is_validated():
    with pytest.raises(ConfigError, match="qp_solver"):
        ScpOptions(qp_solver="osqp")
    with pytest.raises(ConfigError, match="qp_solver"):
        ScpOptions(qp_solver="piqp", fast_path=False)
    assert ScpOptions().qp_solver == "clarabel"
    assert "scp-piqp" in backends()


def test_the_piqp_path_returns_clarabels_plans_on_the_run_states():
    """Same warm start, same state: the plans agree to the solvers' tolerances, and both the QP path
    (terminal cone slack) and the Clarabel fallback (terminal cone binding) are exercised."""
    pytest.importorskip("piqp")
    tg = tightening()
    ref, alt = FHOCP(SC, tg, mode="realtime"), make_solver(SC, tg, "scp-piqp")
    alt.mode = ref.mode
    for t, s in RUN_STATES:
        for dt in (0.0, 0.1, 0.2):  # a cold start, then two warm real-time steps
            alt._plan_t, alt._plan_inputs = ref._plan_t, ref._plan_inputs
            a = ref.solve(t + dt, np.asarray(s), SC.obstacles)
            b = alt.solve(t + dt, np.asarray(s), SC.obstacles)
            np.testing.assert_allclose(b.inputs, a.inputs, atol=1e-5)
            # cold starts run the converged loop: the tolerance 1e-5 on its stopping test, with exact
            # penalties of weight 1e3, leaves the merit equal to ~1e-4 between two solvers
            assert b.merit == pytest.approx(a.merit, rel=1e-4)
            assert not b.fallback
    program = alt.subproblem.compiled
    assert program.qp_solves > 0 and program.clarabel_solves > 0


def test_without_piqp_the_backend_says_how_to_install(monkeypatch):
    import builtins

    from tubekit.exceptions import NotAvailableError
    real_import = builtins.__import__

    def no_piqp(name, *args, **kwargs):
        if name == "piqp":
            raise ImportError("no piqp")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_piqp)
    with pytest.raises(NotAvailableError, match="pip install piqp"):
        make_solver(SC, tightening(), "scp-piqp")
