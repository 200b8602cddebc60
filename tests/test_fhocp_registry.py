"""tubekit.fhocp.registry: FHOCP backends by name, the scenario's by default, IPOPT optional."""

from __future__ import annotations

import builtins

import numpy as np
import pytest

from tubekit import ConfigError, NotAvailableError
from tubekit.fhocp import FHOCP, registry
from tubekit.fhocp.registry import backends, get_backend, make_solver, register_backend

from .fhocp_cases import SC, STATES, tightening


@pytest.fixture
def private_registry(monkeypatch):
    """Registrations made by a test stay in that test."""
    monkeypatch.setattr(registry, "_BACKENDS", dict(registry._BACKENDS))


def test_builtin_backends_and_the_scenario_default():
    assert backends()[:2] == ("scp", "ipopt")
    solver = make_solver(SC, tightening())
    assert isinstance(solver, FHOCP) and solver.mode == SC.controller.fhocp_mode == "realtime"
    converged = make_solver(SC.with_changes(**{"controller.fhocp_mode": "converged"}), tightening())
    assert converged.mode == "converged"


def test_unknown_backend_is_a_config_error_listing_the_names():
    sc = SC.with_changes(**{"controller.fhocp_backend": "snopt"})
    with pytest.raises(ConfigError, match=r"controller\.fhocp_backend: expected one of the FHOCP backends "
                                          r"\('scp', 'ipopt'"):
        make_solver(sc, tightening())
    with pytest.raises(ConfigError, match=r"^backend: "):
        make_solver(SC, tightening(), backend="snopt")
    with pytest.raises(ConfigError, match="controller.fhocp_backend"):
        get_backend(3)  # type: ignore[arg-type]


def test_register_backend_rules(private_registry):
    with pytest.raises(ConfigError, match="name"):
        register_backend("", lambda sc, tg: None)
    with pytest.raises(ConfigError, match="factory"):
        register_backend("mine", "not callable")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="not yet registered"):
        register_backend("scp", lambda sc, tg: None)
    calls = []
    register_backend("mine", lambda sc, tg: calls.append((sc, tg)) or "solver")
    tg = tightening()
    assert make_solver(SC.with_changes(**{"controller.fhocp_backend": "mine"}), tg) == "solver"
    assert calls == [(SC.with_changes(**{"controller.fhocp_backend": "mine"}), tg)]
    register_backend("mine", lambda sc, tg: "other", replace=True)
    assert get_backend("mine")(SC, tg) == "other"


def test_ipopt_backend_without_casadi_names_the_install(monkeypatch):
    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name == "casadi" or name.startswith("casadi."):
            raise ImportError("No module named 'casadi'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)
    with pytest.raises(NotAvailableError, match=r"pip install -e \"\.\[bench\]\""):
        make_solver(SC, tightening(), backend="ipopt")


def test_ipopt_backend_solves_with_the_scenario_settings():
    pytest.importorskip("casadi")
    from tubekit.fhocp.ipopt import IpoptFHOCP
    sc = SC.with_changes(**{"controller.fhocp_backend": "ipopt", "controller.terminal_mode": "off"})
    solver = make_solver(sc, tightening())
    assert isinstance(solver, IpoptFHOCP) and solver.nlp.terminal == "off"
    t, s = STATES[1]
    res = solver.solve(t, np.array(s), SC.obstacles)
    assert not res.fallback and res.max_violation <= 1e-6


def test_the_generated_qoco_backend_without_a_compiler_says_what_is_missing(monkeypatch):
    """``scp-qocogen`` is refused before anything is built when no C compiler can build its solver."""
    from tubekit.fhocp.qp import qocogen

    assert "scp-qocogen" in backends()
    monkeypatch.setattr(qocogen, "compiler", lambda: None)
    with pytest.raises(NotAvailableError, match=r"QP backend 'qocogen' needs a C compiler"):
        make_solver(SC, tightening(), "scp-qocogen")
